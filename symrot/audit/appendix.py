"""Appendices A, C, D: scalar claims for p = sin φ/2, p = φ, p = tan φ/2, and the log series (89)."""

from __future__ import annotations

from collections.abc import Callable

import mpmath
import sympy as sp

from ..core import scalar_definitions
from ..parsing import PHI
from ..validation import evaluate
from .checks import ERRATUM, HOLDS, Check, Outcome
from .numeric import DIGITS, TOLERANCE, axial, rng, rotation, unit

E0 = sp.cos(PHI / 2)
"""Euler parameter e₀ = cos(φ/2) (Appendix A)."""
ZETA = sp.tan(PHI / 2)
"""Magnitude of the Cayley parameter vector ζ (Appendix D)."""
ANGLES = ("0.37", "1.1", "-2.3", "2.9")
"""Random-looking sample angles inside (−π, π), where all these claims are meant to hold."""


def _numeric_residual(expr: sp.Expr) -> tuple[mpmath.mpf, str]:
    worst, where = mpmath.mpf(0), ANGLES[0]
    for angle in ANGLES:
        value = abs(evaluate(expr, angle, DIGITS))
        if value > worst:
            worst, where = value, angle
    return worst, where


def _claim(p: sp.Expr, name: str, printed: sp.Expr, corrected: sp.Expr | None = None
           ) -> Callable[[], Outcome]:
    def verify() -> Outcome:
        actual = scalar_definitions(p)[name]
        worst, where = _numeric_residual(actual - printed)
        if worst < TOLERANCE:
            return Outcome(HOLDS, f"|{name} - printed| <= {mpmath.nstr(worst, 3)} at phi in {ANGLES} "
                           f"({DIGITS} digits)")
        if corrected is None:
            raise ArithmeticError(f"{name} = {printed} fails and no correction is known")
        fixed, _ = _numeric_residual(actual - corrected)
        if fixed > TOLERANCE:
            raise ArithmeticError(f"corrected {name} = {corrected} fails too")
        counterexample = mpmath.nstr(evaluate(actual - printed, where, DIGITS), 15)
        return Outcome(ERRATUM, f"{name} - printed = {counterexample} at phi = {where}; "
                       f"corrected form residual <= {mpmath.nstr(fixed, 3)}",
                       f"{name} = {corrected}")
    return verify


def _eq89() -> Outcome:
    """(89) log R = −Σ (I − R)^k / k, checked through (88) φ = axial(log R) for |φ| < π/3."""
    worst = mpmath.mpf(0)
    with mpmath.workdps(DIGITS + 10):
        for seed in (1, 2, 3):
            r = rng(seed)
            phi = mpmath.mpf(r.uniform(-0.6, 0.6))
            u = unit([mpmath.mpf(r.uniform(-1, 1)) for _ in range(3)])
            a = mpmath.eye(3) - rotation(phi, u)
            term, total = mpmath.eye(3), mpmath.matrix(3, 3)
            for k in range(1, 400):
                term = term * a
                total -= term / k
            worst = max(worst, max(abs(x - phi * y) for x, y in zip(axial(total), u, strict=True)))
    if worst > TOLERANCE:
        raise ArithmeticError(f"eq (89) residual {mpmath.nstr(worst, 5)}")
    return Outcome(HOLDS, f"axial(log R) - phi u <= {mpmath.nstr(worst, 3)} with 399 terms, |phi| < 0.6 "
                   "(the series converges for |phi| < pi/3)")


HALF_SINE = sp.sin(PHI / 2)

CHECKS = [
    Check("A (text after 75): mu", "mu = 2/e0 for p = sin(phi/2)", "numeric",
          _claim(HALF_SINE, "mu", 2 / E0)),
    Check("A (text after 75): nu", "nu = 2 for p = sin(phi/2)", "numeric",
          _claim(HALF_SINE, "nu", sp.Integer(2))),
    Check("A (text after 75): epsilon", "epsilon = mu = 2/e0 for p = sin(phi/2)", "numeric",
          _claim(sp.sin(PHI / 2), "epsilon", 2 / E0)),
    Check("C (text after 86): nu", "nu = 2 sin phi/phi for p = phi (read literally: 2 sin(phi)/phi)",
          "numeric",
          _claim(PHI, "nu", 2 * sp.sin(PHI) / PHI, 2 * sp.sin(PHI / 2) / PHI)),
    Check("C (text after 86): epsilon",
          "epsilon = 2 tan phi/phi for p = phi (read literally: 2 tan(phi)/phi)", "numeric",
          _claim(PHI, "epsilon", 2 * sp.tan(PHI) / PHI, 2 * sp.tan(PHI / 2) / PHI)),
    Check("89", "log(R) = -sum_k (I - R)^k / k", "numeric", _eq89),
    Check("D (text after 98): mu", "mu = 2/(1 + zeta^2) for p = tan(phi/2)", "numeric",
          _claim(sp.tan(PHI / 2), "mu", 2 / (1 + ZETA**2))),
    Check("D (text after 98): nu", "nu = sqrt(2 mu) for p = tan(phi/2)", "numeric",
          _claim(sp.tan(PHI / 2), "nu", sp.sqrt(4 / (1 + ZETA**2)))),
    Check("D (text after 98): epsilon", "epsilon = 2 for p = tan(phi/2)", "numeric",
          _claim(sp.tan(PHI / 2), "epsilon", sp.Integer(2))),
]
