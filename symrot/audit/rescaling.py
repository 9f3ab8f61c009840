"""Section 3.4 rescaling of the Wiener-Milenkovic parameters (p = 4 tan φ/4): eqs (40)–(42).

Each side is a scalar multiple of u, so the check compares the scalar factors at 50 digits over
sample angles with 0 < |φ| < π, for both signs of φ̂ = φ ± 2π.
"""

from __future__ import annotations

import mpmath

from .checks import HOLDS, Check, Outcome
from .numeric import DIGITS, TOLERANCE

ANGLES = ("0.37", "1.1", "-2.3", "2.9", "-0.8")


def _worst(residual: object) -> mpmath.mpf:
    worst = mpmath.mpf(0)
    with mpmath.workdps(DIGITS):
        for text in ANGLES:
            for sign in (1, -1):
                worst = max(worst, abs(residual(mpmath.mpf(text), sign)))  # type: ignore[operator]
    return worst


def _outcome(worst: mpmath.mpf, what: str) -> Outcome:
    if worst > TOLERANCE:
        raise ArithmeticError(f"{what}: residual {mpmath.nstr(worst, 5)}")
    return Outcome(HOLDS, f"{what}: max residual {mpmath.nstr(worst, 3)} at phi in {ANGLES}, "
                   "phi_hat = phi ± 2 pi")


def _p(phi: mpmath.mpf) -> mpmath.mpf:
    return 4 * mpmath.tan(phi / 4)


def _eq40() -> Outcome:
    def residual(phi: mpmath.mpf, sign: int) -> mpmath.mpf:
        p_hat = _p(phi + sign * 2 * mpmath.pi)
        chain = (4 * mpmath.tan(phi / 4 + sign * mpmath.pi / 2), -4 / mpmath.tan(phi / 4),
                 -_p(phi) / mpmath.tan(phi / 4) ** 2)
        return max(abs(p_hat - value) for value in chain)
    return _outcome(_worst(residual), "every member of the chain")


def _eq41() -> Outcome:
    def residual(phi: mpmath.mpf, sign: int) -> mpmath.mpf:
        nu = 2 * mpmath.sin(phi / 2) / _p(phi)
        return _p(phi + sign * 2 * mpmath.pi) + nu / (1 - nu) * _p(phi)
    return _outcome(_worst(residual), "p_hat + nu/(1 - nu) p")


def _eq42() -> Outcome:
    def residual(phi: mpmath.mpf, sign: int) -> mpmath.mpf:
        return abs(_p(phi)) * abs(_p(phi + sign * 2 * mpmath.pi)) - 16
    return _outcome(_worst(residual), "|p| |p_hat| - 16")


CHECKS = [
    Check("40", "p_hat = 4 tan(phi_hat/4) u = 4 tan(phi/4 ± pi/2) u = -4/tan(phi/4) u = -p/tan^2(phi/4)",
          "numeric", _eq40),
    Check("41", "p_hat = -nu/(1 - nu) p  (Wiener-Milenkovic)", "numeric", _eq41),
    Check("42", "p p_hat = 16 (norms)", "numeric", _eq42),
]
