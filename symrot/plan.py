"""Evaluation plans: how each scalar coefficient c(x), x = |p|², is evaluated safely.

Generated code takes the parameter vector p, never φ. Every quantity is a scalar coefficient of
x = |p|²: ν, ε, μ, p′, det H (eqs 17–24) and the coefficients on I, (p×), (p×)² of R (16), H (20),
H⁻¹ (26), G (81) and K (83) (names as in ``Derivation.coefficient_expressions``), and φ itself.
The plan decides this once per coefficient and per precision; backends only print it.

IR (all frozen dataclasses, SymPy expressions in the symbols ``PHI`` and ``S``):

``EvaluationPlan``
    ``name``, ``p`` (generating function), ``p_max`` (float, ``inf`` when unbounded: outside
    |p| < p_max every output is NaN), ``phi_max`` (float), ``precisions``: {"float64": …,
    "float32": …} → ``PrecisionPlan``.
``PrecisionPlan``
    ``dtype``, ``epsilon``, ``angle`` (``ClosedAngle`` or ``NewtonAngle``), ``coefficients``:
    {name → ``Constant`` or ``Branch``}.
``Algebraic(expression)``
    the coefficient as a rational function of the symbol ``X`` = x with no branch (e.g. 1 + x/4 for
    H⁻¹₀ of 2 tan(φ/2)); found by substituting the closed inverse φ(s) and checking x = 0 is regular.
``Constant(value)``
    identically constant coefficient (e.g. H⁻¹₂ = 1/4 for 2 sin(φ/2)): emit the number.
``Branch(threshold, horner, closed, safe_phi)``
    with ``t`` the branch variable (x = |p|² for coefficients, φ² inside ``NewtonAngle``):
    if t < threshold evaluate the polynomial Σ horner[j] t^j (exact rationals, Horner order);
    else evaluate ``closed`` (an expression in ``PHI``).  Both branches must be computed on
    guarded inputs: t replaced by 0 where t ≥ threshold, φ replaced by ``safe_phi`` where
    t < threshold, so neither branch ever divides by zero.  Common subexpressions may only be
    shared *inside* one branch.
``ClosedAngle(expression)``
    φ = expression(S), S = |p| = √x, the closed-form inverse of p(φ) (e.g. 4 atan(S/4)).
``NewtonAngle(start, ratio, slope, iterations, phi_max)``
    φ from s = |p| by Newton on r(φ) = φ·g(φ²) − s, started from the odd reverted series
    φ ≈ Σ start[k] s^(2k+1), where ``ratio`` = g (Branch in t = φ² for p(φ)/φ, Taylor-safe) and
    ``slope`` (Branch in t = φ² for p′(φ)).  Safeguard: keep a bracket [lo, hi] ⊂ [0, phi_max],
    shrink it by the sign of r and take the bisection point when a step leaves it.

Thresholds and degrees come from an error model per precision: the closed form's error is
measured against 30-digit mpmath on a log grid of φ (cancellation in the closed form grows as
x → 0); the Horner tail is bounded by its next two terms at the threshold.  The switch is the
grid point minimising the worse of the two, and the degree is the smallest meeting the target.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache

import mpmath
import numpy as np
import sympy as sp

from .core import Derivation, derive_expression
from .functions import RealCbrt, mpmath_namespace
from .parsing import PHI
from .series import coefficient_list, taylor_series
from .timeouts import bounded

S = sp.Symbol("s", nonnegative=True)
X = sp.Symbol("x", nonnegative=True)
MAX_TERMS = 24
GRID_POINTS = 56
PRECISIONS: dict[str, type[np.floating]] = {"float64": np.float64, "float32": np.float32}
CLOSED_TOLERANCE_ULP = 1.5
NEWTON_ITERATIONS = 6
START_TERMS = 8


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


@dataclass(frozen=True)
class Algebraic:
    expression: sp.Expr


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


Coefficient = Constant | Algebraic | Branch


@dataclass(frozen=True)
class PrecisionPlan:
    dtype: str
    epsilon: float
    angle: ClosedAngle | NewtonAngle
    coefficients: dict[str, Coefficient]


@dataclass(frozen=True)
class EvaluationPlan:
    name: str
    p: sp.Expr
    p_max: float
    phi_max: float
    precisions: dict[str, PrecisionPlan]


def well_conditioned(expr: sp.Expr) -> sp.Expr:
    """Replace cos(a) by 1 − 2 sin²(a/2): the half-angle form keeps 1 − cos φ accurate."""
    return expr.replace(lambda e: isinstance(e, sp.cos), lambda e: 1 - 2 * sp.sin(e.args[0] / 2) ** 2)


def closed_inverse(p: sp.Expr, kappa: sp.Expr) -> sp.Expr | None:
    """φ(s) with p(φ) = s, when SymPy finds a closed form that starts as s/κ."""
    if p == PHI:
        return S
    if p.has(RealCbrt):
        return None
    solutions: list[sp.Expr] = bounded(10, [], sp.solve, sp.Eq(p, S), PHI)
    for candidate in solutions:
        if candidate.has(sp.I) or candidate.free_symbols != {S}:
            continue
        probe = sp.Rational(1, 1000)
        value = candidate.subs(S, probe).evalf(30)
        if value.is_real and abs(value - probe / kappa) < sp.Rational(1, 10**6):
            return sp.simplify(candidate) if len(str(candidate)) < 80 else candidate
    return None


def algebraic_in_x(closed: sp.Expr, inverse: sp.Expr) -> sp.Expr | None:
    """c(φ(√x)) as a rational function of x when trigonometry disappears and x = 0 is regular."""
    substituted = closed.subs(PHI, inverse)
    reduced = bounded(4, None, lambda e: sp.factor(sp.simplify(sp.expand_trig(e))), substituted)
    if reduced is None:
        return None
    in_x = reduced.subs(S, sp.sqrt(X))
    in_x = bounded(2, in_x, sp.factor, in_x)
    if any(isinstance(a, (sp.Function, sp.Pow)) and not (isinstance(a, sp.Pow) and a.exp.is_Rational)
           for a in sp.preorder_traversal(in_x)) or in_x.free_symbols - {X}:
        return None
    at_zero = in_x.subs(X, 0)
    if not at_zero.is_finite:
        return None
    return in_x


def _mp_function(expr: sp.Expr) -> object:
    return sp.lambdify(PHI, expr, modules=[mpmath_namespace(), "mpmath"])


def _np_function(expr: sp.Expr) -> object:
    from .backends.numpy_backend import numpy_function

    return numpy_function(expr)


def _angle_grid(phi_max: float) -> np.ndarray:
    top = min(phi_max, 4 * np.pi) * (1 - 1e-6)
    return np.geomspace(1e-7, top, GRID_POINTS)


def plan_branch(closed: sp.Expr, series: list[sp.Expr], variable_of_phi: sp.Expr, phi_max: float,
                dtype: type) -> Branch:
    """Choose the switch t₀ and Horner degree for one coefficient in one precision."""
    candidates = ([well_conditioned(closed)] if closed.has(sp.cos) else []) + [closed]  # half-angle first
    branches = [_branch_for(form, series, variable_of_phi, phi_max, dtype) for form in candidates]
    return min(branches, key=lambda b: (b.measured_ulp > CLOSED_TOLERANCE_ULP, len(b.horner), b.measured_ulp))


def _branch_for(closed: sp.Expr, series: list[sp.Expr], variable_of_phi: sp.Expr, phi_max: float,
                dtype: type) -> Branch:
    epsilon = float(np.finfo(dtype).eps)
    mp_closed, np_closed = _mp_function(closed), _np_function(closed)
    to_t = sp.lambdify(PHI, variable_of_phi, modules=[mpmath_namespace(), "mpmath"])
    angles = _angle_grid(phi_max)
    scale0 = abs(float(series[0])) or 1.0
    closed_error = np.zeros(len(angles))
    t_values = np.zeros(len(angles))
    with mpmath.workdps(30):
        for k, angle in enumerate(angles):
            a = mpmath.mpf(float(dtype(angle)))
            reference = float(mp_closed(a))  # type: ignore[operator]
            t_values[k] = float(to_t(a))
            with np.errstate(all="ignore"):
                value = float(np_closed(np.asarray(a, dtype=dtype)))  # type: ignore[operator]
            scale = max(abs(reference), scale0)
            closed_error[k] = abs(value - reference) / (scale * epsilon) if np.isfinite(value) else np.inf
    floats = [abs(float(c)) for c in series]

    def tail(t: float, n: int) -> float:
        rest = floats[n:n + 2]
        return sum(c * t ** (n + j) for j, c in enumerate(rest)) / (scale0 * epsilon)

    best, best_k = np.inf, len(angles) - 1
    near_zero = int(np.searchsorted(angles, 0.5 * min(phi_max, 4 * np.pi)))
    for k in range(near_zero):
        worst_closed = float(np.max(closed_error[k:near_zero]))
        worst = max(worst_closed, tail(t_values[k], MAX_TERMS - 2))
        if worst <= CLOSED_TOLERANCE_ULP and best <= CLOSED_TOLERANCE_ULP:
            # both acceptable: prefer the smaller switch (fewer terms)
            if tail(t_values[k], MAX_TERMS - 2) <= tail(t_values[best_k], MAX_TERMS - 2):
                best, best_k = worst, k
        elif worst < best:
            best, best_k = worst, k
    threshold = float(t_values[best_k])
    target = max(0.25, tail(threshold, MAX_TERMS - 2))
    degree = next((n for n in range(1, MAX_TERMS - 1) if tail(threshold, n) <= target), MAX_TERMS - 2)
    return Branch(threshold, tuple(series[:degree]), closed, float(angles[best_k]), best)


@lru_cache(maxsize=64)
def _plan_for(p: sp.Expr, name: str) -> EvaluationPlan:
    from .singularities import validity

    derivation = derive_expression(p)
    limits = validity(derivation)
    phi_max = float(limits.phi_max_float) if np.isfinite(limits.phi_max_float) else 4 * float(np.pi)
    inverse = closed_inverse(p, derivation.kappa)
    x_of_phi = p ** 2
    precisions = {}
    for label, dtype in PRECISIONS.items():
        coefficients: dict[str, Coefficient] = {}
        for coefficient, closed in derivation.coefficient_expressions().items():
            constant = derivation.constant_value(coefficient)
            if constant is not None:
                coefficients[coefficient] = Constant(constant)
                continue
            if inverse is not None:
                algebraic = algebraic_in_x(closed, inverse)
                if algebraic is not None:
                    coefficients[coefficient] = Algebraic(algebraic)
                    continue
            series = derivation.series_in_x(coefficient, MAX_TERMS)
            simplest_form = derivation.simplified_coefficients()[coefficient]
            coefficients[coefficient] = plan_branch(simplest_form, series, x_of_phi, phi_max, dtype)
        angle = ClosedAngle(inverse) if inverse is not None else _newton_angle(derivation, phi_max, dtype)
        precisions[label] = PrecisionPlan(label, float(np.finfo(dtype).eps), angle, coefficients)
    return EvaluationPlan(name, p, float(limits.p_max_float), phi_max, precisions)


def _newton_angle(derivation: Derivation, phi_max: float, dtype: type) -> NewtonAngle:
    order = 2 * MAX_TERMS
    p = derivation.p
    ratio_series = coefficient_list(taylor_series(p / PHI, order), 0, order)[0::2]
    slope_series = derivation.taylor_in_phi("p_prime", order)[0::2]
    ratio = plan_branch(sp.simplify(p / PHI), ratio_series, PHI ** 2, phi_max, dtype)
    slope = plan_branch(derivation.simplified_coefficients()["p_prime"], slope_series, PHI ** 2,
                        phi_max, dtype)
    reverted = derivation.phi_of_p(2 * START_TERMS)
    start = tuple(reverted[1::2][:START_TERMS])
    return NewtonAngle(start, ratio, slope, NEWTON_ITERATIONS, phi_max)


def evaluation_plan(derivation: Derivation, name: str) -> EvaluationPlan:
    """The plan of every coefficient of ``derivation`` in float64 and float32."""
    return _plan_for(derivation.p, name)
