"""Singular angles and the validity range of a parameterization (Section 3.4).

Sources of singularity, for 0 < φ ≤ 4π:

* ``p``: p → ±∞, the generating function itself is singular;
* ``nu``: ν → 0 or ∞, the kinematic inversion through Euler–Rodrigues parameters (eq 75) fails;
* ``p_prime``: p′ → 0 or ∞ (μ → ∞ or 0), H (22) or H⁻¹ (26) is singular;
* ``det_H``: det H (24) → 0 or ∞;
* ``monotonicity``: p′ changes sign, so |p| no longer determines φ.

Method (bounded, numeric-first): each scalar function is scanned in double precision on a fine
grid; sign changes, near-touching zeros (local minima of |f|) and poles (local maxima of |f|)
are bracketed and polished at 50 digits with mpmath; one-sided values at φ* ± 10⁻²⁰ classify the
limit. Symbolic candidates, each bounded by :func:`symrot.timeouts.bounded`, are bracketed too and
preferred as exact angles: the poles of p from ``sympy.calculus.util.singularities`` (the only
SymPy tool that finds poles inside tan) and the zeros of p′ from ``solveset``. When ``solveset``
returns a ConditionSet or times out, the analysis is numeric and ``numeric_only`` is set.
Identically constant functions (e.g. ν for 2 sin(φ/2), det H for eq 35) have no singularity.
Other angles are matched against rational multiples of π (denominators ≤ 24, to 25 digits:
multiple roots polish to fewer digits than simple ones); an angle matching neither is reported
as a Float and ``numeric_only`` is set. The validity range is the smallest singular angle.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from functools import lru_cache

import mpmath
import numpy as np
import sympy as sp

from .core import Derivation, derive_expression
from .functions import mpmath_namespace
from .parsing import PHI
from .timeouts import bounded

SCAN_END = 4 * np.pi
SCAN_POINTS = 4001
DIGITS = 50
QUANTITIES = ("p", "nu", "p_prime", "det_H")
CAUSES = {
    ("p", "oo"): "p -> oo: the generating function is singular",
    ("nu", "0"): "nu -> 0: kinematic inversion through Euler-Rodrigues parameters fails",
    ("nu", "oo"): "nu -> oo: kinematic inversion through Euler-Rodrigues parameters fails",
    ("p_prime", "0"): "p' -> 0 (mu -> oo): H is unbounded and H^-1 singular",
    ("p_prime", "oo"): "p' -> oo (mu -> 0): H is singular",
    ("det_H", "0"): "det H -> 0: H is singular",
    ("det_H", "oo"): "det H -> oo: H^-1 is singular",
    ("monotonicity", "0"): "p' changes sign: |p| no longer determines phi",
}


@dataclass(frozen=True)
class Singularity:
    phi: sp.Expr
    phi_float: float
    cause: str
    quantity: str
    limit: str


@dataclass(frozen=True)
class Validity:
    phi_max: sp.Expr
    phi_max_float: float
    p_max_float: float
    singularities: tuple[Singularity, ...]
    numeric_only: bool

    def listed(self) -> tuple[Singularity, ...]:
        """The singular angles up to twice the validity bound: what ``symrot derive`` prints and
        what the table's causes column and the derivation sheets show."""
        return tuple(s for s in self.singularities if s.phi_float <= 2 * self.phi_max_float)


SYMBOLIC_TIME_LIMIT = 0.5
SCAN_INTERVAL = sp.Interval.Lopen(0, 4 * sp.pi)


def validity(derivation: Derivation) -> Validity:
    """The validity range of ``derivation``'s parameterization and every singular angle."""
    return _validity_of(derivation.p)


@lru_cache(maxsize=256)
def _validity_of(p: sp.Expr) -> Validity:
    derivation = derive_expression(p)
    candidates, confirmed = _symbolic_candidates(p, derivation.scalars_raw["p_prime"])
    brackets = tuple(float(c) for c in candidates)
    found: list[Singularity] = []
    numeric_only = not confirmed
    for quantity in QUANTITIES:
        if quantity != "p" and derivation.constant_value(quantity) is not None:
            continue
        expr = p if quantity == "p" else derivation.scalars_raw[quantity]
        for angle, limit, sign_change in _events(expr, brackets):
            if (quantity, limit) not in CAUSES:
                continue  # p = 0 away from the origin is caught through nu and p'
            exact = _exact_angle(angle, candidates)
            numeric_only |= exact is None
            phi = exact if exact is not None else sp.Float(mpmath.nstr(angle, 30), 30)
            found.append(Singularity(phi, float(angle), CAUSES[(quantity, limit)], quantity, limit))
            if quantity == "p_prime" and limit == "0" and sign_change:
                found.append(Singularity(phi, float(angle), CAUSES[("monotonicity", "0")],
                                         "monotonicity", "0"))
    found.sort(key=lambda s: (s.phi_float, QUANTITIES.index(s.quantity)
                              if s.quantity in QUANTITIES else len(QUANTITIES)))
    if not found:
        return Validity(sp.oo, float("inf"), float("inf"), (), False)
    edge = found[0]
    p_at_edge = float("inf") if any(s.quantity == "p" and abs(s.phi_float - edge.phi_float) < 1e-9
                                    for s in found) else abs(float(p.subs(PHI, edge.phi).evalf(30)))
    return Validity(edge.phi, edge.phi_float, p_at_edge, tuple(found), numeric_only)


def _mp(expr: sp.Expr) -> Callable[[mpmath.mpf], mpmath.mpf]:
    return sp.lambdify(PHI, expr, modules=[mpmath_namespace(), "mpmath"])


def _symbolic_candidates(p: sp.Expr, p_prime: sp.Expr) -> tuple[tuple[sp.Expr, ...], bool]:
    """Exact poles of p and zeros of p′ in (0, 4π]; False when SymPy could not list them all."""

    def poles() -> sp.Set | None:
        return sp.calculus.util.singularities(p, PHI, SCAN_INTERVAL)

    def zeros() -> sp.Set | None:
        return sp.solveset(p_prime, PHI, SCAN_INTERVAL)

    found: list[sp.Expr] = []
    confirmed = True
    for compute in (poles, zeros):
        try:
            result = bounded(SYMBOLIC_TIME_LIMIT, None, compute)
        except (NotImplementedError, ValueError, TypeError, AttributeError):
            result = None
        if not isinstance(result, sp.FiniteSet):
            confirmed &= result is sp.S.EmptySet
            continue
        found.extend(x for x in result if x.is_real and x.is_number)
    return tuple(found), confirmed


def _events(expr: sp.Expr, extra: tuple[float, ...] = ()) -> list[tuple[mpmath.mpf, str, bool]]:
    """(angle, limit '0'|'oo', sign change?) for the zeros and poles of ``expr`` in (0, 4π].

    ``extra`` are candidate angles from the symbolic analysis, bracketed in addition to the scan.
    """
    grid = np.linspace(SCAN_END / SCAN_POINTS, SCAN_END, SCAN_POINTS)
    numeric = sp.lambdify(PHI, expr, modules=[{"RealCbrt": np.cbrt}, "numpy"])
    with np.errstate(all="ignore"):
        values = np.asarray(numeric(grid), dtype=float) * np.ones_like(grid)
    magnitude = np.abs(values)
    scale = float(np.nanmedian(magnitude[np.isfinite(magnitude)])) or 1.0
    exact = _mp(expr)
    events: list[tuple[mpmath.mpf, str, bool]] = []
    candidates: list[tuple[float, float]] = []
    for i in range(1, SCAN_POINTS - 1):
        a, b, c = magnitude[i - 1], magnitude[i], magnitude[i + 1]
        sign_change = np.sign(values[i]) != np.sign(values[i + 1])
        local_min = b <= a and b <= c and b < 1e-3 * max(scale, 1.0)
        local_max = (b >= a and b >= c and b > 1e3 * max(scale, 1.0)) or not np.isfinite(b)
        if sign_change or local_min or local_max:
            candidates.append((grid[i - 1], grid[i + 1]))
    if magnitude[-1] < 1e-9 * max(scale, 1.0) or magnitude[-1] > 1e9 * max(scale, 1.0):
        candidates.append((grid[-2], grid[-1]))
    with mpmath.workdps(DIGITS):
        for low, high in candidates:
            event = _polish(exact, mpmath.mpf(low), mpmath.mpf(high))
            if event is not None and not any(abs(event[0] - e[0]) < 1e-9 for e in events):
                events.append(event)
        for candidate in extra:  # exact angles: classify in place, no root search
            angle = mpmath.mpf(sp.N(candidate, DIGITS))
            if not any(abs(angle - e[0]) < 1e-9 for e in events):
                event = _classify(_safe(exact), angle)
                if event is not None:
                    events.append(event)
    return events


def _polish(f: Callable[[mpmath.mpf], mpmath.mpf], low: mpmath.mpf, high: mpmath.mpf
            ) -> tuple[mpmath.mpf, str, bool] | None:
    """Locate a zero or pole of f in [low, high] at 50 digits and classify it."""

    safe = _safe(f)

    def reciprocal(t: mpmath.mpf) -> mpmath.mpf:
        value = safe(t)
        return mpmath.mpf(0) if mpmath.isinf(value) else 1 / value

    def newton_quotient(h: Callable[[mpmath.mpf], mpmath.mpf]) -> Callable[[mpmath.mpf], mpmath.mpf]:
        # h/h' has a simple root at every multiple root of h (touching zeros such as cos^4).
        return lambda t: h(t) / mpmath.diff(h, t)

    angle = None
    for g in (safe, reciprocal, newton_quotient(safe), newton_quotient(reciprocal)):
        try:
            root = mpmath.findroot(g, (low, high), solver="anderson")
        except (ValueError, ZeroDivisionError, TypeError):
            continue
        if low - 1e-12 <= root <= high + 1e-12:
            angle = root
            break
    if angle is None:
        return None
    return _classify(safe, angle)


def _safe(f: Callable[[mpmath.mpf], mpmath.mpf]) -> Callable[[mpmath.mpf], mpmath.mpf]:
    """``f`` with division by zero read as a pole and complex rounding noise dropped."""

    def safe(t: mpmath.mpf) -> mpmath.mpf:
        try:
            value = f(t)
        except (ZeroDivisionError, ValueError):
            return mpmath.inf
        return value.real if isinstance(value, mpmath.mpc) else value

    return safe


def _classify(safe: Callable[[mpmath.mpf], mpmath.mpf], angle: mpmath.mpf
              ) -> tuple[mpmath.mpf, str, bool] | None:
    """Zero ('0') or pole ('oo') of ``safe`` at ``angle`` from one-sided values at ± 10⁻²⁰."""
    delta = mpmath.mpf(10) ** -20
    left, right = safe(angle - delta), safe(angle + delta)
    tiny, huge = mpmath.mpf(10) ** -12, mpmath.mpf(10) ** 12
    if abs(left) < tiny and abs(right) < tiny:
        crosses = mpmath.sign(safe(angle - 10 * delta)) != mpmath.sign(safe(angle + 10 * delta))
        return angle, "0", bool(crosses)
    if abs(left) > huge or abs(right) > huge:
        return angle, "oo", bool(mpmath.sign(left) != mpmath.sign(right))
    return None


def _exact_angle(angle: mpmath.mpf, candidates: tuple[sp.Expr, ...] = ()) -> sp.Expr | None:
    """The symbolic candidate, or k π / n, that the 50-digit root matches (n ≤ 24), else None."""
    with mpmath.workdps(DIGITS):
        for candidate in candidates:
            if abs(angle - mpmath.mpf(sp.N(candidate, DIGITS))) < mpmath.mpf(10) ** -25:
                return candidate
        for n in range(1, 25):
            k = int(mpmath.nint(angle * n / mpmath.pi))
            if k and abs(angle - k * mpmath.pi / n) < mpmath.mpf(10) ** -25:
                return sp.Rational(k, n) * sp.pi
    return None
