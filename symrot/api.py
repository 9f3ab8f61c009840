"""The Python API: ``symrot.derive('4*tan(phi/4)')`` mirrors ``symrot derive``.

:class:`DerivationResult` wraps the symbolic core's :class:`~symrot.core.derivation.Derivation` with the
registry identity, a JSON-ready dictionary and a LaTeX display for Jupyter (``_repr_latex_``).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import sympy as sp

from symrot.core.budget import stage
from symrot.core.derivation import SCALAR_NAMES, TENSOR_NAMES, Derivation, Tensor, derive_expression
from symrot.core.errors import ParseError, SymrotError
from symrot.core.parsing import MAX_LENGTH, check_expression, parse_expression
from symrot.core.registry import (
    NamedParameterization,
    find_by_expression,
    is_identifier,
    looks_like_a_name,
    lookup,
)
from symrot.core.timeouts import time_limit
from symrot.core.validation import validate

DERIVE_TIME_LIMIT = 60.0
DEFAULT_SERIES_TERMS = 6
COEFFICIENT_KEYS = ("I", "px", "px2")


def resolve(expression: str | sp.Expr) -> tuple[sp.Expr, NamedParameterization | None]:
    """A registry identifier or an expression (parsed safely) → (p(φ), registry entry).

    Raises :class:`~symrot.core.errors.SymrotError` for anything else, in time bounded by the length
    caps: a string longer than :data:`~symrot.core.parsing.MAX_LENGTH` is refused before it is read,
    a SymPy expression is held to the parser's caps (:func:`~symrot.core.parsing.check_expression`).
    """
    if isinstance(expression, sp.Basic):
        with stage("parse"):
            checked = check_expression(expression)
        with stage("registry lookup"):
            return checked, find_by_expression(checked)
    if not isinstance(expression, str):
        raise ParseError("expression must be a string or a SymPy expression, "
                         f"got {type(expression).__name__}")
    if len(expression) > MAX_LENGTH:
        raise ParseError(f"expression is too long ({len(expression)} characters, at most {MAX_LENGTH})")
    text = expression.strip()
    if is_identifier(text) or looks_like_a_name(text):
        with stage("registry lookup"):
            entry = lookup(text)
        return entry.expression, entry
    with stage("parse"):
        expr = parse_expression(text)
    with stage("registry lookup"):
        return expr, find_by_expression(expr)


@dataclass
class DerivationResult:
    """Every derived quantity of one generating function, ready to display or serialize."""

    derivation: Derivation
    entry: NamedParameterization | None
    normalized: bool = False
    original_kappa: sp.Expr | None = None
    """κ of the expression as given, when ``normalize`` divided it out (eq 12)."""

    # -- direct access ------------------------------------------------------------------------
    @property
    def p(self) -> sp.Expr:
        return self.derivation.p

    @property
    def kappa(self) -> sp.Expr:
        return self.derivation.kappa

    def __getattr__(self, name: str) -> Any:
        if name in SCALAR_NAMES:
            return self.derivation.scalars[name]
        if name in TENSOR_NAMES:
            return self.derivation.tensors[name]
        raise AttributeError(name)

    def series(self, name: str, n_terms: int = DEFAULT_SERIES_TERMS) -> list[sp.Expr]:
        """Exact Taylor coefficients of coefficient ``name`` (e.g. 'H_2', 'nu') in ``x = |p|²``."""
        return self.derivation.series_in_x(name, n_terms)

    # -- serialization ----------------------------------------------------------------------
    def to_dict(self, series_terms: int = DEFAULT_SERIES_TERMS) -> dict[str, Any]:
        d = self.derivation
        out: dict[str, Any] = {
            "expression": str(d.p),
            "name": self.entry.identifier if self.entry else None,
            "equation": self.entry.equation if self.entry else None,
            "kappa": str(d.kappa),
            "normalized": self.normalized,
            "original_kappa": str(self.original_kappa) if self.original_kappa is not None else None,
        }
        out.update({name: str(d.scalars[name]) for name in SCALAR_NAMES})
        for name in TENSOR_NAMES:
            tensor = d.tensors[name]
            out[name] = dict(zip(COEFFICIENT_KEYS, map(str, tensor.simplified), strict=True))
        out["canonical"] = {name: _canonical_dict(d.tensors[name]) for name in TENSOR_NAMES}
        out["validity"] = validity_dict(self.derivation)
        out["series"] = {
            name: [str(c) for c in d.series_in_x(name, series_terms)]
            for name in d.coefficient_expressions()
        }
        return out

    def _repr_latex_(self) -> str:
        from symrot.backends.latex import derivation_display

        return derivation_display(self)


def validity_dict(derivation: Derivation) -> dict[str, Any]:
    """The validity range and singular angles (Section 3.4) as JSON-ready data."""
    from symrot.core.singularities import validity

    result = validity(derivation)
    return {
        "phi_max": str(result.phi_max),
        "phi_max_float": result.phi_max_float,
        "p_max_float": result.p_max_float,
        "numeric_only": result.numeric_only,
        "singularities": [
            {"phi": str(s.phi), "phi_float": s.phi_float, "cause": s.cause,
             "quantity": s.quantity, "limit": s.limit}
            for s in result.singularities
        ],
    }


def _canonical_dict(tensor: Tensor) -> dict[str, str]:
    matrix = tensor.canonical
    return {"axial": str(matrix[0, 0]), "real": str(matrix[1, 1]), "imag": str(matrix[2, 1])}


def derive(expression: str | sp.Expr, normalize: bool = False) -> DerivationResult:
    """Derive everything for a generating function (expression or registry identifier).

    Raises :class:`~symrot.core.errors.SymrotError` subclasses for invalid input; bounded in time.
    """
    if not isinstance(normalize, bool):
        raise SymrotError(f"normalize must be True or False, got {type(normalize).__name__}")
    expr, entry = resolve(expression)
    with time_limit(DERIVE_TIME_LIMIT, "derivation"):
        derivation = derive_expression(expr, normalize=normalize)
        original_kappa = validate(expr).kappa if normalize else None
    normalized = normalize and derivation.p != expr
    if normalized:
        with stage("registry lookup"):
            entry = find_by_expression(derivation.p)
    return DerivationResult(derivation, entry, normalized=normalized, original_kappa=original_kappa)


__all__ = ["DerivationResult", "SymrotError", "derive", "resolve"]
