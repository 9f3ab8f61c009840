"""Exact truncated power series of generating functions and their derived coefficients.

:func:`taylor_series` expands an expression in φ with the engine of :mod:`symrot.core.series_engine`
(never ``sympy.series``/``limit``, which can run for minutes on composed expressions), growing its
working order past cancellations and switching from QQ to EX when a coefficient is irrational;
:func:`revert` and :func:`compose_even_in_x` turn series in φ into series in p and in x = |p|².
"""

from __future__ import annotations

import sympy as sp
from sympy.polys.domains import EX
from sympy.polys.ring_series import rs_mul, rs_series_inversion, rs_trunc
from sympy.polys.rings import PolyElement, PolyRing

from symrot.core.errors import InvalidGeneratingFunction, SymrotError
from symrot.core.series_engine import (
    Coefficient,
    InsufficientOrder,
    NeedsSymbolicDomain,
    Series,
    SeriesEngine,
    exact_number,
    series_ring,
)

_MAX_WORKING_ORDER = 160


def taylor_series(expr: sp.Expr, order: int) -> Series:
    """Series of ``expr`` in φ exact up to (excluding) φ**order.

    The working order grows until cancellations leave at least ``order`` exact terms; the
    domain switches from QQ to EX when a coefficient is irrational.
    """
    domain_name = "QQ"
    slack = 8
    expr = with_acos_as_asin(expr)
    while True:
        working = order + slack
        if working > _MAX_WORKING_ORDER:
            raise SymrotError(
                f"could not expand {expr} to order {order}: cancellation exceeds the working order"
            )
        try:
            result = SeriesEngine(working, domain_name).series(expr)
        except NeedsSymbolicDomain:
            if domain_name == "EX":
                raise SymrotError(f"cannot represent the series coefficients of {expr}") from None
            domain_name = "EX"
            continue
        except InsufficientOrder:
            slack *= 2
            continue
        if result.order >= order:
            return result
        slack *= 2


def with_acos_as_asin(expr: sp.Expr) -> sp.Expr:
    """acos u as π/2 − asin u, an identity on the principal branches: in p = π/2 − acos φ the two
    π/2 then cancel in SymPy's sums, and the series stays over QQ. Over EX (π a coefficient), every
    series of that p took ten times as long (28 of its 51 s of planning, profiled)."""
    if not expr.has(sp.acos):
        return expr
    return expr.replace(sp.acos, lambda u: sp.pi / 2 - sp.asin(u))


def coefficient_list(series: Series, start: int, stop: int) -> list[sp.Expr]:
    """Coefficients of φ**k, k in [start, stop), as SymPy numbers."""
    domain = series.ring.domain
    return [exact_number(domain.to_sympy(c)) if domain == EX else domain.to_sympy(c)
            for c in series.coefficients(start, stop)]


def _domain_for(coeffs: list[sp.Expr]) -> tuple[PolyRing, PolyElement]:
    return series_ring("QQ" if all(c.is_Rational for c in coeffs) else "EX")


def compose(outer: list[Coefficient], inner: PolyElement, order: int) -> PolyElement:
    """Σ outer[k] inner^k mod x**order by Horner's rule (inner(0) must be 0)."""
    x = inner.ring.gens[0]
    result = inner.ring.zero
    for coefficient in reversed(outer):
        result = rs_mul(result, inner, x, order) + coefficient
    return rs_trunc(result, x, order)


def revert(p_coeffs: list[sp.Expr], order: int) -> list[sp.Expr]:
    """Series reversion: given p(φ) = Σ a_k φ^k with a_0 = 0, a_1 ≠ 0, return b_k with
    φ = Σ b_k p^k + O(p**order).

    Newton's iteration Φ ← Φ − (P(Φ) − p)/P'(Φ) doubles the number of exact terms per pass,
    with compositions by Horner's rule: O(order^3 log order) exact operations.
    """
    if len(p_coeffs) < order:
        raise InsufficientOrder("not enough coefficients of p to revert")
    poly_ring, x = _domain_for(p_coeffs[:order])
    domain = poly_ring.domain
    a = [domain.from_sympy(c) for c in p_coeffs[:order]]
    if a[0]:
        raise InvalidGeneratingFunction("p(0) is not 0")
    if not a[1]:
        raise InvalidGeneratingFunction("p'(0) = 0: p cannot be inverted near 0")
    derivative = [a[k + 1] * (k + 1) for k in range(order - 1)]
    phi = x * (domain.one / a[1])
    exact = 2
    while exact < order:
        exact = min(2 * exact, order)
        residual = compose(a, phi, exact) - x
        slope = compose(derivative, phi, exact)
        phi = rs_trunc(phi - rs_mul(residual, rs_series_inversion(slope, x, exact), x, exact),
                       x, exact)
    return [domain.to_sympy(phi.coeff(x**k)) if k else sp.S.Zero for k in range(order)]


def compose_even_in_x(even_coeffs: list[sp.Expr], phi_of_p: list[sp.Expr], n_terms: int
                      ) -> list[sp.Expr]:
    """Given c(φ) = Σ c_k φ^k (even) and φ(p) = Σ b_k p^k (odd), return d_j with
    c = Σ d_j x^j, x = p², exact for j < n_terms."""
    order = 2 * n_terms
    everything = list(even_coeffs[:order]) + list(phi_of_p[:order])
    poly_ring, x = _domain_for(everything)
    domain = poly_ring.domain
    phi = poly_ring({(k,): domain.from_sympy(b) for k, b in enumerate(phi_of_p[:order]) if b})
    phi_squared = rs_mul(phi, phi, x, order)
    halves = [domain.from_sympy(even_coeffs[2 * j]) for j in range(n_terms)]
    in_p = compose(halves, phi_squared, order)
    values = [domain.to_sympy(in_p.coeff(x ** (2 * j)) if j else in_p.coeff(1)) for j in range(n_terms)]
    return [exact_number(v) if j else v for j, v in enumerate(values)]


__all__ = ["InsufficientOrder", "Series", "coefficient_list", "compose", "compose_even_in_x", "revert",
           "taylor_series"]
