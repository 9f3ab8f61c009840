"""Starting values for the Newton iteration φ(s), s = |p|, when p(φ) has no closed inverse.

The reverted series φ ≈ Σ b_k s^(2k+1) (exact, from the series engine) is an excellent start near
s = 0 but useless far from it, and a fixed small number of Newton steps cannot repair a poor
start: near a fold of p (p′(φ_max) = 0, e.g. eq 35 at 2π, where p_max − p ∝ (φ_max − φ)³) Newton
converges only linearly. So beyond a switch s₀ the start is a polynomial in a variable in which
φ is analytic up to the edge of the range:

* ``fold`` (p_max finite, p′(φ_max) = 0 with a zero of order k − 1):
  v = 1 − (1 − s/p_max)^(1/k), since φ_max − φ is analytic in (p_max − s)^(1/k);
* ``linear`` (p_max finite, no fold): v = s/p_max;
* ``ratio`` (p unbounded): v = s/(s + c), c = p(φ_max/2).

φ(v) is interpolated at Chebyshev nodes (values from the 30-digit root of
:mod:`symrot.plan.angle_solve`) by a polynomial in y = 2v − 1, stored as Chebyshev coefficients and
evaluated by Clenshaw's recurrence (its monomial form has alternating coefficients up to ~10⁹ for
degree 40, which lose every digit in float32: sinh's float32 angle at φ = 1 came out as 1.15); the
degree is the smallest whose start is within ``START_TOLERANCE`` (relative to φ_max) at the
midpoints. s₀ is where the reverted series' own
relative error reaches ``SERIES_TOLERANCE``. Plan-time numerics only (mpmath, and NumPy arithmetic
that is the same on every CPU); no SymPy call that can hang.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from fractions import Fraction
from functools import lru_cache
from typing import Any, Literal, NamedTuple

import mpmath
import numpy as np
import sympy as sp

from symrot.core.functions import mpmath_namespace
from symrot.core.parsing import PHI
from symrot.plan.angle_solve import angle_of_length
from symrot.plan.evaluation import log_grid

START_TOLERANCE = 1e-9
SERIES_TOLERANCE = 1e-12
DEGREES = (8, 12, 16, 24, 32, 40)
DIGITS = 30
FOLD_DERIVATIVE = mpmath.mpf(10) ** -12


@dataclass(frozen=True)
class FarStart:
    """φ ≈ Σ chebyshev[j] T_j(y), y = 2v(s) − 1, used for s ≥ switch (see the module docstring);
    backends evaluate it with Clenshaw's recurrence (:func:`clenshaw`)."""

    kind: Literal["fold", "linear", "ratio"]
    scale: float
    """p_max for ``fold`` and ``linear``, c for ``ratio``."""
    order: int
    """k for ``fold`` (v = 1 − (1 − s/p_max)^(1/k)); 1 otherwise."""
    chebyshev: tuple[float, ...]
    switch: float
    measured: float
    """Worst relative start error (of φ_max) at the check points."""


def _p_function(p: sp.Expr) -> Callable[[Any], Any]:
    return sp.lambdify(PHI, p, modules=[mpmath_namespace(), "mpmath"])


def fold_order(p: sp.Expr, phi_max: float) -> int:
    """1 if p′(φ_max) ≠ 0, else 1 + the order of the zero of p′ at φ_max (at most 4)."""
    f = _p_function(p)
    with mpmath.workdps(DIGITS):
        at = mpmath.mpf(phi_max)
        scale = max(abs(f(at)), 1)
        for k in range(1, 5):
            if abs(mpmath.diff(f, at, k)) > FOLD_DERIVATIVE * scale:
                return k
    return 4


def v_of_s(kind: str, scale: float, order: int, s: np.ndarray | float) -> np.ndarray:
    """The interpolation variable v ∈ [0, 1] (float64)."""
    s = np.asarray(s, dtype=np.float64)
    if kind == "fold":
        return np.asarray(1.0 - np.power(np.maximum(1.0 - s / scale, 0.0), 1.0 / order))
    if kind == "linear":
        return np.asarray(np.minimum(s / scale, 1.0))
    return np.asarray(s / (s + scale))


def _s_of_v(kind: str, scale: float, order: int, v: mpmath.mpf) -> mpmath.mpf:
    if kind == "fold":
        return scale * (1 - (1 - v) ** order)
    if kind == "linear":
        return scale * v
    return scale * v / (1 - v)


def far_start(p: sp.Expr, p_max: float, phi_max: float, series: tuple[sp.Expr, ...]) -> FarStart:
    """The far-field start for p(φ) on 0 ≤ φ < φ_max (|p| < p_max)."""
    f, f_slope = _p_function(p), _p_function(sp.diff(p, PHI))
    if math.isfinite(p_max):
        order = fold_order(p, phi_max)
        kind: Literal["fold", "linear", "ratio"] = "fold" if order > 1 else "linear"
        scale = p_max
    else:
        kind, order = "ratio", 1
        with mpmath.workdps(DIGITS):
            scale = float(f(mpmath.mpf(phi_max) / 2))
    with mpmath.workdps(DIGITS):
        top = mpmath.mpf(phi_max)

        def phi_at_v(v: float | mpmath.mpf) -> float:
            if v >= 1:
                return phi_max
            return float(angle_of_length(f, f_slope, _s_of_v(kind, scale, order, mpmath.mpf(v)), top))

        checks = np.linspace(0.0, 1.0, 97)[1:-1]
        check_values = np.array([phi_at_v(v) for v in checks])
        best: tuple[float, tuple[float, ...]] = (math.inf, ())
        for degree in DEGREES:
            chebyshev = np.array(chebyshev_interpolant(lambda y: phi_at_v((y + 1) / 2), degree))
            estimate = clenshaw(chebyshev, 2 * checks - 1)
            error = float(np.max(np.abs(estimate - check_values))) / phi_max
            if error < best[0]:
                best = (error, tuple(float(c) for c in chebyshev))
            if error <= START_TOLERANCE:
                break
        switch = _series_switch(f, series, phi_max)
    return FarStart(kind, float(scale), order, best[1], switch, best[0])


def chebyshev_interpolant(function: Callable[[mpmath.mpf], float], degree: int) -> list[float]:
    """Chebyshev coefficients c_j (Σ c_j T_j(y)) of the polynomial of ``degree`` interpolating
    ``function`` at the Chebyshev nodes y_k = cos(π(k + ½)/(n + 1)) of [−1, 1].

    Computed in mpmath (DIGITS) from the discrete orthogonality of T_j at those nodes,
    c_j = (2 − δ_j0)/(n + 1) Σ_k f(y_k) T_j(y_k), and rounded to float64 only at the end. No
    BLAS/LAPACK least squares (whose results depend on the CPU kernel OpenBLAS picks) and no NumPy
    transcendental function (whose results depend on the SIMD extensions): every machine prints
    the same coefficients."""
    with mpmath.workdps(DIGITS):
        n = degree + 1
        angles = [mpmath.pi * (k + mpmath.mpf(1) / 2) / n for k in range(n)]
        values = [mpmath.mpf(function(mpmath.cos(a))) for a in angles]
        pairs = list(zip(values, angles, strict=True))
        weights = [mpmath.mpf(1 if j == 0 else 2) / n for j in range(n)]
        return [float(w * mpmath.fsum(v * mpmath.cos(j * a) for v, a in pairs))
                for j, w in enumerate(weights)]


def clenshaw(chebyshev: Sequence[float] | np.ndarray, y: np.ndarray) -> np.ndarray:
    """Σ c_j T_j(y) by Clenshaw's recurrence b_k = c_k + 2y b_{k+1} − b_{k+2}, result
    c_0 + y b_1 − b_2: stable (error ~ n ε max|f|) where the monomial form is not. The backends
    print the same recurrence."""
    y = np.asarray(y)
    following = np.zeros_like(y)
    current = np.zeros_like(y)
    for c in list(chebyshev)[:0:-1]:
        following, current = current, c + 2 * y * current - following
    return chebyshev[0] + y * current - following


def _series_switch(f: Callable[[Any], Any], series: tuple[sp.Expr, ...], phi_max: float) -> float:
    """Largest s on a log grid below which the reverted series is within SERIES_TOLERANCE."""
    coefficients = [mpmath.mpf(sp.N(c, DIGITS)) for c in series]
    switch = 0.0
    for angle in log_grid(1e-6, phi_max * 0.99, 80):
        s = f(mpmath.mpf(angle))
        estimate = s * mpmath.polyval(coefficients[::-1], s * s)
        if abs(estimate - angle) > SERIES_TOLERANCE * angle:
            break
        switch = float(s)
    return switch


MAX_ITERATIONS = 64
RESIDUAL_ULPS = 4.0
"""The largest error of the printed p(φ), in units of ε s, that widens a lane's tolerance."""
EDGE_DENOMINATOR = 4
"""Largest n of a fractional edge exponent k = 1/n (p_max − p ∝ (φ_max − φ)^k, k = 1/2 for asin)."""


def edge_exponent(p: sp.Expr, far: FarStart, phi_max: float) -> sp.Rational | None:
    """k with p_max − p(φ) ∝ (φ_max − φ)^k at the end of a finite range, when k ≠ 1: the fold order
    the far start found (k = 2, 3, 4 where p′(φ_max) = 0, :func:`fold_order`), or a fraction where
    p′ → ∞ (k = 1/2 at the edge of asin's domain, 2 cos(φ) asin(φ)/15 + … of
    docs/accuracy_hypothesis.md row 187), estimated from the growth of p′ between
    φ_max − 10⁻¹⁰ φ_max and φ_max − 10⁻²⁰ φ_max at DIGITS and accepted when within 0.02 of 1/n,
    n ≤ EDGE_DENOMINATOR. None for an unbounded p (``far.kind`` "ratio") or an ordinary edge.
    Newton in w = (φ_max − φ)^k, where p is regular, then converges quadratically up to the edge
    (:func:`newton_step`)."""
    if far.kind == "fold":
        return sp.Integer(far.order)
    if far.kind == "ratio" or not math.isfinite(phi_max):
        return None
    f_slope = _p_function(sp.diff(p, PHI))
    with mpmath.workdps(DIGITS):
        top = mpmath.mpf(phi_max)
        near, nearer = mpmath.mpf(10) ** -10 * top, mpmath.mpf(10) ** -20 * top
        try:
            slopes = [mpmath.mpf(f_slope(top - gap)) for gap in (near, nearer)]
        except (TypeError, ValueError, ZeroDivisionError, OverflowError):
            return None
        if not all(mpmath.isfinite(value) and value > 0 for value in slopes):
            return None
        growth = float(mpmath.log(slopes[1] / slopes[0]) / mpmath.log(near / nearer))
    fraction = Fraction(1 - growth).limit_denominator(EDGE_DENOMINATOR)
    if fraction.numerator != 1 or fraction.denominator < 2 or abs(float(fraction) - (1 - growth)) > 0.02:
        return None
    return sp.Rational(1, fraction.denominator)


class NewtonCount(NamedTuple):
    """What :func:`measured_iterations` found: the steps to print, and the smallest s = |p| whose
    angle those steps do not reach (∞ when every checked angle is reached)."""

    steps: int
    unconverged: float


class NewtonLanes(NamedTuple):
    """The checks of :func:`measured_iterations`: s = p(θ) rounded to the precision, the exact angle
    of that s, and how close to it an iterate must come."""

    sizes: np.ndarray
    angles: np.ndarray
    tolerance: np.ndarray


def newton_lanes(p: sp.Expr, slope: sp.Expr, angles: np.ndarray, phi_max: float, dtype: type,
                 ratio_model: Callable[[np.ndarray], np.ndarray], leading: float = 0.0,
                 series_below: float = 0.0) -> NewtonLanes:
    """At every angle of ``angles``: s = p(θ) rounded to ``dtype``, the exact angle θ* of that s
    (DIGITS), and the tolerance 2 ε θ* + 2 ε s/p′(θ*) (1 + e) (what one ε of s moves the angle:
    large next to a fold, p′ → 0), where e is the error in units of ε s, up to RESIDUAL_ULPS, of
    the printed residual's p(φ) = φ·``leading`` + φ·m(φ²) (``ratio_model`` = m as the plan prints
    it: the tail g − g(0) of g = p/φ with ``leading`` = g(0), or g itself with ``leading`` = 0;
    :class:`symrot.plan.ir.NewtonAngle`) at θ* rounded, the two products rounded and their sum
    exact where φ² < ``series_below`` (the residual (φ·g(0) − s) + φ·m rounds only relative to
    itself), φ·(g(0) + m) rounded above: no iterate can pin
    the angle closer than the residual it is steered by (at
    φ_max − 10⁻⁹ of the fold of row 57 of docs/accuracy_hypothesis.md, p(φ) is 3 ulp off in
    float64 and the iterate 2.9 ε s/p′). A printed form that is wrong beyond rounding is not
    excused: its lanes stay unconverged."""
    epsilon = float(np.finfo(dtype).eps)
    f, f_slope = _p_function(p), _p_function(slope)
    sizes, exact, spreads = [], [], []
    with mpmath.workdps(DIGITS):
        for angle in angles:
            s = dtype(float(f(mpmath.mpf(float(angle)))))
            if not (np.isfinite(s) and s > 0):
                continue
            theta = angle_of_length(f, f_slope, mpmath.mpf(float(s)), mpmath.mpf(phi_max))
            rate = abs(f_slope(theta))
            spread = float(s) / float(rate) if rate > 0 else math.inf
            if spread * epsilon > WIDTH_CHECK * float(theta):  # next to a fold: p′ varies across the width
                width = _width(f, f_slope, mpmath.mpf(float(s)), theta, phi_max, epsilon)
                spread = min(spread, width / epsilon)
            sizes.append(s)
            exact.append(float(theta))
            spreads.append(spread)
        rounded: np.ndarray = np.asarray(exact, dtype=dtype)
        with np.errstate(all="ignore"):
            ratio: np.ndarray = np.asarray(ratio_model(rounded), dtype=dtype)
            tail: np.ndarray = np.asarray(rounded * ratio, dtype=dtype)
            head: np.ndarray = np.asarray(rounded * dtype(leading), dtype=dtype)
            above = rounded * rounded >= series_below  # the residual φ·g − s: one rounded product
            tail = np.where(above, np.asarray(rounded * (dtype(leading) + ratio), dtype=dtype), tail)
            head = np.where(above, dtype(0), head)
        residual_error = [abs(mpmath.mpf(float(first)) + mpmath.mpf(float(second))
                              - f(mpmath.mpf(float(angle)))) if np.isfinite(second) else 0.0
                          for first, second, angle in zip(head, tail, rounded, strict=True)]
    # in Python floats: epsilon * s of a float32 s is a float32, and a large residual divided by it
    # overflowed in the cast (a RuntimeWarning from the Python API, for sin φ + sin(3φ)/9)
    tolerance = []
    for theta, spread, error, s in zip(exact, spreads, residual_error, sizes, strict=True):
        residual_ulps = min(float(error) / (epsilon * float(s)), RESIDUAL_ULPS)
        tolerance.append(2 * epsilon * (theta + spread * (1 + residual_ulps)))
    return NewtonLanes(np.asarray(sizes, dtype=dtype), np.asarray(exact), np.asarray(tolerance))


WIDTH_CHECK = 1e-6
"""Where ε s/p′(θ*) exceeds this fraction of θ*, :func:`newton_lanes` takes the width of the
angles whose p lies within ε s of s from two more inversions instead (:func:`_width`)."""


def _width(f: Callable[[Any], Any], f_slope: Callable[[Any], Any], s: Any, theta: Any, phi_max: float,
           epsilon: float) -> float:
    """max |φ − θ*| over the angles φ ≤ φ_max with |p(φ) − s| ≤ ε s. Next to a fold (p′ → 0) the
    first-order width ε s/p′(θ*) is far too large: at float64's p_max of eq 35 it was infinite
    (θ* = 2π, p′ = 0) where the angles that round to the same s span 3·10⁻⁵ rad, and that excused
    a Newton iteration that ended 0.35 rad from the angle after a bisection."""
    below = angle_of_length(f, f_slope, s * (1 - epsilon), mpmath.mpf(phi_max))
    above = angle_of_length(f, f_slope, s * (1 + epsilon), mpmath.mpf(phi_max))
    return float(max(theta - below, above - theta))


def fold_top(p: sp.Expr, slope: sp.Expr, p_max: float, phi_max: float, dtype: type) -> float:
    """For p with a fold at φ_max (p′(φ_max) = 0): the smallest angle whose p lies within ε of
    ``p_max`` rounded to ``dtype``, rounded down. Every |p| from p(that angle) to p_max is p of an
    angle in [that angle, φ_max] rounded, so the backends clip the start and the last iterate to it,
    a backward stable angle where p′ > 0: at φ_max itself R, H and the derivatives through 1/p′ are infinite
    or meaningless (eq 35 at float64's p_max: PyTorch's iterate was 2π for 29 of 116 points, its
    dφ/d|p| infinite)."""
    epsilon = float(np.finfo(dtype).eps)
    f, f_slope = _p_function(p), _p_function(slope)
    with mpmath.workdps(DIGITS):
        size = mpmath.mpf(float(dtype(p_max))) * (1 - epsilon)
        angle = angle_of_length(f, f_slope, size, mpmath.mpf(phi_max))
        top = dtype(float(angle))
        while mpmath.mpf(float(top)) > angle:
            top = np.nextafter(top, dtype(0))
    return float(top)


CHANGE, EDGE_STEP = sp.symbols("change u", real=True)
"""The symbols of :func:`edge_step`: c = r/p′ and u = k c/δ, δ = φ_max − φ."""


def edge_step(edge: sp.Rational) -> sp.Expr:
    """The next iterate of Newton in w = δ^k (δ = φ_max − φ) from φ, as an expression in PHI, CHANGE
    (c = r/p′, the step of Newton in φ) and EDGE_STEP (u = k c/δ ≥ :func:`edge_floor` > −1).

    w − k δ^(k−1) c = δ^k (1 + u) gives φ − δ((1 + u)^(1/k) − 1), written without the cancellation
    of (1 + u)^(1/k) − 1 for small u (far from the edge, where φ_max − δ(…) would also lose φ's
    digits): for k = 1/n, φ − c Σ_{j=1..n} C(n, j) u^(j−1)/n; for k = n,
    φ − n c/Σ_{j=0..n−1} r^j with r = (1 + u)^(1/n). Both tend to Newton's φ − c as u → 0."""
    if edge < 1:
        n = int(1 / edge)
        return PHI - CHANGE * sum(sp.binomial(n, j) / n * EDGE_STEP ** (j - 1) for j in range(1, n + 1))
    n = int(edge)
    root = (1 + EDGE_STEP) ** sp.Rational(1, n)
    horner: sp.Expr = 1 + root
    for _ in range(n - 2):  # 1 + r(1 + r(…)), kept as products of the root (not (1 + u)^(j/n))
        horner = sp.Add(1, sp.Mul(root, horner, evaluate=False), evaluate=False)
    return PHI - n * CHANGE / horner


@lru_cache(maxsize=8)
def _edge_step_function(edge: sp.Rational) -> Callable[..., Any]:
    return sp.lambdify((PHI, CHANGE, EDGE_STEP), edge_step(edge), "numpy")


def edge_floor(edge: sp.Rational) -> float:
    """The smallest u = k·c/δ that a step in w = δ^k takes: −1 + 2^−min(10k, 20). Below −1 Newton in
    w overshoots past the edge (w < 0); the step then shrinks δ by (1 + u)^(1/k), a factor of 2^−10
    for k ≤ 2 (2^−6.7 for k = 3, 2^−5 for k = 4), instead of bisecting the bracket: where the root
    lies within the rounding of s of the fold, every step overshoots (eq 35 at float64's p_max, in
    w = (2π − φ)³ before its start was clipped to ``fold_top``: 15 bisections from π to within
    2·10⁻⁵ of 2π). Exact in float32 (a multiple of 2^−24)."""
    return -1.0 + 2.0 ** -min(10 * float(edge), 20.0)


def newton_step(phi: np.ndarray, change: np.ndarray, edge: sp.Rational | None,
                top: float) -> tuple[np.ndarray, np.ndarray]:
    """(step, defined) of the safeguarded iteration from φ with the plain Newton correction
    ``change`` = r/p′: φ − change, or for an edge exponent k (:func:`edge_exponent`) Newton in
    w = δ^k, δ = φ_max − φ (:func:`edge_step`), defined while δ > 0, with u = k·change/δ raised to
    :func:`edge_floor` where the step would leave the range."""
    dtype = phi.dtype.type
    if edge is None:
        return phi - change, np.ones(phi.shape, dtype=bool)
    delta = (dtype(top) - phi).astype(dtype)
    u = (dtype(float(edge)) * change / np.where(delta > 0, delta, 1.0)).astype(dtype)
    defined = delta > 0
    floor = dtype(edge_floor(edge))
    change = np.where(u < floor, floor * delta / dtype(float(edge)), change).astype(dtype)  # c = u δ/k
    u = np.where(u < floor, floor, u).astype(dtype)
    step = np.asarray(_edge_step_function(edge)(phi, change, np.where(defined, u, 0.0).astype(dtype)))
    return step.astype(dtype), defined


def measured_iterations(lanes: NewtonLanes, start: Sequence[sp.Expr], far: FarStart,
                        printed: tuple[Callable[[np.ndarray], np.ndarray],
                                       Callable[[np.ndarray], np.ndarray]],
                        reciprocal: bool, bracket_top: float,
                        edge: sp.Rational | None = None, leading: float = 0.0,
                        fold_top: float = math.inf, series_below: float = 0.0) -> NewtonCount:
    """Steps the printed safeguarded Newton iteration needs, counted by running it.

    On the checks of ``lanes`` (:func:`newton_lanes`) the start (reverted series below
    ``far.switch``, the Chebyshev far start above) and the bracketed Newton steps are evaluated as
    the backends do, with ``printed`` = (p(φ)/φ − ``leading``, p′(φ)) as the plan's branches print
    them (evaluated with the ideal libm of :mod:`symrot.plan.evaluation`) and the residual
    (φ·``leading`` − s) + φ·(p(φ)/φ − ``leading``) where φ² < ``series_below`` (the tail's polynomial),
    φ·(``leading`` + (p(φ)/φ − ``leading``)) − s above, with the steps of Newton on 1/p if
    ``reciprocal`` (:class:`symrot.plan.ir.NewtonAngle`) or in w = (φ_max − φ)^k for an ``edge``
    exponent k (:func:`newton_step`), in the bracket [0, ``bracket_top``] (the largest value of the
    precision not above the exact φ_max), each iterate clipped to ``fold_top`` as the backends clip the
    last (:class:`symrot.plan.ir.NewtonAngle`).
    The steps are one more than the first step count after which every lane is within its
    tolerance, or ``MAX_ITERATIONS`` if no count is; then ``unconverged`` is the
    smallest s whose lane is still outside after ``MAX_ITERATIONS`` steps (the plan ends the
    range below it), and ∞ otherwise. Near a pole of p where φ(s)
    flattens (2 cos(2φ) atanh(3φ/2)/3 at φ = 2/3) the far start is poor in relative terms and Newton
    falls back on bisection: nine steps left the angle 10⁻³ off there."""
    ratio_model, slope_model = printed
    s_values, theta, limit = lanes
    if not len(s_values):
        return NewtonCount(0, math.inf)
    dtype = s_values.dtype.type
    coefficients = [float(c) for c in start]
    with np.errstate(all="ignore"):
        series = np.zeros_like(s_values)
        for c in coefficients[::-1]:
            series = (dtype(c) + s_values * s_values * series).astype(dtype)
        y = 2.0 * v_of_s(far.kind, far.scale, far.order, s_values) - 1.0
        far_value: np.ndarray = np.asarray(clenshaw(np.asarray(far.chebyshev), y), dtype=dtype)
        start_top = min(bracket_top, fold_top)  # a fold: the start below the angles that round alike
        phi = np.clip(np.where(s_values < far.switch, s_values * series, far_value), 0.0, start_top)
        phi = phi.astype(dtype)
        low, high = np.zeros_like(s_values), np.full_like(s_values, bracket_top)
        for step_count in range(1, MAX_ITERATIONS + 1):
            head = (phi * dtype(leading)).astype(dtype)
            ratio = np.asarray(ratio_model(phi), dtype=dtype)
            tail = (phi * ratio).astype(dtype)
            residual = np.where(phi * phi < series_below, ((head - s_values).astype(dtype) + tail),
                                (phi * (dtype(leading) + ratio)).astype(dtype) - s_values).astype(dtype)
            value = (head + tail).astype(dtype)
            high = np.where(residual > 0, phi, high)
            low = np.where(residual <= 0, phi, low)
            derivative: np.ndarray = np.asarray(slope_model(phi), dtype=dtype)
            safe = (derivative > 0) & np.isfinite(derivative)  # p′ = ∞: a zero step would stay there
            change = (residual / np.where(safe, derivative, 1.0)).astype(dtype)
            if reciprocal:
                change = (change * (value / np.where(s_values > 0, s_values, 1.0))).astype(dtype)
            step, defined = newton_step(phi, change, edge, bracket_top)
            inside = safe & defined & (step >= low) & (step <= high)
            phi = np.where(inside, step, 0.5 * (low + high)).astype(dtype)
            converged = np.abs(np.minimum(phi, fold_top).astype(np.float64) - theta) <= limit
            if np.all(converged):
                return NewtonCount(min(step_count + 1, MAX_ITERATIONS), math.inf)
    return NewtonCount(MAX_ITERATIONS, float(np.min(s_values[~converged])))
