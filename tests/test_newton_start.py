"""The plan's count of Newton steps (symrot.newton_start.measured_iterations) runs the printed
iteration, and names the sizes whose angle the steps do not reach, so that the range ends there."""

from __future__ import annotations

import math

import numpy as np
import sympy as sp

from symrot.newton_start import MAX_ITERATIONS, FarStart, measured_iterations
from symrot.parsing import PHI

SERIES_ONLY = FarStart(kind="linear", scale=1.0, order=1, chebyshev=(0.0,), switch=math.inf, measured=0.0)
"""A far start never used: every lane starts from the reverted series φ ≈ s."""


def _sinh_models(wrong_above: float) -> tuple:
    def ratio(phi: np.ndarray) -> np.ndarray:  # p(φ)/φ, printed 10⁻⁶ too large above ``wrong_above``
        return np.sinh(phi) / phi * np.where(phi > wrong_above, 1 + 1e-6, 1.0)

    return ratio, np.cosh


def test_every_angle_reached_counts_steps_and_no_limit() -> None:
    angles = np.geomspace(1e-3, 3.0, 40)
    count = measured_iterations(sp.sinh(PHI), sp.cosh(PHI), [sp.Integer(1)], SERIES_ONLY, angles, 6.0,
                                np.float64, _sinh_models(math.inf), False, 6.0)
    assert count.steps < MAX_ITERATIONS and count.unconverged == math.inf


def test_angles_the_steps_do_not_reach_end_the_range_at_the_smallest_size() -> None:
    """A printed p(φ)/φ that is 10⁻⁶ too large above φ = 1 (as a form that loses digits there
    would be): those lanes converge to the wrong angle, whatever the count of steps."""
    angles = np.geomspace(1e-3, 3.0, 40)
    count = measured_iterations(sp.sinh(PHI), sp.cosh(PHI), [sp.Integer(1)], SERIES_ONLY, angles, 6.0,
                                np.float64, _sinh_models(1.0), False, 6.0)
    first_wrong = float(np.sinh(angles[angles > 1.0][0]))
    assert count.steps == MAX_ITERATIONS
    assert math.isclose(count.unconverged, first_wrong, rel_tol=1e-12)
