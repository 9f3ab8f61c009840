"""The reference angle φ(s) of a length s = |p|: the root of p(φ) = s on 0 < φ < φ_max, in mpmath.

Plan-layer numerics shared by the domain sweep (:mod:`symrot.plan.domain`, up to 240 digits) and the
Newton start (:mod:`symrot.plan.newton_start`, 30 digits). p is increasing on [0, φ_max) (p′ > 0 inside
the validity range of §3.4), so the root is bracketed and bisection always converges; but
bisection needs one evaluation of p per bit (800 at 240 digits): for φ/cos(φ/4), which has no
closed inverse, it was a quarter of the plan's time.

:func:`angle_of_length` therefore takes Newton steps on g(φ) = 1/p(φ) − 1/s, which is nearly linear
next to a pole of p (p ≈ c/(φ_max − φ): one step lands on the root, where Newton on p − s
overshoots past the pole), and falls back on bisection whenever a step leaves the bracket (next
to a fold, where p′ → 0).
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import mpmath

Function = Callable[[Any], Any]


def angle_of_length(p_of: Function, slope_of: Function, s: Any, phi_max: Any) -> Any:
    """φ in (0, φ_max) with p(φ) = s at the working precision of mpmath (module docstring).

    ``p_of`` and ``slope_of`` evaluate p and p′ in mpmath; a non-finite value (past the pole or
    the edge) counts as p ≥ s. The result is within φ_max·2^−prec of the root, as bisection's."""
    low, high = mpmath.mpf(0), mpmath.mpf(phi_max)
    tolerance = high * mpmath.eps
    theta = high / 2
    for _ in range(int(mpmath.mp.prec) + 8):  # bisection's bound: each fallback halves the bracket
        value = _finite(p_of, theta)
        if value is None or value >= s:
            high = theta
        else:
            low = theta
        candidate = _newton_step(theta, value, _finite(slope_of, theta), s)
        if candidate is None or not low <= candidate <= high:  # θ itself is an end of the bracket
            candidate = (low + high) / 2
        if abs(candidate - theta) <= tolerance or high - low <= tolerance:
            return candidate
        theta = candidate
    return (low + high) / 2


def _newton_step(theta: Any, value: Any, slope: Any, s: Any) -> Any:
    """φ + (1/p − 1/s)·p²/p′: Newton on 1/p(φ) = 1/s, or None where it is undefined."""
    if value is None or slope is None or value == 0 or slope == 0:
        return None
    return theta + (1 / value - 1 / s) * value * value / slope


def _finite(function: Function, theta: Any) -> Any:
    """function(θ), or None where it is infinite, complex or undefined."""
    try:
        value = function(theta)
    except (ZeroDivisionError, ValueError, OverflowError):
        return None
    if isinstance(value, mpmath.mpc):
        if value.imag != 0:
            return None
        value = value.real
    return value if mpmath.isfinite(value) else None
