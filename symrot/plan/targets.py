"""The plan's accuracy targets and work budgets: counts and ulps, never times, so that a plan is the
same on every machine and under any load."""

from __future__ import annotations

import numpy as np

MAX_TERMS = 24
CHEAP_TERMS = 8
"""A Horner polynomial of up to this many terms (8 fused multiply-adds) is cheaper than a closed
form with sin/cos (a libm call is 20–60 cycles) or a division: switches move up to where it stays
accurate, so that small rotations, the common case in time stepping, never reach libm."""
ALGEBRAIC_WORK = 4000
"""Total expansion size (:func:`symrot.plan.algebraic.reduction_size`, operations) the algebraic search
of one plan may simplify; past it, coefficients get branches. A count, not a time: the plan is
the same on every machine and under any load."""
PRECISIONS: dict[str, type[np.floating]] = {"float64": np.float64, "float32": np.float32}
CLOSED_TOLERANCE_ULP = 1.5
POLYNOMIAL_TOLERANCE_ULP = 2.0
"""A branch's Horner polynomial, measured on the grid below its switch, must stay within this
(the truncation estimate alone keeps it below a quarter ulp plus the rounding of Horner's steps)."""
ANGLE_TOLERANCE_ULP = 2.0
"""A closed inverse φ(s) is printed only when its measured error (beyond the conditioning of φ(s),
see :func:`closed_angle_error`) stays within this; otherwise the Newton angle is used."""
UNREAD_SCALARS = frozenset({"p_prime", "epsilon", "mu"})
"""Planned and printed beside the others (eqs 15, 16, 21), but no emitted function reads them (the
tangent's determinant is det H, the quaternion reads e₀ and ν): they do not bound the domain."""
NEWTON_ITERATIONS = 6
START_TERMS = 8
