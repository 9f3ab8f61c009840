"""The plan's count of Newton steps (symrot.plan.newton_start.measured_iterations) runs the printed
iteration, and names the sizes whose angle the steps do not reach, so that the range ends there;
next to a fold or an asin edge the steps are Newton's in w = (φ_max − φ)^k (edge_step)."""

from __future__ import annotations

import math
from typing import Literal

import mpmath
import numpy as np
import pytest
import sympy as sp

from symrot.core.parsing import PHI
from symrot.plan.newton_start import (
    CHANGE,
    EDGE_STEP,
    MAX_ITERATIONS,
    FarStart,
    edge_exponent,
    edge_step,
    far_start,
    measured_iterations,
    newton_lanes,
)

SERIES_ONLY = FarStart(kind="linear", scale=1.0, order=1, chebyshev=(0.0,), switch=math.inf, measured=0.0)
"""A far start never used: every lane starts from the reverted series φ ≈ s."""


def _sinh_models(wrong_above: float) -> tuple:
    def ratio(phi: np.ndarray) -> np.ndarray:  # p(φ)/φ, printed 10⁻⁶ too large above ``wrong_above``
        return np.sinh(phi) / phi * np.where(phi > wrong_above, 1 + 1e-6, 1.0)

    return ratio, np.cosh


def test_every_angle_reached_counts_steps_and_no_limit() -> None:
    angles = np.geomspace(1e-3, 3.0, 40)
    models = _sinh_models(math.inf)
    lanes = newton_lanes(sp.sinh(PHI), sp.cosh(PHI), angles, 6.0, np.float64, models[0])
    count = measured_iterations(lanes, [sp.Integer(1)], SERIES_ONLY, models, False, 6.0)
    assert count.steps < MAX_ITERATIONS and count.unconverged == math.inf


def test_angles_the_steps_do_not_reach_end_the_range_at_the_smallest_size() -> None:
    """A printed p(φ)/φ that is 10⁻⁶ too large above φ = 1 (as a form that loses digits there
    would be): those lanes converge to the wrong angle, whatever the count of steps."""
    angles = np.geomspace(1e-3, 3.0, 40)
    models = _sinh_models(1.0)
    lanes = newton_lanes(sp.sinh(PHI), sp.cosh(PHI), angles, 6.0, np.float64, models[0])
    count = measured_iterations(lanes, [sp.Integer(1)], SERIES_ONLY, models, False, 6.0)
    first_wrong = float(np.sinh(angles[angles > 1.0][0]))
    assert count.steps == MAX_ITERATIONS
    assert math.isclose(count.unconverged, first_wrong, rel_tol=1e-12)


def _far(kind: Literal["fold", "linear", "ratio"], order: int = 1) -> FarStart:
    return FarStart(kind=kind, scale=1.0, order=order, chebyshev=(0.0,), switch=math.inf, measured=0.0)


def test_edge_exponent_names_folds_and_asin_edges_only() -> None:
    linear = _far("linear")
    assert edge_exponent(sp.asin(PHI), linear, 1.0) == sp.Rational(1, 2)  # p′ = (1 − φ²)^(−1/2)
    assert edge_exponent(sp.asin(PHI / 3) + PHI, linear, 3.0) == sp.Rational(1, 2)
    assert edge_exponent(PHI, linear, 1.0) is None  # an ordinary end of the range
    assert edge_exponent(PHI - PHI**3 / 3, _far("fold", 2), 1.0) == 2  # the far start's fold order
    assert edge_exponent(sp.sinh(PHI), _far("ratio"), 6.0) is None  # unbounded p


def test_the_far_start_finds_the_fold_order_of_the_edge() -> None:
    """p′ = 1 − φ² and (1 − φ)²: folds of order 2 and 3, which ``edge_exponent`` takes from it."""
    for p, p_max, order in ((PHI - PHI**3 / 3, 2 / 3, 2), (PHI - PHI**2 + PHI**3 / 3, 1 / 3, 3)):
        far = far_start(p, p_max, 1.0, (sp.Integer(1),))
        assert (far.kind, far.order) == ("fold", order)
        assert edge_exponent(p, far, 1.0) == order


@pytest.mark.parametrize("edge", [sp.Rational(1, 2), sp.Rational(1, 3), sp.Integer(2), sp.Integer(3),
                                  sp.Integer(4)])
def test_edge_step_is_newton_in_w_without_cancellation(edge: sp.Rational) -> None:
    """φ_max − δ(1 + u)^(1/k) at 50 digits (u = k c/δ, the Newton step in w = δ^k), and Newton's
    φ − c in the limit of small steps, where φ_max − δ(…) would lose the digits."""
    step = sp.lambdify((PHI, CHANGE, EDGE_STEP), edge_step(edge), "mpmath")
    with mpmath.workdps(50):
        top, k = mpmath.mpf(2), mpmath.mpf(edge.p) / edge.q
        for phi, change in ((1.5, 0.1), (1.9, -0.05), (0.5, 0.3)):
            delta = top - phi
            u = k * mpmath.mpf(change) / delta
            expected = top - delta * (1 + u) ** (1 / k)
            assert abs(step(mpmath.mpf(phi), mpmath.mpf(change), u) - expected) < mpmath.mpf(10) ** -45
    tiny = np.float64(1e-12)
    phi = np.float64(1e-3)
    numeric = sp.lambdify((PHI, CHANGE, EDGE_STEP), edge_step(edge), "numpy")
    value = numeric(phi, tiny, float(edge) * tiny / 1.999)
    assert abs(value - (phi - tiny)) <= 4 * np.spacing(phi)


def _asin_lanes() -> tuple:
    p = sp.asin(PHI)
    models = (lambda phi: np.arcsin(phi) / phi, lambda phi: 1 / np.sqrt(1 - phi * phi))
    angles = 1 - np.geomspace(1e-2, 1e-12, 11)
    return p, models, newton_lanes(p, sp.diff(p, PHI), angles, 1.0, np.float64, models[0])


def test_an_infinite_slope_bisects_and_newton_in_w_converges_from_the_edge() -> None:
    """From a start at φ_max = 1, where p′ = ∞, a step in φ is zero: it stayed there (row 187 of
    docs/accuracy_hypothesis.md was NaN for φ > 0.99995; row 113 stalled where its printed p′
    overflowed next to a pole). The iteration now bisects where p′ is not finite, and in
    w = √(1 − φ) it converges from there in a few steps."""
    _, models, lanes = _asin_lanes()
    at_edge = FarStart(kind="linear", scale=math.pi / 2, order=1, chebyshev=(1.0,), switch=0.0, measured=1.0)
    plain = measured_iterations(lanes, [sp.Integer(1)], at_edge, models, False, 1.0)
    edge = measured_iterations(lanes, [sp.Integer(1)], at_edge, models, False, 1.0, sp.Rational(1, 2))
    assert plain.unconverged == edge.unconverged == math.inf
    assert edge.steps < 16 < 32 < plain.steps


def test_newton_in_w_needs_fewer_steps_from_the_far_start() -> None:
    p, models, lanes = _asin_lanes()
    series = tuple(sp.Rational((-1) ** k, math.factorial(2 * k + 1)) for k in range(8))  # φ = sin(s)
    far = far_start(p, math.pi / 2, 1.0, series)
    plain = measured_iterations(lanes, series, far, models, False, 1.0)
    edge = measured_iterations(lanes, series, far, models, False, 1.0, sp.Rational(1, 2))
    assert plain.unconverged == edge.unconverged == math.inf
    assert edge.steps < plain.steps


def test_lanes_of_a_residual_far_off_in_float32_stay_finite_without_warnings() -> None:
    """The tolerance divides the residual's error by ε s; with s a float32, ε s was a float32 and
    the quotient overflowed in the cast (a RuntimeWarning through the Python API while planning
    sin φ + sin(3φ)/9). The residual's share is capped at RESIDUAL_ULPS, so the tolerance is finite."""
    import warnings

    with warnings.catch_warnings():
        warnings.simplefilter("error")
        lanes = newton_lanes(PHI, sp.Integer(1), np.array([0.5, 1.0]), 2 * math.pi, np.float32,
                             lambda t: np.full_like(t, 1e35))
    assert np.all(np.isfinite(lanes.tolerance)) and np.all(lanes.tolerance > 0)


def test_the_tolerance_next_to_a_fold_is_the_width_of_the_angles_that_round_alike() -> None:
    """At φ_max(1 − 10⁻⁹) of eq 35 (a triple fold at 2π), s = p(φ) rounds to float64's p_max and
    the first-order tolerance 2ε s/p′ was infinite (p′ = 0 at the exact angle, 2π): any iterate
    passed, and one that ended 0.35 rad off (a bisection, then linear steps in φ) was counted as
    converged. The angles whose p lies within ε s of s span ~3·10⁻⁵ rad there (tolerance 9.7·10⁻⁵)."""
    p = sp.cbrt(6 * (PHI - sp.sin(PHI)))
    slope = sp.diff(p, PHI)
    angles = np.array([2 * math.pi * (1 - 1e-9), 1.0])
    lanes = newton_lanes(p, slope, angles, 2 * math.pi, np.float64, lambda phi: np.zeros_like(phi), 1.0)
    assert lanes.tolerance[0] < 1e-3
    assert lanes.tolerance[1] < 1e-14  # away from the fold the first-order width stands
