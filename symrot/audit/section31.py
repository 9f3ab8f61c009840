"""Section 3.1: eqs (14)–(16), (18), (19) for any generating function.

Run over the Table-1 rows, det H = 1 (eq 35) and the sine/tangent families m = 1..6, at 50 digits
with random angles in (0.2, 1.2) (inside every member's range of validity) and random axes.
"""

from __future__ import annotations

import mpmath
import sympy as sp

from ..validation import evaluate
from .checks import DEFINITION, HOLDS, Check, Outcome
from .composition import SEEDS, _cross, _dot, _pair
from .definitions import unit_normalized_functions
from .numeric import DIGITS, TOLERANCE, rng, rotation, skew, unit


def _scalars(expr: sp.Expr, angle: mpmath.mpf) -> tuple[mpmath.mpf, mpmath.mpf, mpmath.mpf]:
    """p, ν (15), ε (16) at one angle."""
    p = evaluate(expr, mpmath.nstr(angle, DIGITS + 5), DIGITS + 10)
    return p, 2 * mpmath.sin(angle / 2) / p, 2 * mpmath.tan(angle / 2) / p


def _over_functions(residual: object) -> tuple[mpmath.mpf, int]:
    worst, functions = mpmath.mpf(0), unit_normalized_functions()
    with mpmath.workdps(DIGITS):
        for index, (_, expr) in enumerate(functions):
            worst = max(worst, residual(expr, index))  # type: ignore[operator]
    return worst, len(functions)


def _verdict(worst: mpmath.mpf, count: int, what: str) -> Outcome:
    if worst > TOLERANCE:
        raise ArithmeticError(f"{what}: residual {mpmath.nstr(worst, 5)}")
    return Outcome(HOLDS, f"{what}: max residual {mpmath.nstr(worst, 3)} over {count} generating "
                   "functions (Table 1, eq 35, sine/tangent m = 1..6)")


def _eq14() -> Outcome:
    def residual(expr: sp.Expr, index: int) -> mpmath.mpf:
        r = rng(index)
        angle = mpmath.mpf(r.uniform(0.2, 1.2))
        u = unit([mpmath.mpf(r.uniform(-1, 1)) for _ in range(3)])
        p, nu, eps = _scalars(expr, angle)
        p_cross = skew([p * x for x in u])
        printed = mpmath.eye(3) + nu**2 / eps * p_cross + nu**2 / 2 * p_cross * p_cross
        return mpmath.mnorm(printed - rotation(angle, u), 1)
    return _verdict(*_over_functions(residual), "eq (14) against eq (1)")


def _composition(vector: bool) -> Outcome:
    def residual(expr: sp.Expr, index: int) -> mpmath.mpf:
        q = _pair(SEEDS[index % len(SEEDS)], max_angle=1.2)
        p1, nu1, eps1 = _scalars(expr, q.phi1)
        p2, nu2, eps2 = _scalars(expr, q.phi2)
        p3, nu3, eps3 = _scalars(expr, q.phi3)
        a, b = nu1 * p1 * q.u1, nu2 * p2 * q.u2
        if not vector:
            return abs(nu3 / eps3 - (nu1 / eps1 * nu2 / eps2 - _dot(a, b) / 4))
        return mpmath.mnorm(nu3 * p3 * q.u3 - (nu1 / eps1 * b + nu2 / eps2 * a - _cross(a, b) / 2), 1)
    return _verdict(*_over_functions(residual), "against R3 = R2 R1")


CHECKS = [
    Check("14", "R = I + nu^2/eps (p x) + nu^2/2 (p x)^2", "numeric, any p", _eq14),
    Check("15", "nu = 2 sin(phi/2)/p", "definition",
          lambda: Outcome(DEFINITION, "defines nu; used by (14), (18), (19) and Table 1")),
    Check("16", "eps = 2 tan(phi/2)/p", "definition",
          lambda: Outcome(DEFINITION, "defines epsilon; used by (14), (18), (19) and Table 1")),
    Check("18", "nu3/eps3 = nu1/eps1 nu2/eps2 - (nu1 p1).(nu2 p2)/4", "numeric, any p",
          lambda: _composition(vector=False)),
    Check("19", "nu3 p3 = nu1/eps1 (nu2 p2) + nu2/eps2 (nu1 p1) - (nu1 p1) x (nu2 p2)/2", "numeric, any p",
          lambda: _composition(vector=True)),
]

