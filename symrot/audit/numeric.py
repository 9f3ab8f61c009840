"""50-digit numeric helpers: random axes, rotation tensors, smooth trajectories."""

from __future__ import annotations

import random

import mpmath

DIGITS = 50
TOLERANCE = mpmath.mpf(10) ** -40


def rng(seed: int) -> random.Random:
    return random.Random(seed)


def skew(v: list[mpmath.mpf]) -> mpmath.matrix:
    return mpmath.matrix([[0, -v[2], v[1]], [v[2], 0, -v[0]], [-v[1], v[0], 0]])


def unit(v: list[mpmath.mpf]) -> list[mpmath.mpf]:
    n = mpmath.sqrt(sum(x * x for x in v))
    return [x / n for x in v]


def rotation(phi: mpmath.mpf, u: list[mpmath.mpf]) -> mpmath.matrix:
    """Eq (1): R = I + sin φ (u×) + (1 − cos φ)(u×)²."""
    k = skew(u)
    return mpmath.eye(3) + mpmath.sin(phi) * k + (1 - mpmath.cos(phi)) * k * k


def norm(m: mpmath.matrix) -> mpmath.mpf:
    return mpmath.mnorm(m, 1)


def axial(m: mpmath.matrix) -> list[mpmath.mpf]:
    return [(m[2, 1] - m[1, 2]) / 2, (m[0, 2] - m[2, 0]) / 2, (m[1, 0] - m[0, 1]) / 2]


class Trajectory:
    """φ(t), u(t) built from random trigonometric polynomials; derivatives by mpmath.diff."""

    def __init__(self, seed: int) -> None:
        r = rng(seed)
        self.coeffs = [[mpmath.mpf(r.uniform(-1, 1)) for _ in range(3)] for _ in range(4)]

    def _component(self, i: int, t: mpmath.mpf) -> mpmath.mpf:
        a, b, c = self.coeffs[i]
        return a + b * mpmath.sin(t) + c * mpmath.cos(2 * t)

    def phi(self, t: mpmath.mpf) -> mpmath.mpf:
        return 1 + self._component(0, t)

    def u(self, t: mpmath.mpf) -> list[mpmath.mpf]:
        return unit([self._component(i, t) + (2 if i == 1 else 0) for i in (1, 2, 3)])

    def rotation(self, t: mpmath.mpf) -> mpmath.matrix:
        return rotation(self.phi(t), self.u(t))

    def rotation_dot(self, t: mpmath.mpf) -> mpmath.matrix:
        return mpmath.matrix(
            [[mpmath.diff(lambda s, i=i, j=j: self.rotation(s)[i, j], t) for j in range(3)]
             for i in range(3)]
        )
