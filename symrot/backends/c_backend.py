"""Header-only C99 backend: ``symrot derive EXPR --name NAME --emit c`` → ``symrot_NAME.h``.

Prints the evaluation plan of :mod:`symrot.plan.builder` (one per precision) through
``templates/c/header.h.j2``; it builds no plan of its own. For each function of
:data:`~symrot.backends.c_functions.FUNCTIONS` the header has a double version and a float version
(suffix ``_f``, float math functions, the float32 plan), and matrix functions also a ``_batch``
kernel. The statements come from :mod:`symrot.backends.c_writer` (single calls, and how a plan
becomes C), :mod:`symrot.backends.c_batch` (batch kernels), :mod:`symrot.backends.c_operations`
(quaternions, composition, rescaling) and :mod:`symrot.backends.c_derivatives` (the derivatives of
issue 19); this module assembles them into the header and writes it.
"""

from __future__ import annotations

import re
from functools import partial
from pathlib import Path
from typing import Any

import sympy as sp

from symrot.backends.c_aliasing import stored_last
from symrot.backends.c_batch import DEFAULT_BLOCK, BatchWriter
from symrot.backends.c_derivatives import DerivativeWriter
from symrot.backends.c_entries import share_entries
from symrot.backends.c_functions import FUNCTIONS, CFunction
from symrot.backends.c_operations import OperationWriter
from symrot.backends.c_printer import PRECISIONS, Precision
from symrot.backends.c_shared import share_coefficients
from symrot.backends.c_sincos import NEAREST
from symrot.backends.c_writer import FunctionWriter
from symrot.backends.templating import render
from symrot.core.atomic import write_atomic
from symrot.core.derivation import Derivation, derive_expression
from symrot.core.derivatives import rate_vector, tensor_derivative
from symrot.core.errors import SymrotError
from symrot.core.forked import first_here_others_in_children
from symrot.core.registry import NAMED, find_by_expression, lookup
from symrot.plan.builder import evaluation_plan
from symrot.plan.ir import ClosedAngle, EvaluationPlan

HEADER_NAME = re.compile(r"[A-Za-z_][A-Za-z0-9_]*")


class InvalidHeaderName(SymrotError):
    """--name is not a C identifier."""


def header_source(plan: EvaluationPlan, name: str, expression: str | None = None) -> str:
    """The text of ``symrot_NAME.h`` for ``plan``: the float functions are printed in a forked
    child while this process prints the double ones (:mod:`symrot.core.forked`), after the derivative
    algebra both read (:func:`symrot.core.derivatives.tensor_derivative`, :func:`rate_vector`)."""
    if not HEADER_NAME.fullmatch(name):
        raise InvalidHeaderName(f"--name {name[:40]!r} is not a C identifier")
    tensor_derivative()
    rate_vector()
    functions = [function for functions_of_one in first_here_others_in_children(
        [partial(_precision_functions, plan, name, precision) for precision in PRECISIONS])
        for function in functions_of_one]
    identifier = registry_title(plan.p)
    text = expression or sp.sstr(plan.p)
    return render(
        "c/header.h.j2", name=name, expression=text, title=identifier,
        command=f"symrot derive '{text}' --name {name} --emit c --out DIR",
        validity=FunctionWriter(plan, name, "double").validity_notes()[0],
        plan_note=f"the float64 and float32 plans of symrot.plan, {angle_kind(plan)} for phi",
        guard=f"SYMROT_{name.upper()}_H", functions=functions, block=DEFAULT_BLOCK,
        nearest=_uses_nearest(functions),
    )


def _uses_nearest(functions: list[dict[str, Any]]) -> bool:
    """Whether a printed statement rounds with the header's SYMROT_NEAREST macros (the sin/cos
    kernel of the _batch loops, :mod:`symrot.backends.c_sincos`)."""
    return any(macro + "(" in repr(functions) for macro in NEAREST.values())


def _precision_functions(plan: EvaluationPlan, name: str, precision: Precision) -> list[dict[str, Any]]:
    """The functions of one precision, in header order: angle, public functions with their batch
    kernels, operations, derivatives, with the coefficient blocks several of them compute alike
    printed once as helpers after the angle's (:mod:`symrot.backends.c_shared`); each stores its
    outputs after reading its inputs (:func:`~symrot.backends.c_aliasing.stored_last`); the entries
    that several compute alike but for names are one helper too (:mod:`symrot.backends.c_entries`)."""
    writer = FunctionWriter(plan, name, precision)
    batch = BatchWriter(writer)
    angle = []
    if plan.complement is not None:
        angle.append(writer.complement_function())
    angle.append(writer.angle_function())
    angle += writer.angle_low_functions
    public = [writer.function(spec) for spec in FUNCTIONS]
    for spec, function in zip(FUNCTIONS, public, strict=True):
        if function["batch_signature"]:
            function["batch_statements"], function["batch_notes"] = batch.kernel(spec)
    operations = OperationWriter(plan, name, precision).all()
    derivatives = DerivativeWriter(plan, name, precision).all()
    callers, helpers = share_coefficients([*public, *operations, *derivatives], writer)
    functions = [*angle, *helpers, *callers]  # the shared coefficients after phi, before their callers
    stored = [stored_last(function) for function in functions]  # outputs may alias inputs
    return share_entries(stored, writer)  # the same entries but for names, once


def angle_kind(plan: EvaluationPlan) -> str:
    angle = plan.precisions["float64"].angle
    return "closed inverse" if isinstance(angle, ClosedAngle) else "safeguarded Newton iteration"


def registry_title(p: sp.Expr) -> str:
    entry = find_by_expression(p)
    return f"{entry.title}, eq {entry.equation}" if entry else ""


def plan_for(derivation: Derivation, name: str) -> EvaluationPlan:
    return evaluation_plan(derivation, name)


def emit(derivation: Derivation, name: str, out: Path) -> list[Path]:
    """Write ``out/symrot_NAME.h`` (the ``--emit c`` entry point); return the written paths."""
    text = header_source(plan_for(derivation, name), name)
    out.mkdir(parents=True, exist_ok=True)
    path = out / f"symrot_{name}.h"
    write_atomic(path, text)
    return [path]


COVERED: tuple[str, ...] = (
    *NAMED, "sine_m3", "sine_m5", "sine_m6", "tangent_m1", "tangent_m3", "tangent_m5", "tangent_m6",
)
"""Headers under generated/c/: Table 1, eq 35 and the sine/tangent families up to m = 6 (sine m = 1,
2, 4 are linear, euler_rodrigues, sine_m4; tangent m = 2, 4 are cayley_gibbs_rodrigues and
wiener_milenkovic)."""


def generated_headers(names: tuple[str, ...] | None = None) -> dict[str, str]:
    """generated/c/symrot_NAME.h for every name in :data:`COVERED` (``make generate``), or for
    ``names``."""
    headers = {}
    for name in COVERED if names is None else names:
        derivation = derive_expression(lookup(name).expression)
        headers[f"c/symrot_{name}.h"] = header_source(plan_for(derivation, name), name)
    return headers


__all__ = ["COVERED", "FUNCTIONS", "CFunction", "FunctionWriter", "InvalidHeaderName", "emit",
           "generated_headers", "header_source", "plan_for"]
