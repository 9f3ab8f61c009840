"""C functions for the derivatives of issue 19, built on :class:`~symrot.backends.c_writer.FunctionWriter`.

Single calls in double and, suffixed ``_f``, float; no allocation; matrices row-major
(D[3*i + j] = ∂(T a)_i/∂p_j, column j the derivative by p_j; docs/derivatives.md):

* ``rotation_derivative(p, a, D)``, ``rotation_transpose_derivative``, ``tangent_derivative``,
  ``tangent_transpose_derivative``, ``tangent_inverse_derivative``: ∂(T a)/∂p printed entry by entry
  from the form the core derives (:func:`symrot.core.derivatives.tensor_derivative`), with the planned
  coefficients c_k and slopes c_k′ = dc_k/dx (Tᵀ: T's statements on c1, c1′ negated, so that the two
  share one helper, :mod:`symrot.backends.c_entries`); NaN outside the range, as every function of
  the header;
* ``angular_acceleration(p, pdot, pddot, alpha)``: α = H p̈ + Ḣ ṗ with Ḣ ṗ from
  :func:`symrot.core.derivatives.rate_value`;
* ``compose_jacobians(p1, p2, J1, J2)``: ∂p₃/∂p₁ = H(p₃)⁻¹ R(p₂) H(p₁), ∂p₃/∂p₂ = H(p₃)⁻¹ H(p₂) for
  p₃ = compose(p₁, p₂); ``rescale_jacobian(p, J)``: H(p_r)⁻¹ H(p) when p is rescaled to p_r, I when
  it is kept. Both return the status of compose/rescale (0, or 1 with NaN outputs).
"""

from __future__ import annotations

import math
import re
from dataclasses import replace
from typing import Any

import sympy as sp

from symrot.backends.c_functions import P, vector_entries
from symrot.backends.c_printer import Precision
from symrot.backends.c_statements import Statement, ops_of
from symrot.backends.c_writer import FunctionWriter
from symrot.backends.subexpressions import common_subexpressions
from symrot.core.derivatives import SLOPES, VALUES, rate_value, rate_vector, slope_name, tensor_derivative
from symrot.plan.ir import EvaluationPlan

DERIVATIVES = {"rotation_derivative": ("R", 1, "d(R a)/dp"),
               "rotation_transpose_derivative": ("R", -1, "d(R^T a)/dp"),
               "tangent_derivative": ("H", 1, "d(H a)/dp"),
               "tangent_transpose_derivative": ("H", -1, "d(H^T a)/dp"),
               "tangent_inverse_derivative": ("H_inverse", 1, "d(H^-1 a)/dp")}
"""C function → (tensor, sign of c1 and c1′, summary)."""


def _vector(name: str) -> sp.Matrix:
    return sp.Matrix([sp.Symbol(f"{name}[{i}]", real=True) for i in range(3)])


class DerivativeWriter(FunctionWriter):
    """The derivative functions of one plan in one precision: their validity test uses the plan's
    ``derivative_x_limit`` (the slopes' edge of the domain, at most ``x_limit``)."""

    def __init__(self, plan: EvaluationPlan, header: str, precision: Precision) -> None:
        super().__init__(plan, header, precision)
        self.kinematic_x_limit = self.precision_plan.x_limit
        self.precision_plan = replace(self.precision_plan, x_limit=self.precision_plan.derivative_x_limit)

    def out_of_range(self, x: str = "x") -> str:
        """The kinematic validity test, and, where the slopes end before it (for a bounded p too),
        their own edge: a plan whose slopes no form represents in the format has edge 0 (NaN)."""
        test = super().out_of_range(x)  # unbounded p: tests x_limit, which is the slopes' edge here
        limit = self.precision_plan.x_limit
        if math.isfinite(self.plan.p_max) and limit < min(self.kinematic_x_limit, self.plan.p_max ** 2):
            test = f"{test} || !({x} < {self.printer.literal(sp.Float(limit))})"
        return test

    def name(self, function: str) -> str:
        return f"symrot_{self.header}_{function}{self.suffix}"

    def entry(self, function: str, summary: str, signature: str, statements: list[Statement],
              notes: list[str]) -> dict[str, Any]:
        return {"c_name": self.name(function), "summary": summary, "equation": "D1-D5 of the sheet",
                "notes": notes, "ops": ops_of(statements), "signature": signature,
                "statements": statements, "batch_signature": None, "output": None}

    def nan_out(self, output: str, count: int, status: str = "") -> list[Statement]:
        nan = self.nan_fill(output, count)
        return [*nan, {"kind": "return", "value": status}]

    def scalars(self, tensor: str, sign: int, used: set[sp.Symbol]
                ) -> tuple[list[Statement], dict[sp.Symbol, sp.Expr], list[str]]:
        """Statements of T's coefficients and slopes among ``used`` (no unused C variable), the values
        of VALUES/SLOPES (0 for the others), and the names computed."""
        symbols = {**{VALUES[k]: f"{tensor}_{k}" for k in range(3)},
                   **{SLOPES[k]: slope_name(f"{tensor}_{k}") for k in range(3)}}
        names = [n for symbol, n in symbols.items() if symbol in used]
        body, values = self.coefficients(names)
        negated = {VALUES[1], SLOPES[1]}
        scalars = {symbol: (sign if symbol in negated else 1) * values[n] if symbol in used else sp.S.Zero
                   for symbol, n in symbols.items()}
        return body, scalars, names

    def transposed(self, tensor: str, plain: dict[sp.Symbol, sp.Expr]
                   ) -> tuple[list[Statement], dict[str, str]] | None:
        """Tᵀ = c0 I − c1 (p×) + c2 (p×)²: c1 and c1′ negated into variables of their own
        (``c_R_T_1 = -c_R_1``), and the renaming that turns T's entries into Tᵀ's. The entries are
        T's statements as printed, on the new names, so the two functions call one helper for them
        (:mod:`symrot.backends.c_entries`); the negation is exact. None where c1 or c1′ is a
        nonzero constant (folded into T's expressions: Tᵀ's print on their own)."""
        statements: list[Statement] = []
        names: dict[str, str] = {}
        for symbol in (VALUES[1], SLOPES[1]):
            value = plain[symbol]
            if value == 0:
                continue
            if not isinstance(value, sp.Symbol):
                return None
            name = f"c_{tensor}_T{str(value)[len(tensor) + 2:]}"
            statements.append(self.let(name, -value))
            names[str(value)] = name
        return statements, names

    def derivative(self, function: str) -> dict[str, Any]:
        tensor, sign, summary = DERIVATIVES[function]
        t = self.ctype
        statements: list[Statement] = [*self.prologue(), {"kind": "if", "condition": self.out_of_range(),
                                                          "then": self.nan_out("D", 9), "otherwise": []}]
        body, scalars, names = self.scalars(tensor, 1, set(tensor_derivative().terms))
        statements += body
        transposed = self.transposed(tensor, scalars) if sign < 0 else None
        if sign < 0 and transposed is None:
            scalars = self.scalars(tensor, sign, set(tensor_derivative().terms))[1]
        matrix = tensor_derivative().matrix(sp.Matrix(P), _vector("a"), scalars)
        replacements, entries = common_subexpressions(list(matrix), "dw")
        lets = [self.let(str(symbol), value) for symbol, value in replacements]
        lets += [self.set(f"D[{i}]", entry) for i, entry in enumerate(entries)]
        if transposed is not None:
            negated, renamed = transposed
            pattern = re.compile(r"\b(" + "|".join(map(re.escape, renamed)) + r")\b") if renamed else None
            lets = [{**s, "value": pattern.sub(lambda m: renamed[m[1]], s["value"])} if pattern else s
                    for s in lets]
            statements += negated
        statements += lets
        notes = ["Row-major D[3*i + j] = d(T a)_i / dp_j (column j: the derivative by p_j), a fixed.",
                 *self.validity_notes(), *self.coefficient_notes(names)]
        signature = f"void {self.name(function)}(const {t} p[3], const {t} a[3], {t} D[9])"
        return self.entry(function, f"{summary} for a fixed vector a", signature, statements, notes)

    def angular_acceleration(self) -> dict[str, Any]:
        t = self.ctype
        statements: list[Statement] = [*self.prologue(), {"kind": "if", "condition": self.out_of_range(),
                                                          "then": self.nan_out("alpha", 3), "otherwise": []}]
        body, scalars, names = self.scalars("H", 1, {*VALUES, *rate_vector()})
        statements += body
        given = tuple(sp.Symbol(f"pddot[{i}]", real=True) for i in range(3))
        w = tuple(sp.Symbol(f"w{i}", real=True) for i in range(3))
        cross, first = vector_entries(scalars[VALUES[0]], scalars[VALUES[1]], scalars[VALUES[2]], given, w)
        rate = rate_value(sp.Matrix(P), _vector("pdot"), scalars)
        statements += [self.let(f"w{i}", cross[i]) for i in range(3)]
        replacements, entries = common_subexpressions([first[i] + rate[i] for i in range(3)], "dw")
        statements += [self.let(str(symbol), value) for symbol, value in replacements]
        statements += [self.set(f"alpha[{i}]", entry) for i, entry in enumerate(entries)]
        notes = ["alpha = d omega/dt = H pddot + Hdot pdot for omega = H pdot (eq 20).",
                 *self.validity_notes(), *self.coefficient_notes(names)]
        signature = (f"void {self.name('angular_acceleration')}(const {t} p[3], const {t} pdot[3], "
                     f"const {t} pddot[3], {t} alpha[3])")
        return self.entry("angular_acceleration", "angular acceleration", signature, statements, notes)

    def compose_jacobians(self) -> dict[str, Any]:
        """J1 = H(p3)⁻¹ R(p2) H(p1), J2 = H(p3)⁻¹ H(p2): the same in every header
        (``templates/c/shared.h.j2``)."""
        return self.shared("compose_jacobians")

    def rescale_jacobian(self) -> dict[str, Any]:
        """H(q)⁻¹ H(p) for q = rescale(p), the identity where p is kept: the same in every header
        (``templates/c/shared.h.j2``)."""
        return self.shared("rescale_jacobian")

    def all(self) -> list[dict[str, Any]]:
        """After the operations of the header (they call compose, rescale, to_quaternion)."""
        return [*(self.derivative(f) for f in DERIVATIVES), self.angular_acceleration(),
                self.compose_jacobians(), self.rescale_jacobian()]
