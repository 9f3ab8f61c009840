"""An independent high-precision reference for any generating function p(φ) (issue 16).

Nothing here uses symrot's derivation, plan or backends: the generating function is parsed by
SymPy alone (:func:`parse`), p and p′ are lambdified to mpmath, and every quantity comes from the
definitions of Bauchau & Trainelli (2003), not from the closed forms that symrot derives:

* φ from |p| by a safeguarded Newton iteration (bisection whenever a step leaves the bracket) on
  [0, φ_max), n = p/|p|;
* R from eq (1), R = I + sin φ (n×) + 2 sin²(φ/2) (n×)² (no 1 − cos φ, which cancels), and the
  square root G the same with φ/2 (eq 76, m = 2);
* H from its definition ω = H ṗ (eq 20) with ω = axial(Ṙ Rᵀ) (eq 9): column i of H is
  axial((∂R/∂p_i) Rᵀ), the derivative by a central difference with step 10⁻⁽ᵈ⁺¹⁰⁾ at 2d + 30
  digits (truncation and rounding both below 10⁻ᵈ); K (eq 80, γ = K ṗ) the same from G;
* H⁻¹ and det H from H by mpmath linear algebra; the quaternion (cos φ/2, sin(φ/2) n) (eq 74);
* the operations on quaternions (from_quaternion, compose, rescale) from the quaternion product.

At p = 0: R = G = I, H = I (eq 13 with κ = 1 gives lim H = I), K = I/2, φ = 0, e = (1, 0, 0, 0).

The validity range (Section 3.4) is found by :func:`validity_edge`: the first φ in (0, 2π] where
p or p′ stops being finite, real and positive (a pole, the end of the domain, a fold p′ → 0 or
p′ → ∞), else 2π where ν = 2 sin(φ/2)/p → 0. A touching zero of p′ (p′ ≥ 0) is not detected.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Any

import mpmath
import numpy as np
import sympy as sp
from sympy.parsing.sympy_parser import parse_expr, standard_transformations

DIGITS = 60
"""Correct digits of every reference value."""

PHI = sp.Symbol("phi", real=True)


class RealCbrt(sp.Function):
    """The real (odd) cube root, as in symrot's expression syntax."""

    def fdiff(self, argindex: int = 1) -> sp.Expr:
        return sp.Rational(1, 3) / RealCbrt(self.args[0]) ** 2


def _real_cbrt(x: Any) -> Any:
    return mpmath.sign(x) * mpmath.cbrt(abs(x))


_NAMES: dict[str, Any] = {
    "phi": PHI, "pi": sp.pi, "sin": sp.sin, "cos": sp.cos, "tan": sp.tan, "asin": sp.asin,
    "acos": sp.acos, "atan": sp.atan, "sinh": sp.sinh, "cosh": sp.cosh, "tanh": sp.tanh,
    "asinh": sp.asinh, "acosh": sp.acosh, "atanh": sp.atanh, "exp": sp.exp, "log": sp.log,
    "sqrt": sp.sqrt, "cbrt": RealCbrt,
}


def parse(text: str) -> sp.Expr:
    """``text`` in symrot's syntax (phi, pi, + - * / ** and the functions above) as SymPy."""
    return parse_expr(text, local_dict=dict(_NAMES), global_dict={"Integer": sp.Integer,
                      "Float": sp.Float, "Rational": sp.Rational, "Symbol": sp.Symbol},
                      transformations=standard_transformations, evaluate=True)


def mp_function(expr: sp.Expr) -> Callable[[Any], Any]:
    """φ ↦ expr(φ) in mpmath at the working precision (constants too are returned as mpf)."""
    function = sp.lambdify(PHI, expr, modules=[{"RealCbrt": _real_cbrt}, "mpmath"])

    def evaluate(phi: Any) -> Any:
        value = function(phi)
        return value if isinstance(value, mpmath.mpf | mpmath.mpc) else mpmath.mpf(value)

    return evaluate


def _is_good(value: Any) -> bool:
    return isinstance(value, mpmath.mpf) and mpmath.isfinite(value) and value > 0


def validity_edge(p: Callable[[Any], Any], dp: Callable[[Any], Any], grid: int = 4000,
                  digits: int = 40) -> mpmath.mpf:
    """φ_max: the first φ ∈ (0, 2π] where p or p′ is not finite, real and > 0, else 2π."""

    def good(phi: Any) -> bool:
        try:
            return _is_good(p(phi)) and _is_good(dp(phi))
        except (ZeroDivisionError, ValueError, OverflowError):
            return False

    with mpmath.workdps(digits):
        top = 2 * mpmath.pi
        low = mpmath.mpf(0)
        for k in range(1, grid + 1):
            phi = top * k / grid
            if not good(phi):
                high = phi
                for _ in range(int(digits * 3.33) + 8):
                    middle = (low + high) / 2
                    low, high = (middle, high) if good(middle) else (low, middle)
                return +high
            low = phi
        return top


SMALL_ANGLES = (mpmath.mpf("3e-31"), mpmath.mpf("7e-13"))
"""Where :func:`loses_digits_at_small_angles` looks (not powers of two: the roundings of exp(φ) and
exp(−φ) at 2⁻¹³³ drop the same φ²/2 and their difference is exact by symmetry)."""


def loses_digits_at_small_angles(function: Callable[[Any], Any]) -> bool:
    """Whether ``function`` loses more than its guard digits at one of SMALL_ANGLES: its values at
    DIGITS + 10 digits and at twice as many plus 80 differ by more than 10^−DIGITS relative (the
    cancellation of 1 − cos φ or exp(φ) − exp(−φ)), or it cannot be evaluated there."""
    for angle in SMALL_ANGLES:
        values = []
        for digits in (DIGITS + 10, 2 * (DIGITS + 10) + 80):
            with mpmath.workdps(digits):
                try:
                    values.append(+function(+angle))
                except (ZeroDivisionError, ValueError):
                    return True
        coarse, fine = values
        if fine == 0 or abs(coarse - fine) > abs(fine) * mpmath.mpf(10) ** -DIGITS:
            return True
    return False


@dataclass
class GeneratingFunction:
    """p(φ) with its derivative, as mpmath functions, and its validity range."""

    expression: str
    cancels: bool = False
    """True when evaluating p(φ) loses digits at small φ (e.g. exp(φ) − exp(−φ)): extra digits. Set
    here too when p or p′ measurably loses them (:func:`loses_digits_at_small_angles`), so that a
    function typed without the flag (2(1 − cos φ)/φ) is not measured against a cancelled reference."""
    phi_max_text: str | None = None
    """φ_max as a SymPy expression; None: :func:`validity_edge`."""
    expr: sp.Expr = field(init=False)
    p: Callable[[Any], Any] = field(init=False)
    dp: Callable[[Any], Any] = field(init=False)
    phi_max: mpmath.mpf = field(init=False)

    def __post_init__(self) -> None:
        self.expr = parse(self.expression)
        self.p = mp_function(self.expr)
        self.dp = mp_function(sp.diff(self.expr, PHI))
        with mpmath.workdps(DIGITS + 10):
            if self.phi_max_text is None:
                self.phi_max = validity_edge(self.p, self.dp)
            else:
                self.phi_max = mpmath.mpf(sp.N(parse(self.phi_max_text), DIGITS + 10))
        self.cancels = self.cancels or any(loses_digits_at_small_angles(f) for f in (self.p, self.dp))

    def guard(self, s: Any) -> int:
        """Extra digits for |p| = s: the cancellation of p(φ) at small φ, when flagged."""
        if not self.cancels or s == 0 or s >= 1:
            return 10
        return 10 + 2 * int(-mpmath.log10(s) + 1)

    def value(self, phi: Any) -> Any:
        """p(φ), with the guard digits of its size (p(0) = 0: p is odd, even if written as 0/0)."""
        if phi == 0:
            return mpmath.mpf(0)
        with mpmath.workdps(mpmath.mp.dps + self.guard(abs(phi))):
            value = self.p(phi)
        return +value

    def p_max(self) -> mpmath.mpf:
        """|p| at the edge of the validity range (inf at a pole)."""
        try:
            value = self.value(self.phi_max)
        except (ZeroDivisionError, ValueError):
            return mpmath.inf
        return abs(value) if isinstance(value, mpmath.mpf) else mpmath.inf

    def inverse(self, s: Any, guess: Any = None) -> mpmath.mpf:
        """φ ∈ [0, φ_max) with p(φ) = s at the working precision (safeguarded Newton)."""
        if s == 0:
            return mpmath.mpf(0)
        tolerance = mpmath.mpf(2) ** (-mpmath.mp.prec + 8)
        low, high = mpmath.mpf(0), +self.phi_max
        phi = mpmath.mpf(guess) if guess is not None and 0 < guess < high else min(s, high / 2)
        for _ in range(20 * mpmath.mp.dps):
            residual = self.value(phi) - s
            if residual == 0:  # exact at this precision (the Newton step would be φ itself, which
                return phi     # the bracket test below would take for a step outside and bisect)
            if residual > 0:
                high = phi
            else:
                low = phi
            with mpmath.workdps(mpmath.mp.dps + self.guard(phi)):
                slope = self.dp(phi)
            step = phi - residual / slope if _is_good(slope) else low - 1
            if not low < step < high:
                step = (low + high) / 2
            if abs(step - phi) <= tolerance * step or high - low <= tolerance * high:
                return step
            phi = step
        raise ValueError(f"no angle found for |p| = {mpmath.nstr(s, 20)}")


def skew(v: Sequence[Any]) -> mpmath.matrix:
    """(v×), the skew-symmetric matrix of v."""
    return mpmath.matrix([[0, -v[2], v[1]], [v[2], 0, -v[0]], [-v[1], v[0], 0]])


def _axial(w: mpmath.matrix) -> list[Any]:
    return [(w[2, 1] - w[1, 2]) / 2, (w[0, 2] - w[2, 0]) / 2, (w[1, 0] - w[0, 1]) / 2]


def rodrigues(phi: Any, axis: Sequence[Any]) -> mpmath.matrix:
    """Eq (1): R = I + sin φ (u×) + 2 sin²(φ/2) (u×)² for a unit axis u."""
    u = skew(axis)
    return mpmath.eye(3) + mpmath.sin(phi) * u + 2 * mpmath.sin(phi / 2) ** 2 * (u * u)


@dataclass
class State:
    """Every reference quantity at one parameter vector p."""

    angle: mpmath.mpf
    R: mpmath.matrix
    G: mpmath.matrix
    H: mpmath.matrix
    K: mpmath.matrix
    quaternion: list[Any]

    @property
    def H_inverse(self) -> mpmath.matrix:
        with mpmath.workdps(max(mpmath.mp.dps, 2 * DIGITS)):
            return mpmath.inverse(self.H)

    @property
    def det_H(self) -> mpmath.mpf:
        with mpmath.workdps(max(mpmath.mp.dps, 2 * DIGITS)):
            return mpmath.det(self.H)


class Reference:
    """The definitions of Section 2–3 evaluated for one generating function at ``digits``."""

    def __init__(self, function: GeneratingFunction, digits: int = DIGITS) -> None:
        self.function = function
        self.digits = digits
        self._states: dict[tuple[Any, ...], State] = {}

    def kappa(self) -> Any:
        """κ = p′(0) (eq 12) as p(t)/t at t = 10^−(digits + 10), which p written as 0/0 at φ = 0 allows
        (2(1 − cos φ)/φ); its relative error is of order t². H(0) was I whatever κ (φ + tanh φ, κ = 2:
        a correct H(0) = I/2 measured 2.25·10¹⁵ ulp)."""
        with mpmath.workdps(self.digits + 20):
            t = mpmath.mpf(10) ** -(self.digits + 10)
            return self.function.value(t) / t

    def _rotation(self, p: Sequence[Any], guess: Any, half: bool = False) -> tuple[Any, mpmath.matrix]:
        s = mpmath.sqrt(sum(v * v for v in p))
        if s == 0:
            return mpmath.mpf(0), mpmath.eye(3)
        phi = self.function.inverse(s, guess)
        axis = [v / s for v in p]
        return phi, rodrigues(phi / 2 if half else phi, axis)

    def state(self, p: Sequence[float | Any], guess: Any = None) -> State:
        """R, G, H, K, φ and the quaternion at p (exact binary inputs are read exactly; cached)."""
        key = tuple(mpmath.mpf(v) for v in p)
        if key not in self._states:
            if len(self._states) > 64:
                self._states.clear()
            self._states[key] = self._state(list(key), guess)
        return self._states[key]

    def _state(self, p: list[Any], guess: Any) -> State:
        s = mpmath.sqrt(sum(v * v for v in p))
        inner = 2 * self.digits + 30  # p(φ) adds its own guard digits (GeneratingFunction.value)
        with mpmath.workdps(inner):
            p = [mpmath.mpf(v) for v in p]
            s = mpmath.sqrt(sum(v * v for v in p))
            if s == 0:  # ω = H ṗ with ṗ = κ φ̇ n at the identity: H = I/κ, K = I/(2κ)
                zero, kappa = mpmath.mpf(0), self.kappa()
                return State(zero, mpmath.eye(3), mpmath.eye(3), mpmath.eye(3) / kappa,
                             mpmath.eye(3) / (2 * kappa), [mpmath.mpf(1), zero, zero, zero])
            phi, rotation = self._rotation(p, guess)
            root = rodrigues(phi / 2, [v / s for v in p])
            step = mpmath.mpf(10) ** -(self.digits + 10) * max(1, s)
            h_columns, k_columns = [], []
            for i in range(3):
                plus, minus = list(p), list(p)
                plus[i] += step
                minus[i] -= step
                phi_plus, r_plus = self._rotation(plus, phi)
                phi_minus, r_minus = self._rotation(minus, phi)
                d_r = (r_plus - r_minus) / (2 * step)
                d_g = (rodrigues(phi_plus / 2, [v / mpmath.norm(plus) for v in plus])
                       - rodrigues(phi_minus / 2, [v / mpmath.norm(minus) for v in minus])) / (2 * step)
                h_columns.append(_axial(d_r * rotation.T))
                k_columns.append(_axial(d_g * root.T))
            tangent = mpmath.matrix([[h_columns[j][i] for j in range(3)] for i in range(3)])
            root_tangent = mpmath.matrix([[k_columns[j][i] for j in range(3)] for i in range(3)])
            quaternion = [mpmath.cos(phi / 2)] + [mpmath.sin(phi / 2) * v / s for v in p]
        return State(phi, rotation, root, tangent, root_tangent, quaternion)

    # -- derivatives (issue 19) ------------------------------------------------------------------
    def tensor(self, p: Sequence[Any], name: str) -> mpmath.matrix:
        """R, R_T (Rᵀ), H, H_T (Hᵀ) or H_inverse at p, from the definitions above."""
        state = self.state(p)
        if name.endswith("_T"):
            return getattr(state, name[:-2]).T
        return getattr(state, name)

    def derivative(self, p: Sequence[Any], a: Sequence[Any], name: str) -> mpmath.matrix:
        """∂(T a)/∂p for a fixed a, column j = d(T a)/dp_j, T = :meth:`tensor` ``name``: a central
        difference of T itself with step 10⁻³⁰ max(1, |p|) (truncation ~10⁻⁶⁰; T is exact to ~10⁻⁸⁰,
        so rounding ~10⁻⁵⁰)."""
        with mpmath.workdps(2 * self.digits + 30):
            p = [mpmath.mpf(v) for v in p]
            a_vector = mpmath.matrix([mpmath.mpf(v) for v in a])
            step = mpmath.mpf(10) ** -30 * max(1, mpmath.sqrt(sum(v * v for v in p)))
            columns = []
            for j in range(3):
                plus, minus = list(p), list(p)
                plus[j] += step
                minus[j] -= step
                columns.append((self.tensor(plus, name) - self.tensor(minus, name)) * a_vector / (2 * step))
            return mpmath.matrix([[columns[j][i] for j in range(3)] for i in range(3)])

    def along(self, p: Sequence[Any], pdot: Sequence[Any], pddot: Sequence[Any]
              ) -> tuple[mpmath.matrix, mpmath.matrix]:
        """(Ḣ ṗ, α) on the trajectory p(t) = p + t ṗ + t² p̈/2 at t = 0: d/dt of H(p(t)) applied to ṗ,
        and α = dω/dt of ω(t) = H(p(t)) ṗ(t) (eq 20), by central differences in t (step as above)."""
        with mpmath.workdps(2 * self.digits + 30):
            p, v, w = ([mpmath.mpf(c) for c in u] for u in (p, pdot, pddot))
            step = mpmath.mpf(10) ** -30
            values = {}
            for t in (step, -step):
                point = [p[i] + t * v[i] + t * t * w[i] / 2 for i in range(3)]
                values[t] = (self.state(point).H, mpmath.matrix([v[i] + t * w[i] for i in range(3)]))
            (h_plus, v_plus), (h_minus, v_minus) = values[step], values[-step]
            rate = (h_plus - h_minus) * mpmath.matrix(v) / (2 * step)
            acceleration = (h_plus * v_plus - h_minus * v_minus) / (2 * step)
            return rate, acceleration

    # -- operations on rotations of any size ------------------------------------------------
    def from_quaternion(self, e: Sequence[Any]) -> list[Any]:
        """p of the rotation e (either sign); NaN when its angle is ≥ φ_max."""
        e = [mpmath.mpf(v) for v in e]
        with mpmath.workdps(self.digits + 20):
            norm = mpmath.sqrt(sum(v * v for v in e[1:]))
            if norm == 0:
                return [mpmath.mpf(0)] * 3
            sign = -1 if e[0] < 0 else 1
            phi = 2 * mpmath.atan2(norm, abs(e[0]))
            if phi >= self.function.phi_max:
                return [mpmath.nan] * 3
            size = self.function.value(phi)
            return [sign * size * v / norm for v in e[1:]]

    def compose(self, p1: Sequence[Any], p2: Sequence[Any], guess: tuple[Any, Any] = (None, None)
                ) -> list[Any]:
        """p3 with R(p3) = R(p2) R(p1) (eqs 7–8 through the quaternion product)."""
        a = self.state(p1, guess[0]).quaternion
        b = self.state(p2, guess[1]).quaternion
        with mpmath.workdps(self.digits + 20):
            product = [b[0] * a[0] - (b[1] * a[1] + b[2] * a[2] + b[3] * a[3]),
                       b[0] * a[1] + a[0] * b[1] + (b[2] * a[3] - b[3] * a[2]),
                       b[0] * a[2] + a[0] * b[2] + (b[3] * a[1] - b[1] * a[3]),
                       b[0] * a[3] + a[0] * b[3] + (b[1] * a[2] - b[2] * a[1])]
        return self.from_quaternion(product)

    def rescale(self, p: Sequence[Any], guess: Any = None) -> list[Any]:
        """p itself when its angle is ≤ π, else the parameters of the same rotation, angle 2π − φ."""
        e = self.state(p, guess).quaternion
        return [mpmath.mpf(v) for v in p] if e[0] >= 0 else self.from_quaternion(e)


def as_float(value: Any) -> np.ndarray:
    """An mpmath matrix or list as a float64 array (for printing and tests)."""
    if isinstance(value, mpmath.matrix):
        return np.array([[float(value[i, j]) for j in range(value.cols)] for i in range(value.rows)])
    return np.array([float(v) for v in value])
