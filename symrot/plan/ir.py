"""The intermediate representation of an evaluation plan: what :mod:`symrot.plan.builder` decides and every
backend prints.

Its own module so that the planners (:mod:`symrot.plan.builder`, :mod:`symrot.plan.quaternion`) and the
backends share it without importing each other; :mod:`symrot.plan.builder` re-exports every name.

IR (all frozen dataclasses, SymPy expressions in the symbols ``PHI``, ``S`` = |p|, ``X`` = x and,
for the sine family, ``D`` = p_max² − x):

``EvaluationPlan``
    ``name``, ``p`` (generating function), ``p_max`` (float, ``inf`` when unbounded: outside
    |p| < p_max every output is NaN), ``phi_max`` (float), ``precisions``: {"float64": …,
    "float32": …} → ``PrecisionPlan``, ``e0_min`` (operations, :mod:`symrot.plan.quaternion`) and
    ``complement`` (p_max² when expressions use ``D``, which backends compute with compensated
    arithmetic: :func:`symrot.plan.algebraic.fold_complement`).
``PrecisionPlan``
    ``dtype``, ``epsilon``, ``angle`` (``ClosedAngle`` or ``NewtonAngle``), ``coefficients``:
    {name → ``Constant``, ``Algebraic`` or ``Branch``}, ``quaternion_scale`` (σ = p(φ)/sin(φ/2)).
``Algebraic(expression)``
    the coefficient as an algebraic function of x (and d) with no branch (e.g. 1 + x/4 for H⁻¹₀ of
    2 tan(φ/2)); found by substituting the closed inverse φ(s) (:mod:`symrot.plan.algebraic`) and
    accepted only when it is accurate in float64 on a log grid of x, p = 0 exactly.
``Constant(value)``
    identically constant coefficient (e.g. H⁻¹₂ = 1/4 for 2 sin(φ/2)): emit the number.
``Branch(threshold, horner, closed, safe_phi, measured_ulp, edge_ulp, accurate_threshold, accurate_terms)``
    with ``t`` the branch variable (x = |p|² for coefficients, φ² inside ``NewtonAngle`` and σ):
    if t < threshold evaluate the polynomial Σ horner[j] t^j (exact rationals, Horner order);
    else evaluate ``closed`` (an expression in ``PHI``, and ``S``/``D`` where the base angle of a
    closed inverse was substituted).  Each branch is evaluated only where it applies (or on
    guarded inputs), so neither ever divides by zero.  Common subexpressions may only be shared
    *inside* one branch.
``ClosedAngle(expression)``
    φ = expression(S), S = |p| = √x, the closed-form inverse of p(φ) (e.g. 4 atan(S/4); for the
    sine family k asin(S/k) becomes k atan2(S, √D), accurate up to the fold).
``NewtonAngle(start, ratio, slope, iterations, phi_max, far, reciprocal, converges_below, leading, edge,
fold_top)``
    φ from s = |p| by Newton on r(φ) = φ·g(φ²) − s (on 1/(φ·g(φ²)) − 1/s if ``reciprocal``),
    started from the odd reverted series φ ≈ Σ start[k] s^(2k+1) below ``far.switch`` and from
    the fold-aware interpolant ``far`` (:mod:`symrot.plan.newton_start`) above it, where g = p(φ)/φ =
    ``leading`` + ``ratio`` (``ratio``: Branch in t = φ² for the tail g − g(0), Taylor-safe, the
    residual printed as (φ·leading − s) + φ·ratio below its switch) and ``slope`` (Branch in t = φ²
    for p′(φ)).
    Safeguard: keep a bracket [lo, hi] ⊂ [0, phi_max] (``phi_max`` rounded down in the precision),
    shrink it by the sign of r and bisect when a step leaves it or p′ is not finite (a zero step
    from where the printed p′ overflows would stay there). With an ``edge`` exponent k the
    steps are Newton's in w = (φ_max − φ)^k, where p is regular at a fold or an asin edge.
``QuaternionScale(algebraic, branch)``
    σ = p(φ)/sin(φ/2) of from_quaternion (:mod:`symrot.plan.quaternion`): algebraic in e₀, or a
    ``Branch`` in t = φ².
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import lru_cache

import mpmath
import sympy as sp
from mpmath.libmp import from_rational

from symrot.core.functions import mpmath_namespace
from symrot.core.parsing import PHI
from symrot.plan.newton_start import FarStart


@dataclass(frozen=True)
class Constant:
    value: sp.Expr


@dataclass(frozen=True)
class Branch:
    threshold: float
    horner: tuple[sp.Expr, ...]
    closed: sp.Expr
    safe_phi: float
    measured_ulp: float
    edge_ulp: float = 0.0
    """Worst error of the closed form on the upper half of the range (towards φ_max)."""
    accurate_threshold: float | None = None
    """The smallest switch the accuracy allows (``threshold`` is moved up from it for speed), with
    the first ``accurate_terms`` coefficients of ``horner``: for backends where a branch costs
    more than a short polynomial saves, such as NumPy's masked passes over whole arrays."""
    accurate_terms: int | None = None

    @property
    def smallest_switch(self) -> tuple[float, tuple[sp.Expr, ...]]:
        """(switch, Horner coefficients) with the switch as small as the accuracy allows."""
        if self.accurate_threshold is None or self.accurate_terms is None:
            return self.threshold, self.horner
        return self.accurate_threshold, self.horner[:self.accurate_terms]


@dataclass(frozen=True)
class Algebraic:
    expression: sp.Expr


ANGLE_CORRECTION_GROWTH = 4.0
"""φ p′/p above which the backends correct the half-angle sine and cosine of a Newton angle by λ
(``EvaluationPlan.angle_correction``): λ's error is about (k + ½) ε s/p′ for a residual k units of
roundoff off, φ's rounding ½ ε φ, so λ gains where φ p′/p > 2k + 1 (k ≈ 1–2 for the plans' ratios)."""

NARROW_CORRECTION_GROWTH = 1.0
"""φ p′/p above which a float32 closed angle takes λ from float64's angle next to 2π: that λ is exact
to float32's eyes, so it gains wherever s is better conditioned than φ. 3 sinh(φ/3) (φ p′/p = 2.2 at
2π) had float32 ``tangent_inverse`` 1.8·10⁷ ulp, 5.7 times its condition number, at 2π − 10⁻⁶."""

ANGLE_CORRECTION_LIMIT = 4
"""λ is applied while |λ| ≤ ANGLE_CORRECTION_LIMIT ε φ (``EvaluationPlan.angle_correction_bound``):
a larger λ means the iterate φ was not converged and one Newton correction would not be exact."""


@dataclass(frozen=True)
class ClosedAngle:
    expression: sp.Expr


@dataclass(frozen=True)
class NewtonAngle:
    start: tuple[sp.Expr, ...]
    ratio: Branch
    slope: Branch
    iterations: int
    phi_max: float
    far: FarStart
    """The start for s ≥ far.switch (see :mod:`symrot.plan.newton_start`)."""
    reciprocal: bool
    """Steps of Newton on 1/p(φ) = 1/s instead of p(φ) = s: the step (s − p)/p′ times p/s. Used when
    p is unbounded (a pole at φ_max), where 1/p is nearly linear: the direct step from a start just
    below the pole moves by less than half an ulp (row 96 of docs/accuracy_hypothesis.md stayed
    10⁻⁶ off for 64 steps)."""
    converges_below: float
    """The smallest s = |p| of the plan's checks whose angle ``iterations`` steps do not reach
    (:func:`symrot.plan.newton_start.measured_iterations`); the precision's range ends below it."""
    leading: sp.Expr
    """g(0) = κ (eq 12): ``ratio`` is the tail g − g(0), and the backends print the residual as
    (φ g(0) − s) + φ (g − g(0)) where the tail's polynomial applies (φ² below ``split_below``),
    φ (g(0) + (g − g(0))) − s = φ g − s above. φ − s is exact (Sterbenz) once φ is within a factor 2
    of s, so there the residual keeps the digits that rounding φ·g to s's precision loses (a half
    ulp of s, and the closed form's own ulps where the polynomial applies instead; above, the split
    only added roundings where p/φ is far from 1: held-out seed 2029, float32 ω next to 2π):
    cbrt(6(φ − sin φ)) (eq 35) was up to 2.33 ulp off in float64 with r = φ·g − s, and 0.91 with
    this residual."""
    edge: sp.Rational | None = None
    """k where the steps are Newton's in w = (φ_max − φ)^k instead of φ
    (:func:`symrot.plan.newton_start.newton_step`): p_max − p ∝ (φ_max − φ)^k at the end of the range,
    a fold (k = 2, 3, 4) or an edge where p′ → ∞ (k = 1/2 for asin). The step from φ with
    δ = φ_max − φ and the Newton correction c = r/p′ is φ_max − δ(1 + u)^(1/k), u = k c/δ, printed
    without cancellation (:func:`symrot.plan.newton_start.edge_step`) and taken while δ > 0, with u raised to
    :func:`symrot.plan.newton_start.edge_floor` (> −1) where Newton in w would overshoot past the edge;
    Newton in φ converges only linearly next to a fold and overshoots past an asin edge (row 187
    of docs/accuracy_hypothesis.md was NaN for φ > 0.99995)."""
    fold_top: float = math.inf
    """For a fold at φ_max (p′(φ_max) = 0): the smallest angle whose p rounds like p_max
    (:func:`symrot.plan.newton_start.fold_top`); every backend clips the start and the last iterate to it
    (the residual there is negative beyond rounding). inf otherwise."""

    def __post_init__(self) -> None:
        if self.ratio.smallest_switch[0] != self.ratio.threshold:
            raise ValueError("the tail of Newton's ratio has one switch for every backend "
                             "(plan._branch_for with whole=...): split_below relies on it")

    @property
    def split_below(self) -> float:
        """φ² below which the backends print the residual split, (φ g(0) − s) + φ (g − g(0)): the
        switch of the tail's polynomial (``ratio``), which every backend takes for the tail
        itself, so that the split applies exactly where the tail is its polynomial."""
        return self.ratio.threshold


Coefficient = Constant | Algebraic | Branch


@dataclass(frozen=True)
class QuaternionScale:
    """σ = p(φ)/sin(φ/2), **p** = σ **e**: ``algebraic`` in
    :data:`~symrot.plan.quaternion.E0` or ``branch`` in t = φ²."""

    algebraic: sp.Expr | None
    branch: Branch | None


def uses_angle(coefficient: Coefficient) -> bool:
    """Whether the coefficient's code needs the angle φ (a Branch whose closed form has φ)."""
    return isinstance(coefficient, Branch) and coefficient.closed.has(PHI)


@dataclass(frozen=True)
class PrecisionPlan:
    dtype: str
    epsilon: float
    angle: ClosedAngle | NewtonAngle
    coefficients: dict[str, Coefficient]
    quaternion_scale: QuaternionScale
    """σ with **p** = σ **e** for from_quaternion (see :mod:`symrot.plan.quaternion`)."""
    x_limit: float = 2.0**600
    """Edge of the domain for unbounded p: every output is NaN for x = |p|² ≥ x_limit, the largest
    power of two up to which every printed form is right (:mod:`symrot.plan.domain`)."""
    derivative_x_limit: float = 2.0**600
    """The same edge for the derivatives of :mod:`symrot.core.derivatives` (≤ ``x_limit``): their slopes
    dc/dx may overflow earlier (Wiener–Milenkovic's −256/(x + 16)³ beyond 2^341), and must not move
    the domain of the other functions."""

    def uses_angle(self) -> bool:
        """Whether some coefficient's closed form needs the angle φ (and its half-angle sine and
        cosine); algebraic plans (Cayley, Wiener–Milenkovic) never do."""
        return any(uses_angle(c) for c in self.coefficients.values())


@dataclass(frozen=True)
class EvaluationPlan:
    name: str
    p: sp.Expr
    p_max: float
    phi_max: float
    precisions: dict[str, PrecisionPlan]
    e0_min: float | None
    """from_quaternion (e₀ ≥ 0) is valid iff e₀ > e0_min; None: every rotation is representable."""
    complement: sp.Rational | None = None
    """p_max² when expressions use the symbol ``D`` = p_max² − x, which backends must compute with
    compensated arithmetic (:func:`symrot.plan.algebraic.fold_complement`)."""
    p_max_squared_exact: sp.Float | None = None
    """p_max² at 50 digits (None when p is unbounded): see :meth:`boundary`."""

    def complement_parts(self, mantissa_bits: int) -> tuple[sp.Rational, sp.Rational]:
        """(high, low): ``complement`` = p_max² rounded to nearest with ``mantissa_bits`` bits, and
        what is left rounded the same way, so that a compensated sum started from high + low keeps
        p_max² to twice the precision. low is 0 for the named families (k² = 1, 4, 9, …); 16/9, the
        p_max² of (4/3) sin(3φ/4), is no float."""
        assert self.complement is not None
        squared = sp.Rational(self.complement)
        high = _rounded(squared, mantissa_bits)
        return high, _rounded(squared - high, mantissa_bits)

    def across_tensors(self) -> tuple[str, ...]:
        """The tensors T whose across-axis part t = c₀ − c₂|p|² is a coefficient of the plan
        (``T_across``, in every precision): backends write T = t I + c₁ (p×) + c₂ p pᵀ with it, and
        with t = c₀ − c₂|p|² computed from c₀ and c₂ for the others (whose c₀ is a constant)."""
        names = [n.removesuffix("_across") for n in self.precisions["float64"].coefficients
                 if n.endswith("_across")]
        return tuple(n for n in names
                     if all(n + "_across" in plan.coefficients for plan in self.precisions.values()))

    def angle_correction(self) -> dict[str, str]:
        """{precision: the precision whose angle gives λ = φ* − φ (its Newton helpers ``ratio`` and
        ``slope`` when it iterates, else its closed angle)} for the precisions whose angle is a
        Newton iteration, and for a float32 closed angle (below): λ is the part of the exact angle φ*
        below the last bit of the iterate φ, one more Newton correction of φ, and backends print
        sin(φ/2) + cos(φ/2) λ/2 and cos(φ/2) − sin(φ/2) λ/2 for the half-angle sine and cosine
        while |λ| ≤ :meth:`angle_correction_bound` φ. float64's helpers serve float32 too when
        float64 has them: a float32 residual s − p(φ) is as uncertain as the rounding of φ itself.

        Next to 2π (ν → 0) sin(φ/2) is far better conditioned in s than in φ when p grows faster
        than φ: the half ulp of φ's rounding moved R₁ = sin φ/p of cosh(3φ/2)(2 tanh(φ/4) +
        3 tanh(φ/3)/2) at φ = 6.28318 by 6.6 times its condition number in s (float64); with λ it
        is within 2.2 times, and float32 within 5.6 ulp instead of 2.4·10⁵.

        λ is used only where φ p′/p > :data:`ANGLE_CORRECTION_GROWTH`: its own error, that of the
        residual s − p(φ) divided by p′, exceeds the half ulp of φ's rounding where p grows no
        faster than φ (cbrt(6(φ − sin φ)) at φ ≈ 1: H⁻¹ 3.4 ulp from NumPy with λ, 1.8 without).

        A float32 closed angle takes λ = φ₆₄(s) − φ, float64's angle (closed, or one Newton step
        from φ with float64's helpers) minus its own, wherever it is used: that λ is exact to
        float32's eyes. 2 sinh(3φ/2)/3 at φ = 6.283: float32 ``pdot`` was 1.8·10⁶ ulp off. Only
        where φ p′/p > :data:`NARROW_CORRECTION_GROWTH` (any growth faster than φ: the λ is exact)
        next to 2π, where sin(φ/2) is ill conditioned in φ (not at the
        tangent family's poles, where it is not: there λ would only cost time), and not for p whose
        plan has a complement d (float32's d would have to be widened exactly)."""
        correction: dict[str, str] = {}
        if self.grows_faster_than_angle():
            newton = [label for label, precision in self.precisions.items()
                      if isinstance(precision.angle, NewtonAngle)]
            correction = {label: "float64" if "float64" in newton else label for label in newton}
        narrow = self.precisions.get("float32")
        if (narrow is not None and isinstance(narrow.angle, ClosedAngle) and "float64" in self.precisions
                and self.complement is None and narrow.uses_angle()
                and _grows_faster_than_angle(self.p, self.phi_max, where_half_sine_is_ill=True,
                                             growth_above=NARROW_CORRECTION_GROWTH)):
            correction["float32"] = "float64"
        return correction

    def angle_correction_bound(self, label: str) -> float:
        """|λ|/φ above which precision ``label`` leaves the half angles uncorrected:
        :data:`ANGLE_CORRECTION_LIMIT` units of its roundoff."""
        return ANGLE_CORRECTION_LIMIT * self.precisions[label].epsilon

    def grows_faster_than_angle(self) -> bool:
        """Whether φ p′/p exceeds :data:`ANGLE_CORRECTION_GROWTH` anywhere in the range (on 256
        angles at 30 digits, the same on every machine): where it does not, λ is never used and
        is not printed (eq 35)."""
        return _grows_faster_than_angle(self.p, self.phi_max)

    def boundary(self, mantissa_bits: int) -> tuple[float, bool]:
        """(B, inclusive) for a binary type with that many mantissa bits: B = p_max² rounded to the
        type; inclusive when B lies below the exact p_max², so that x = |p|² ≤ B is inside the range
        (e.g. p = fl(2π) u for the rotation vector); otherwise inside means x < B."""
        if self.p_max_squared_exact is None:
            return float("inf"), False
        with mpmath.workprec(200):
            exact = mpmath.mpf(self.p_max_squared_exact._to_mpmath(200))
            with mpmath.workprec(mantissa_bits):
                rounded = +exact
            return float(rounded), bool(rounded < exact)


@lru_cache(maxsize=64)
def _grows_faster_than_angle(p: sp.Expr, phi_max: float, where_half_sine_is_ill: bool = False,
                             growth_above: float = ANGLE_CORRECTION_GROWTH) -> bool:
    """See ``EvaluationPlan.grows_faster_than_angle`` (φ p′/p > ``growth_above`` somewhere); with
    ``where_half_sine_is_ill``, only at angles where sin(φ/2) is ill conditioned in φ,
    |(φ/2) cot(φ/2)| > ANGLE_CORRECTION_GROWTH (φ > 5.8: next to 2π)."""
    end = phi_max if math.isfinite(phi_max) else 4 * math.pi
    growth = sp.lambdify(PHI, PHI * sp.diff(p, PHI) / p, modules=[mpmath_namespace(), "mpmath"])
    with mpmath.workdps(30):
        for k in range(1, 257):
            angle = mpmath.mpf(end) * k / 257
            half_sine_condition = abs(angle / 2 * mpmath.cot(angle / 2))
            if where_half_sine_is_ill and not half_sine_condition > ANGLE_CORRECTION_GROWTH:
                continue
            try:
                value = growth(angle)
            except (ZeroDivisionError, ValueError, OverflowError):
                continue
            if isinstance(value, mpmath.mpf) and value > growth_above:
                return True
    return False


def nearest_binary(value: sp.Rational, mantissa_bits: int) -> mpmath.mpf:
    """The number of ``mantissa_bits`` bits nearest to ``value`` (ties to even), as an mpmath
    number: what a compiler makes of a literal of ``value`` in a format of that precision."""
    return mpmath.mpf(from_rational(int(value.p), int(value.q), mantissa_bits, "n"))


def _rounded(value: sp.Rational, mantissa_bits: int) -> sp.Rational:
    """:func:`nearest_binary` as an exact rational."""
    if value == 0:
        return sp.Integer(0)
    mantissa, exponent = nearest_binary(abs(value), mantissa_bits).man_exp  # of the magnitude
    return sp.sign(value) * sp.Integer(mantissa) * sp.Integer(2) ** exponent
