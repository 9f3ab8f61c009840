"""50-digit numerics for the audit: vectors, rotations from eq (1), random points, trajectories.

Everything runs in :func:`precision` (60 significant digits, compared to 10⁻⁴⁵ relative), with
random numbers from seeded generators so that every run — and ``docs/errata.md`` — is identical.
Time derivatives come from :func:`mpmath.diff` on smooth random trajectories φ(t), u(t).
"""

from __future__ import annotations

import random
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from typing import Any, TypeAlias

import mpmath
import sympy as sp

from symrot.core.functions import mpmath_namespace
from symrot.core.parsing import PHI

DIGITS = 60
TOLERANCE = mpmath.mpf(10) ** -45
"""Relative residual below which a numeric identity counts as holding (50+ digits agree)."""
REFUTED = mpmath.mpf(10) ** -8
"""Relative residual above which a numeric identity counts as failing."""

Vector: TypeAlias = Any
"""A 3×1 ``mpmath.matrix`` (mpmath has no type stubs)."""
Scalar = Callable[[mpmath.mpf], mpmath.mpf]


@contextmanager
def precision() -> Iterator[None]:
    with mpmath.workdps(DIGITS):
        yield


def rng(label: str) -> random.Random:
    """A generator seeded by a label (string seeds are hashed deterministically)."""
    return random.Random(f"symrot-audit:{label}")


def mp_function(expr: sp.Expr) -> Scalar:
    """``expr`` (in φ) as an mpmath function honouring the working precision."""
    return sp.lambdify(PHI, expr, modules=[mpmath_namespace(), "mpmath"])


def vector(values: list[mpmath.mpf]) -> Vector:
    return mpmath.matrix(values)


def unit(v: Vector) -> Vector:
    return v / mpmath.norm(v)


def random_axis(r: random.Random) -> Vector:
    return unit(vector([mpmath.mpf(r.gauss(0, 1)) for _ in range(3)]))


def random_angle(r: random.Random, bound: float, low: float = 0.05) -> mpmath.mpf:
    """An angle with low ≤ |φ| ≤ bound and a random sign."""
    return mpmath.mpf(r.uniform(low, bound)) * r.choice((-1, 1))


def skew(v: Vector) -> mpmath.matrix:
    """(v×)."""
    return mpmath.matrix([[0, -v[2], v[1]], [v[2], 0, -v[0]], [-v[1], v[0], 0]])


def axial(m: mpmath.matrix) -> Vector:
    """The axial vector of skw(m)."""
    return vector([(m[2, 1] - m[1, 2]) / 2, (m[0, 2] - m[2, 0]) / 2, (m[1, 0] - m[0, 1]) / 2])


def dot(a: Vector, b: Vector) -> mpmath.mpf:
    return sum(a[i] * b[i] for i in range(3))


def cross(a: Vector, b: Vector) -> Vector:
    return vector([a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]])


def outer(a: Vector, b: Vector) -> mpmath.matrix:
    return mpmath.matrix([[a[i] * b[j] for j in range(b.rows)] for i in range(a.rows)])


def rotation(phi: mpmath.mpf, u: Vector) -> mpmath.matrix:
    """Eq (1): R = I + sin φ (u×) + (1 − cos φ)(u×)²."""
    k = skew(u)
    return mpmath.eye(3) + mpmath.sin(phi) * k + (1 - mpmath.cos(phi)) * k * k


def size(m: mpmath.matrix | mpmath.mpf) -> mpmath.mpf:
    """Largest absolute entry."""
    if isinstance(m, mpmath.matrix):
        return max(abs(x) for x in m)
    return abs(m)


def relative(residual: mpmath.matrix | mpmath.mpf, reference: mpmath.matrix | mpmath.mpf) -> mpmath.mpf:
    return size(residual) / max(mpmath.mpf(1), size(reference))


def fmt(x: mpmath.mpf | float, digits: int = 12) -> str:
    return mpmath.nstr(mpmath.mpf(x), digits)


def fmt_vector(v: Vector, digits: int = 8) -> str:
    return "(" + ", ".join(fmt(v[i], digits) for i in range(v.rows)) + ")"


def derivative(
    f: Callable[[mpmath.mpf], mpmath.matrix | mpmath.mpf], t: mpmath.mpf
) -> mpmath.matrix | mpmath.mpf:
    """d/dt of a scalar- or matrix-valued function, entry by entry (mpmath.diff)."""
    value = f(t)
    if not isinstance(value, mpmath.matrix):
        return mpmath.diff(f, t)
    return mpmath.matrix(
        [
            [mpmath.diff(lambda s, i=i, j=j: f(s)[i, j], t) for j in range(value.cols)]
            for i in range(value.rows)
        ]
    )


class Trajectory:
    """A random smooth motion φ(t) = φ₀ + a t + b t², u(t) = unit(u₀ + v t + w t²), at t = 0."""

    def __init__(self, label: str, bound: float = 2.8) -> None:
        r = rng(f"trajectory:{label}")
        self.phi0 = random_angle(r, bound, low=0.3)
        self.rates = [mpmath.mpf(r.uniform(-1, 1)) for _ in range(2)]
        self.axis = [random_axis(r) * (1 if k == 0 else mpmath.mpf(r.uniform(0.2, 1))) for k in range(3)]
        self.t = mpmath.mpf(0)

    def phi(self, t: mpmath.mpf) -> mpmath.mpf:
        return self.phi0 + self.rates[0] * t + self.rates[1] * t * t

    def u(self, t: mpmath.mpf) -> Vector:
        return unit(self.axis[0] + self.axis[1] * t + self.axis[2] * t * t)

    def rotation(self, t: mpmath.mpf, fraction: int = 1) -> mpmath.matrix:
        """R(t) from eq (1), or the m-th root G_(m)(t) (rotation by φ/m, eq 76)."""
        return rotation(self.phi(t) / fraction, self.u(t))

    def spin(self, fraction: int = 1) -> Vector:
        """ω = axial(Ṙ Rᵀ) (or γ_(m) = axial(Ġ Gᵀ)) at t = 0."""
        r = self.rotation(self.t, fraction)
        r_dot = derivative(lambda s: self.rotation(s, fraction), self.t)
        return axial(r_dot * r.T)

    def parameter_vector(self, p: Scalar) -> Callable[[mpmath.mpf], Vector]:
        return lambda s: p(self.phi(s)) * self.u(s)
