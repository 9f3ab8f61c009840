"""Composition of rotations: eqs (7), (8) (Section 2) and (43) with its note (Section 3.4).

Every check builds R₁, R₂ from eq (1) at random angles and axes (50 digits), forms R₃ = R₂R₁,
and reads φ₃, u₃ back from R₃ (cos φ₃ = (tr R₃ − 1)/2, sin φ₃ u₃ = axial R₃).
"""

from __future__ import annotations

from dataclasses import dataclass

import mpmath

from .checks import HOLDS, Check, Outcome
from .numeric import DIGITS, TOLERANCE, axial, rng, rotation, unit

SEEDS = (11, 12, 13, 14)


@dataclass
class Pair:
    phi1: mpmath.mpf
    u1: mpmath.matrix
    phi2: mpmath.mpf
    u2: mpmath.matrix
    phi3: mpmath.mpf
    u3: mpmath.matrix


def _pair(seed: int, max_angle: float = 1.4) -> Pair:
    """Two random rotations with |φ₁| + |φ₂| < π so that φ₃ ∈ (0, π) is read back unambiguously."""
    r = rng(seed)
    phi1 = mpmath.mpf(r.uniform(0.1, max_angle))
    phi2 = mpmath.mpf(r.uniform(0.1, max_angle))
    u1 = unit([mpmath.mpf(r.uniform(-1, 1)) for _ in range(3)])
    u2 = unit([mpmath.mpf(r.uniform(-1, 1)) for _ in range(3)])
    r3 = rotation(phi2, u2) * rotation(phi1, u1)
    cos3 = (r3[0, 0] + r3[1, 1] + r3[2, 2] - 1) / 2
    phi3 = mpmath.acos(cos3)
    u3 = mpmath.matrix(axial(r3)) / mpmath.sin(phi3)
    return Pair(phi1, mpmath.matrix(u1), phi2, mpmath.matrix(u2), phi3, u3)


def _dot(a: mpmath.matrix, b: mpmath.matrix) -> mpmath.mpf:
    return sum(a[i] * b[i] for i in range(3))


def _cross(a: mpmath.matrix, b: mpmath.matrix) -> mpmath.matrix:
    return mpmath.matrix([a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]])


def _worst(residual: object) -> mpmath.mpf:
    worst = mpmath.mpf(0)
    with mpmath.workdps(DIGITS):
        for seed in SEEDS:
            worst = max(worst, residual(_pair(seed)))  # type: ignore[operator]
    return worst


def _holds(worst: mpmath.mpf, what: str) -> Outcome:
    if worst > TOLERANCE:
        raise ArithmeticError(f"{what}: residual {mpmath.nstr(worst, 5)}")
    return Outcome(HOLDS, f"{what}: max residual {mpmath.nstr(worst, 3)} at {len(SEEDS)} random pairs "
                   "against R3 = R2 R1")


def _eq7() -> Outcome:
    def residual(q: Pair) -> mpmath.mpf:
        c1, s1, c2, s2 = (mpmath.cos(q.phi1 / 2), mpmath.sin(q.phi1 / 2),
                          mpmath.cos(q.phi2 / 2), mpmath.sin(q.phi2 / 2))
        return abs(mpmath.cos(q.phi3 / 2) - (c1 * c2 - s1 * s2 * _dot(q.u1, q.u2)))
    return _holds(_worst(residual), "cos(phi3/2)")


def _eq8() -> Outcome:
    def residual(q: Pair) -> mpmath.mpf:
        c1, s1, c2, s2 = (mpmath.cos(q.phi1 / 2), mpmath.sin(q.phi1 / 2),
                          mpmath.cos(q.phi2 / 2), mpmath.sin(q.phi2 / 2))
        rhs = c1 * s2 * q.u2 + c2 * s1 * q.u1 - s1 * s2 * _cross(q.u1, q.u2)
        return mpmath.mnorm(mpmath.sin(q.phi3 / 2) * q.u3 - rhs, 1)
    return _holds(_worst(residual), "sin(phi3/2) u3")


def _wiener_milenkovic(phi: mpmath.mpf) -> tuple[mpmath.mpf, mpmath.mpf, mpmath.mpf]:
    """p = 4 tan(φ/4), ν = 2 sin(φ/2)/p (15), ε = 2 tan(φ/2)/p (16)."""
    p = 4 * mpmath.tan(phi / 4)
    return p, 2 * mpmath.sin(phi / 2) / p, 2 * mpmath.tan(phi / 2) / p


def _eq43() -> Outcome:
    def residual(q: Pair) -> mpmath.mpf:
        p1, nu1, eps1 = _wiener_milenkovic(q.phi1)
        p2, nu2, eps2 = _wiener_milenkovic(q.phi2)
        p3, nu3, _ = _wiener_milenkovic(q.phi3)
        vec1, vec2 = p1 * q.u1, p2 * q.u2
        rhs = nu1 * nu2 / nu3 * (vec1 / eps2 + vec2 / eps1 - _cross(vec1, vec2) / 2)
        return mpmath.mnorm(p3 * q.u3 - rhs, 1)
    return _holds(_worst(residual), "p3 (Wiener-Milenkovic)")


def _eq43_note() -> Outcome:
    """Text after (43): 2ν₃ − 1 = cos φ₃/2 = ν₁ν₂(1/ε₁ε₂ − p₁·p₂/4)."""
    def first(q: Pair) -> mpmath.mpf:
        return abs(2 * _wiener_milenkovic(q.phi3)[1] - 1 - mpmath.cos(q.phi3 / 2))

    def second(q: Pair) -> mpmath.mpf:
        p1, nu1, eps1 = _wiener_milenkovic(q.phi1)
        p2, nu2, eps2 = _wiener_milenkovic(q.phi2)
        return abs(mpmath.cos(q.phi3 / 2)
                   - nu1 * nu2 * (1 / (eps1 * eps2) - p1 * p2 * _dot(q.u1, q.u2) / 4))
    worst_first = _holds(_worst(first), "2 nu3 - 1 = cos(phi3/2)").evidence
    worst_second = _holds(_worst(second), "cos(phi3/2) = nu1 nu2 (1/(eps1 eps2) - p1.p2/4)").evidence
    return Outcome(HOLDS, f"{worst_first}; {worst_second}")


CHECKS = [
    Check("7", "cos(phi3/2) = cos(phi1/2) cos(phi2/2) - sin(phi1/2) sin(phi2/2) u1.u2", "numeric", _eq7),
    Check("8", "sin(phi3/2) u3 = cos(phi1/2) sin(phi2/2) u2 + cos(phi2/2) sin(phi1/2) u1 "
          "- sin(phi1/2) sin(phi2/2) u1 x u2", "numeric", _eq8),
    Check("43", "p3 = nu1 nu2/nu3 (p1/eps2 + p2/eps1 - p1 x p2/2)  (Wiener-Milenkovic)", "numeric", _eq43),
    Check("text after (43)", "2 nu3 - 1 = cos(phi3/2) = nu1 nu2 (1/(eps1 eps2) - p1.p2/4)", "numeric",
          _eq43_note),
]
