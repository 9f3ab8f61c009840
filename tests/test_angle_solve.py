"""symrot.plan.angle_solve: the reference angle φ(s) against closed inverses, at the precisions the domain
sweep (up to 240 digits) and the Newton start (30 digits) use, with far fewer evaluations of p than
bisection's one per bit."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import mpmath
import pytest
import sympy as sp

from symrot.core.parsing import PHI
from symrot.plan.angle_solve import angle_of_length

# p, its closed inverse φ(s), φ_max: a pole (tan, 1/cos), a fold (2 sin(φ/2): p′ = 0 at π), and
# the identity-like rotation vector
CASES = [
    (4 * sp.tan(PHI / 4), lambda s: 4 * mpmath.atan(s / 4), 2 * mpmath.pi),
    (sp.tan(PHI / 2), lambda s: 2 * mpmath.atan(s), mpmath.pi),
    (2 * sp.sin(PHI / 2), lambda s: 2 * mpmath.asin(s / 2), mpmath.pi),
    (PHI, lambda s: s, mpmath.mpf(1000)),
]


def _counted(p: sp.Expr) -> tuple[Callable[[Any], Any], Callable[[Any], Any], list[int]]:
    calls = [0]
    function = sp.lambdify(PHI, p, "mpmath")

    def p_of(theta: Any) -> Any:
        calls[0] += 1
        return function(theta)

    return p_of, sp.lambdify(PHI, sp.diff(p, PHI), "mpmath"), calls


@pytest.mark.parametrize(("p", "inverse", "phi_max"), CASES, ids=[str(c[0]) for c in CASES])
@pytest.mark.parametrize("digits", [30, 120, 240])
def test_angle_matches_the_closed_inverse(p: sp.Expr, inverse: Callable[[Any], Any], phi_max: Any,
                                          digits: int) -> None:
    p_of, slope_of, _ = _counted(p)
    with mpmath.workdps(digits):
        top = p_of(mpmath.mpf(phi_max) * (1 - mpmath.mpf(10) ** -6))
        for exponent in range(-100, 400, 7):
            s = mpmath.mpf(2) ** exponent
            if not s < top:
                continue
            exact = inverse(s)
            found = angle_of_length(p_of, slope_of, s, phi_max)
            assert abs(found - exact) <= 4 * mpmath.eps * phi_max, (exponent, found, exact)


def test_next_to_a_pole_it_takes_few_evaluations() -> None:
    """Newton on 1/p is nearly linear next to the pole: at 240 digits (800 bits, as many bisection
    steps) a point 2^-150 from φ_max needs a handful of evaluations."""
    p_of, slope_of, calls = _counted(4 * sp.tan(PHI / 4))
    with mpmath.workdps(240):
        for exponent in (50, 150, 300):
            calls[0] = 0
            angle_of_length(p_of, slope_of, mpmath.mpf(2) ** exponent, 2 * mpmath.pi)
            assert calls[0] <= 20, (exponent, calls[0])


def test_an_undefined_p_counts_as_beyond_the_root() -> None:
    """Past the edge p is complex (√(1 − φ²/4)·…) or infinite: bisection then moves the upper end."""
    p = PHI * sp.sqrt(1 - PHI**2 / 16)  # complex beyond φ = 4, increasing to φ = 2√2
    p_of, slope_of, _ = _counted(p)
    with mpmath.workdps(40):
        s = mpmath.mpf(1)
        found = angle_of_length(p_of, slope_of, s, 10)  # starts at φ = 5, where p is complex
        assert abs(p_of(found) - s) < mpmath.mpf(10) ** -35
