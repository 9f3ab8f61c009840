"""The angle φ(s) and the quaternion scalar e₀ = cos(φ/2) (eq 74) in the plan: the rescaling
scale, the bracket and the Newton iteration on p(φ) = s where no closed inverse serves."""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import replace
from functools import lru_cache
from typing import NamedTuple

import mpmath
import numpy as np
import sympy as sp

from symrot.core.derivation import Derivation, derive_expression
from symrot.core.functions import RealCbrt
from symrot.core.parsing import PHI
from symrot.core.series import coefficient_list, taylor_series
from symrot.plan.algebraic import X as X  # re-exported: the symbol of the coefficients' variable x = |p|²
from symrot.plan.algebraic import (
    algebraic_in_x,
    closed_with_complement,
    with_complement,
)
from symrot.plan.branches import (
    plan_branch,
)
from symrot.plan.evaluation import (
    log_grid,
    model_function,
)
from symrot.plan.ir import (
    Algebraic,
    Branch,
    Coefficient,
    EvaluationPlan,
    NewtonAngle,
    QuaternionScale,
)
from symrot.plan.measurement import (
    angle_grid,
)
from symrot.plan.newton_start import (
    START_TOLERANCE,
    edge_exponent,
    far_start,
    fold_top,
    measured_iterations,
    newton_lanes,
)
from symrot.plan.newton_start import FarStart as FarStart
from symrot.plan.quaternion import (
    quaternion_scalar,
    quaternion_scalar_series,
    scale_expression,
    scale_in_e0,
    scale_series,
)
from symrot.plan.targets import (
    MAX_TERMS,
    NEWTON_ITERATIONS,
    START_TERMS,
)


def _p_max_squared(p: sp.Expr, phi_max: sp.Expr, p_max: float, at_jump: bool) -> sp.Float | None:
    """p(φ_max)² at 50 digits, or None when p is unbounded. Where the range ends at a jump of p
    (``at_jump``: 2 atan(tan(φ/2)) at π, see :mod:`symrot.core.singularities`) the value there is not the
    limit from the left, so p_max (that limit, from the validity analysis) is squared instead."""
    if not np.isfinite(p_max):
        return None
    exact = None if at_jump else sp.N(p.subs(PHI, phi_max) ** 2, 50)
    return exact if exact is not None and exact.is_Float and exact.is_finite else sp.Float(p_max * p_max, 50)


def _use_complement(coefficient: Coefficient, inverse: sp.Expr, complement: sp.Rational) -> Coefficient:
    """The same coefficient with k² − x written as the accurately computed D (fold of the sine family)."""
    if isinstance(coefficient, Algebraic):
        return Algebraic(with_complement(coefficient.expression, complement))
    if isinstance(coefficient, Branch):
        return replace(coefficient, closed=closed_with_complement(coefficient.closed, inverse, complement))
    return coefficient


def _quaternion_scalar(derivation: Derivation, inverse: sp.Expr | None, complement: sp.Rational | None,
                       phi_max: float, p_max: float, dtype: type) -> Coefficient:
    """e₀ = cos(φ/2) as a coefficient of x (eq 74)."""
    if inverse is not None:
        algebraic = algebraic_in_x(quaternion_scalar(), inverse, p_max)
        if algebraic is not None:
            return Algebraic(algebraic)
    series = _quaternion_scalar_series(derivation.p)
    return plan_branch(quaternion_scalar(), series, derivation.p ** 2, phi_max, dtype, derivation.p, inverse,
                       complement)


def _quaternion_scale(p: sp.Expr, phi_top: float, dtype: type) -> QuaternionScale:
    """σ = p(φ)/sin(φ/2) on 0 ≤ φ ≤ min(φ_max, π): trig-free in e₀ if possible, else a Branch in φ²."""
    algebraic, closed = _scale_forms(p)
    if algebraic is not None:
        return QuaternionScale(algebraic, None)
    return QuaternionScale(None, plan_branch(closed, _scale_series(p), PHI ** 2, phi_top, dtype))


@lru_cache(maxsize=64)
def _quaternion_scalar_series(p: sp.Expr) -> list[sp.Expr]:
    """e₀'s exact series in x (both precisions read it)."""
    return quaternion_scalar_series(derive_expression(p), MAX_TERMS)


@lru_cache(maxsize=64)
def _scale_series(p: sp.Expr) -> list[sp.Expr]:
    """σ's exact series in φ² (both precisions read it)."""
    return scale_series(p, MAX_TERMS)


@lru_cache(maxsize=64)
def _scale_forms(p: sp.Expr) -> tuple[sp.Expr | None, sp.Expr]:
    """(σ algebraic in e₀ or None, σ simplified in φ): the symbolic work of
    :func:`_quaternion_scale`, the same for both precisions."""
    algebraic = scale_in_e0(p)
    if algebraic is not None:
        return algebraic, scale_expression(p)
    return None, (sp.simplify(scale_expression(p)) if not p.has(RealCbrt) else scale_expression(p))


def _bracket_top(exact: sp.Expr, phi_max: float, dtype: type) -> float:
    """The largest ``dtype`` value not above φ_max (``phi_max`` if φ_max is not finite): the top of
    the Newton bracket and of the clipped start. Rounded to nearest it can lie past a pole or a
    fold, where p is negative or decreasing: float32(3π/4) is beyond the pole of tan(2φ/3), and
    the iteration stayed there, 2·10⁻⁶ off, for 64 steps."""
    if not exact.is_finite:
        return float(dtype(phi_max))
    with mpmath.workdps(40):
        edge = mpmath.mpf(sp.N(exact, 40))
        top = dtype(float(edge))
        while mpmath.mpf(float(top)) > edge:
            top = np.nextafter(top, dtype(0))
    return float(top)


class NewtonForms(NamedTuple):
    """The symbolic part of :func:`_newton_angle`, the same for both precisions."""

    leading: sp.Expr
    """g(0) = κ (eq 12), the first term of g's series."""
    tail: sp.Expr
    """g − g(0), g = p/φ simplified."""
    tail_series: list[sp.Expr]
    """The exact series of the tail in φ² (its first term 0)."""
    slope: sp.Expr
    slope_series: list[sp.Expr]
    """p′ simplified and its exact series in φ²."""
    start: tuple[sp.Expr, ...]
    """The start's series φ(p), odd powers of p."""


@lru_cache(maxsize=64)
def _newton_forms(p: sp.Expr) -> NewtonForms:
    """:class:`NewtonForms` of p: Newton's ratio g = p/φ split into g(0) and its tail, its slope p′
    and the start φ(p)."""
    order = 2 * MAX_TERMS
    derivation = derive_expression(p)
    ratio_series = coefficient_list(taylor_series(p / PHI, order), 0, order)[0::2]
    slope_series = derivation.taylor_in_phi("p_prime", order)[0::2]
    reverted = derivation.phi_of_p(2 * START_TERMS)
    leading = ratio_series[0]
    slope_form = derivation.simplified_coefficients()["p_prime"]
    return NewtonForms(leading, sp.simplify(p / PHI) - leading, [sp.Integer(0), *ratio_series[1:]],
                       slope_form, slope_series, tuple(reverted[1::2][:START_TERMS]))


def _newton_angle(derivation: Derivation, phi_max: float, p_max: float, dtype: type,
                  bracket_top: float) -> NewtonAngle:
    p = derivation.p
    forms = _newton_forms(p)
    leading, start = forms.leading, forms.start
    ratio = plan_branch(forms.tail, forms.tail_series, PHI ** 2, phi_max, dtype, whole=abs(float(leading)))
    slope = plan_branch(forms.slope, forms.slope_series, PHI ** 2, phi_max, dtype)
    far = _far_start(p, p_max, phi_max, start)
    top = (fold_top(p, derivation.scalars["p_prime"], p_max, phi_max, dtype)
           if far.kind == "fold" and math.isfinite(p_max) else math.inf)
    grid = np.unique(np.concatenate([angle_grid(phi_max), phi_max * (1 - log_grid(1e-6, 1e-9, 4))]))
    printed = (_branch_model(ratio, dtype), _branch_model(slope, dtype))
    reciprocal = far.kind == "ratio"  # p unbounded: a pole at φ_max
    below = float(ratio.threshold)  # NewtonAngle.split_below
    lanes = newton_lanes(p, derivation.scalars["p_prime"], grid, phi_max, dtype, printed[0], float(leading),
                         below)
    count = measured_iterations(lanes, start, far, printed, reciprocal, bracket_top, leading=float(leading),
                                fold_top=top, series_below=below)
    edge = _edge_exponent(p, far, phi_max)
    if edge is not None:
        edge_count = measured_iterations(lanes, start, far, printed, reciprocal, bracket_top, edge,
                                         float(leading), top, below)
        # p′ = ∞ at the edge (k < 1): steps in φ overshoot past it and bisect (43 steps for asin(φ)
        # from a start at the edge, 6 in w), wherever the checks fall
        if edge < 1 or (-edge_count.unconverged, edge_count.steps) < (-count.unconverged, count.steps):
            count = edge_count
        else:
            edge = None
    iterations = max(newton_iterations(far.measured, float(np.finfo(dtype).eps)), count.steps)
    return NewtonAngle(start, ratio, slope, iterations, bracket_top, far, reciprocal, count.unconverged,
                       leading, edge, top)


def _branch_model(branch: Branch, dtype: type) -> Callable[[np.ndarray], np.ndarray]:
    """A Branch in t = φ² as the backends evaluate it (Horner below the switch, the closed form
    above, with the ideal libm), as a function of φ."""
    closed = model_function(branch.closed, [PHI])
    coefficients = [dtype(float(c)) for c in branch.horner]

    def evaluate(phi: np.ndarray) -> np.ndarray:
        t = (phi * phi).astype(dtype)
        series = np.zeros_like(t)
        for c in coefficients[::-1]:
            series = (c + t * series).astype(dtype)
        with np.errstate(all="ignore"):
            return np.where(t < branch.threshold, series, np.asarray(closed(phi), dtype=dtype)).astype(dtype)

    return evaluate


def newton_iterations(start_error: float, epsilon: float) -> int:
    """Steps of the safeguarded Newton iteration for a far start within ``start_error`` (relative,
    as measured by :func:`symrot.plan.newton_start.far_start`): :data:`NEWTON_ITERATIONS` for a start
    within START_TOLERANCE, plus the quadratic steps that a worse start needs to reach ``epsilon``
    (e₀ → e₀² → …). sinh(φ)cosh(φ), whose far start in s/p_max is only within 2·10⁻³, came out
    10⁻⁴ off at φ = 0.1 after 6 steps and within 1.3 ulp after 8."""
    error = min(max(start_error, START_TOLERANCE), 0.5)
    needed = math.ceil(math.log2(math.log(epsilon) / math.log(error)) - 1e-9)
    floor = math.ceil(math.log2(math.log(epsilon) / math.log(START_TOLERANCE)) - 1e-9)
    return NEWTON_ITERATIONS + max(0, needed - floor)


_far_start = lru_cache(maxsize=64)(far_start)
"""The far start does not depend on the precision: both plans share one fit."""

_edge_exponent = lru_cache(maxsize=64)(edge_exponent)
"""Both precisions' plans share one estimate of the edge exponent."""


_GIVEN_PLANS: dict[tuple[sp.Expr, str], EvaluationPlan] = {}
"""Plans handed to :func:`remember_plan` (e.g. read back from disk by the CLI), by (p, name)."""
