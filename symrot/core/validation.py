"""Validation of a generating function p(φ) against the requirements of Section 3.1.

A generating function must be real, odd, vanish at 0, be real-analytic at 0 (a Taylor series
exists) and have a finite, non-zero normalization κ = lim p/φ (eq 12). Each failure raises
:class:`InvalidGeneratingFunction` with the reason; nothing downstream runs on an invalid p.
"""

from __future__ import annotations

from dataclasses import dataclass

import mpmath
import sympy as sp

from symrot.core.errors import InvalidGeneratingFunction, NonAnalyticError, SymrotError, SymrotTimeout
from symrot.core.parsing import PHI
from symrot.core.series import InsufficientOrder, coefficient_list, taylor_series

CHECK_ORDER = 16
"""Order through which the Taylor series is checked for oddness."""

SAMPLE_ANGLES = ("0.001", "0.37", "0.81", "1.23")
"""Angles (rad) at which oddness and realness are checked numerically at 50 digits."""


@dataclass(frozen=True)
class ValidatedFunction:
    expression: sp.Expr
    kappa: sp.Expr
    taylor: tuple[sp.Expr, ...]
    """Exact Taylor coefficients of p(φ), index k ↔ φ^k, k < CHECK_ORDER."""


def evaluate(expr: sp.Expr, angle: mpmath.mpf | str, digits: int = 50) -> mpmath.mpc:
    """Evaluate ``expr`` at φ = angle with ``digits`` significant digits (mpmath, not floats)."""
    with mpmath.workdps(digits + 10):
        value = sp.N(expr.subs(PHI, sp.Float(str(angle), digits + 10)), digits + 5)
        return mpmath.mpc(complex(value)) if not value.is_real else mpmath.mpf(value)


def _evaluate_or_inf(expr: sp.Expr, angle: str) -> mpmath.mpf | mpmath.mpc:
    """``evaluate``, with an exponent beyond mpmath's range (sinh of sinh of ...) read as inf."""
    try:
        return evaluate(expr, angle)
    except OverflowError:
        return mpmath.inf


def validate(expr: sp.Expr) -> ValidatedFunction:
    """Check ``expr`` as a generating function and return it with κ and its Taylor series."""
    others = expr.free_symbols - {PHI}
    if others:
        hint = ("; the angle is symrot.PHI, a real symbol (sympy.Symbol('phi', real=True))"
                if any(str(symbol) == str(PHI) for symbol in others) else "")
        raise InvalidGeneratingFunction(f"p must depend on phi only{hint}")
    if PHI not in expr.free_symbols:
        raise InvalidGeneratingFunction("p does not depend on phi")
    try:
        series = taylor_series(expr, CHECK_ORDER)
    except NonAnalyticError as exc:
        raise InvalidGeneratingFunction(f"p is not real-analytic at phi = 0: {exc}") from None
    except InsufficientOrder:
        raise InvalidGeneratingFunction("p vanishes to high order at phi = 0 (kappa = 0)") from None
    if series.is_zero:
        raise InvalidGeneratingFunction(
            f"p vanishes to order {CHECK_ORDER} at phi = 0, so kappa = lim p/phi = 0 (eq 12)"
        )
    valuation = series.valuation
    if valuation < 0:
        raise InvalidGeneratingFunction("p has a pole at phi = 0, so kappa = lim p/phi is infinite")
    if valuation == 0:
        raise InvalidGeneratingFunction("p(0) must be 0 (p must be odd)")
    coefficients = coefficient_list(series, 0, CHECK_ORDER)
    even = [k for k in range(0, CHECK_ORDER, 2) if coefficients[k] != 0]
    if even:
        raise InvalidGeneratingFunction(
            f"p is not odd: its Taylor series has a phi^{even[0]} term ({coefficients[even[0]]})"
        )
    if valuation > 1:
        raise InvalidGeneratingFunction(
            f"kappa = lim p/phi = 0 (eq 12): p starts at phi^{valuation}"
        )
    kappa = coefficients[1]
    _check_numerically(expr)
    return ValidatedFunction(expr, kappa, tuple(coefficients))


def _check_numerically(expr: sp.Expr) -> None:
    """Oddness and realness away from 0, where the series check says nothing.

    p must be real near 0 (the smallest sample angle). At larger angles a function may leave its
    real domain on both sides (that only limits its validity range), but never on one side only,
    and wherever p(±φ) are both real they must satisfy p(−φ) = −p(φ).
    """
    for index, angle in enumerate(SAMPLE_ANGLES):
        try:
            plus, minus = (_evaluate_or_inf(expr, a) for a in (angle, "-" + angle))
        except SymrotTimeout:
            raise  # running out of time says nothing about p
        except (TypeError, ValueError, ZeroDivisionError, SymrotError):
            raise InvalidGeneratingFunction(f"p cannot be evaluated at phi = ±{angle}") from None
        real_plus = not isinstance(plus, mpmath.mpc) and mpmath.isfinite(plus)
        real_minus = not isinstance(minus, mpmath.mpc) and mpmath.isfinite(minus)
        if not real_plus and not real_minus and index > 0:
            continue
        if not (real_plus and real_minus):
            raise InvalidGeneratingFunction(f"p is not real and finite at phi = ±{angle}")
        scale = max(abs(plus), abs(minus), mpmath.mpf(10) ** -40)
        if abs(plus + minus) > scale * mpmath.mpf(10) ** -40:
            raise InvalidGeneratingFunction(
                f"p is not odd: p({angle}) + p(-{angle}) = {mpmath.nstr(plus + minus, 5)}"
            )
