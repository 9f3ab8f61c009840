"""The derivatives of :mod:`symrot.core.derivatives` as NumPy statements (issue 19).

The core derives ∂(T a)/∂p as rational combinations of the scalars c_k, c_k′ on tensors built from
p and a, and Ṫ ṗ on vectors; this module prints those combinations term by term (nothing is
typed in here but the NumPy spelling of each basis tensor). In the printed code ``c0, c1, c2`` and
``d0, d1, d2`` are the coefficients and their slopes of shape (...,), ``p`` and ``a`` the vectors of
shape (..., 3), and ``pa = p × a``, ``ppa = p × (p × a)``, ``pta = p·a`` are computed first.
"""

from __future__ import annotations

import sympy as sp

from symrot.core.derivatives import SLOPES, VALUES, rate_vector, tensor_derivative

_SCALARS = {**{s: f"c{k}" for k, s in enumerate(VALUES)}, **{s: f"d{k}" for k, s in enumerate(SLOPES)}}

_OUTER_VECTORS = {"a*p": "a", "(p x a)*p": "pa", "(p x (p x a))*p": "ppa"}
"""Basis tensors u ⊗ p = u pᵀ by their vector u."""
_MATRICES = {"[a x]": "_skew(a)", "[(p x a) x]": "_skew(pa)", "[p x][a x]": "_skew(p) @ _skew(a)"}
_VECTORS = {"a (p.a)": "a * pta[..., None]", "(p x a) (p.a)": "pa * pta[..., None]",
            "(p x (p x a)) (p.a)": "ppa * pta[..., None]", "(p x a) x a": "_cross(pa, a)"}
_PREAMBLE = ["pa = _cross(p, a)", "ppa = _cross(p, pa)"]
_DOT = "pta = numpy.einsum('...i,...i->...', p, a)"


def _factor(scalar: sp.Symbol, rational: sp.Rational) -> str:
    name = _SCALARS[scalar]
    if rational == 1:
        return name
    if rational == -1:
        return f"(-{name})"
    return f"({float(rational)!r} * {name})"


def derivative_lines() -> list[str]:
    """Statements returning ∂(T a)/∂p (..., 3, 3): the rank-one part u pᵀ, then the matrices."""
    outer: list[str] = []
    matrices: list[str] = []
    for scalar, combination in tensor_derivative().terms.items():
        for name, rational in combination.items():
            factor = _factor(scalar, rational)
            if name in _OUTER_VECTORS:
                outer.append(f"{factor}[..., None] * {_OUTER_VECTORS[name]}")
            else:
                matrices.append(f"{factor}[..., None, None] * ({_MATRICES[name]})")
    lines = list(_PREAMBLE)
    lines.append("u = " + " + ".join(outer) if outer else "u = numpy.zeros_like(a)")
    lines.append("out = u[..., :, None] * p[..., None, :]")
    lines += [f"out = out + {term}" for term in matrices]
    lines.append("return out")
    return lines


def rate_lines() -> list[str]:
    """Statements returning Ṫ ṗ = [∂(T a)/∂p]_(a = ṗ) ṗ for a = ṗ, (..., 3)."""
    terms = [f"{_factor(scalar, rational)}[..., None] * {_VECTORS[name]}"
             for scalar, combination in rate_vector().items() for name, rational in combination.items()]
    return [*_PREAMBLE, _DOT, "return " + (" + ".join(terms) if terms else "numpy.zeros_like(a)")]
