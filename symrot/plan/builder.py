"""Evaluation plans: how each scalar coefficient c(x), x = |p|², is evaluated safely.

Generated code takes the parameter vector p, never φ. Every quantity is a scalar coefficient of
x = |p|²: ν, ε, μ, p′, det H (eqs 17–24), the coefficients on I, (p×), (p×)² of R (16), H (20),
H⁻¹ (26), G (81) and K (83) (names as in ``Derivation.coefficient_expressions``), the slopes dc/dx
of R's, H's and H⁻¹'s coefficients (``R_1_x`` …, :mod:`symrot.core.derivatives`), e₀ = cos(φ/2)
(``e_0``, eq 74) and φ itself. The plan decides this once per coefficient and per precision;
backends only print it.

The plan's IR (``EvaluationPlan``, ``PrecisionPlan``, ``Constant``, ``Algebraic``, ``Branch``,
``ClosedAngle``, ``NewtonAngle``) is described and defined in :mod:`symrot.plan.ir`; this module
builds it from the candidate forms (:mod:`symrot.plan.forms`), the branches
(:mod:`symrot.plan.branches`) and the angle (:mod:`symrot.plan.angles`), under the targets of
:mod:`symrot.plan.targets`.

Thresholds and degrees come from an error model per precision: the closed form's error is
measured against 60-digit mpmath on a log grid of φ plus points approaching φ_max, each point
taking the worst of a few nearby arguments (a cancellation must not hide behind one lucky
rounding). The inputs are those of the backends: x = |p|² rounded, s = √x, and the angle φ̂
computed from s, rounded; the reference is the exact coefficient of the rounded x, so a form is
charged the rounding of φ̂ but not the input's own (:func:`measured_inputs`). The Horner tail is
bounded by its next two terms at the threshold.  The switch is
the grid point minimising the worse of the two, moved up for speed as far as a polynomial of
``CHEAP_TERMS`` terms still truncates below a quarter ulp, and the degree is the smallest meeting
the target.  Among equivalent closed forms (as derived, half-angle forms of cos φ, everything in
sin(φ/2), cos(φ/2), p written as s and p² as x, algebraic parts such as p′ written through the
closed inverse φ(s)) the plan takes the one whose worst error is smallest, then the shortest
polynomial at the smallest switch the accuracy allows, then a form in φ alone (one in s or x is
taken where it is measurably more accurate), then the fewest distinct trigonometric arguments
(sin a and cos a: one sincos).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from contextlib import suppress
from dataclasses import replace
from functools import lru_cache, partial
from typing import Any, NamedTuple

import mpmath
import numpy as np
import sympy as sp

from symrot.core.derivation import Derivation, derive_expression
from symrot.core.errors import SymrotError, SymrotTimeout
from symrot.core.forked import first_here_others_in_children
from symrot.core.parsing import PHI
from symrot.core.two_processes import computed_in_two_processes, simplify_tensors
from symrot.plan.algebraic import (
    REDUCTION_OPS,
    D,
    S,
    algebraic_in_x,
    angle_with_complement,
    closed_with_base_angle,
    fold_complement,
    reduction_size,
    with_bounded_powers,
    with_complement,
)
from symrot.plan.algebraic import X as X  # re-exported: the symbol of the coefficients' variable x = |p|²
from symrot.plan.angles import (
    _GIVEN_PLANS,
    _bracket_top,
    _newton_angle,
    _newton_forms,
    _p_max_squared,
    _quaternion_scalar,
    _quaternion_scalar_series,
    _quaternion_scale,
    _scale_forms,
    _use_complement,
)
from symrot.plan.branches import (
    _CANDIDATES,
    BRANCH_VARIABLES,
    OWN_SCALE,
    FormsKey,
    UnplannableCoefficient,
    _candidate_forms,
    candidate_forms,
    plan_branch,
    tensor_part,
)
from symrot.plan.domain import FIRST_POWER, domain_limit
from symrot.plan.evaluation import (
    ModelKey,
    model_key,
    model_source,
    remember_sources,
)
from symrot.plan.forms import (
    angle_forms,
    closed_angle_error,
    closed_inverse,
)
from symrot.plan.ir import (
    Algebraic,
    Branch,
    ClosedAngle,
    Coefficient,
    Constant,
    EvaluationPlan,
    NewtonAngle,
    PrecisionPlan,
)
from symrot.plan.newton_start import FarStart as FarStart
from symrot.plan.quaternion import (
    QUATERNION_SCALAR,
    e0_min,
    quaternion_scalar,
)
from symrot.plan.targets import (
    ALGEBRAIC_WORK,
    ANGLE_TOLERANCE_ULP,
    MAX_TERMS,
    PRECISIONS,
    UNREAD_SCALARS,
)


class _SharedWork(NamedTuple):
    """What the plans of both precisions read: the derivation, its range and closed inverse, and
    the algebraic forms found once for both (:func:`_plan_for`)."""

    derivation: Derivation
    limits: Any
    phi_max: float
    p_max: float
    inverse: sp.Expr | None
    complement: sp.Rational | None
    unbounded: bool
    det_h_own_scale: bool
    algebraic_forms: dict[str, sp.Expr | None]


@lru_cache(maxsize=64)
def _plan_for(p: sp.Expr, name: str) -> EvaluationPlan:
    """The plan of both precisions. The symbolic work they share (the algebraic search, the
    simplified forms and series) is done first; then float32 is planned in a forked child while
    this process plans float64 (:mod:`symrot.core.forked`), both from the same state."""
    from symrot.core.singularities import validity

    derivation = derive_expression(p)
    simplify_tensors(derivation, beside=lambda: validity(derivation))
    _check_scale(derivation)
    limits = validity(derivation)
    phi_max = float(limits.phi_max_float) if np.isfinite(limits.phi_max_float) else 4 * float(np.pi)
    inverse = closed_inverse(p, derivation.kappa)
    p_max = float(limits.p_max_float)
    unbounded = not math.isfinite(p_max)  # p → ∞ at φ_max
    # det H = μ ν² → 0 at φ_max because p′ → ∞ there (a logarithmic pole such as asinh(tan φ), where
    # the analysis finds p′ → ∞ and a finite |p| 10⁻¹² from the edge; an arcsine edge): judged
    # relative to itself, as where p is unbounded. Not where ν → 0 makes it vanish (2π): there no form
    # is better, and the relative measure only lengthened the polynomials (rotation vector 7 → 10 terms)
    at_edge = {(s.quantity, s.limit) for s in limits.singularities
               if abs(s.phi_float - phi_max) <= 1e-12 * phi_max}
    det_h_own_scale = unbounded or {("det_H", "0"), ("p_prime", "oo")} <= at_edge
    complement = fold_complement(inverse, p_max)
    algebraic_forms = _algebraic_forms(derivation, inverse, p_max)
    shared = _SharedWork(derivation, limits, phi_max, p_max, inverse, complement, unbounded, det_h_own_scale,
                         algebraic_forms)
    _prepare_shared_work(shared)
    plans = first_here_others_in_children([partial(_precision_plan, shared, label, dtype)
                                           for label, dtype in PRECISIONS.items()])
    precisions = dict(zip(PRECISIONS, plans, strict=True))
    return EvaluationPlan(name, p, p_max, phi_max, precisions, e0_min(limits.phi_max), complement,
                          _p_max_squared(p, limits.phi_max, p_max, ("p", "jump") in at_edge))


def _searched(derivation: Derivation) -> list[str]:
    """The planned coefficients whose value is neither a constant nor a slope, in plan order: those
    an algebraic form is searched for (an across-axis part only when c₀ is not constant)."""
    across = {t.across_name: name for name, t in derivation.tensors.items()}
    names = []
    for coefficient in derivation.planned_expressions():
        tensor = across.get(coefficient)
        if tensor is not None and derivation.constant_value(tensor + "_0") is not None:
            continue  # c_0 exact: the backends compute t = c_0 - c_2 x, which loses nothing
        if derivation.constant_value(coefficient) is None and coefficient not in derivation.slopes:
            names.append(coefficient)
    return names


def _algebraic_forms(derivation: Derivation, inverse: sp.Expr | None,
                     p_max: float) -> dict[str, sp.Expr | None]:
    """Each searched coefficient's form algebraic in x (and d), or None: with a closed inverse, the
    simplest form and then the raw one are tried (:func:`symrot.plan.algebraic.algebraic_in_x`). The search
    of one plan is capped by the size of what it simplifies (a few seconds for every named
    parameterization; expressions whose forms never simplify would otherwise spend minutes): past
    ALGEBRAIC_WORK, coefficients get branches. Both precisions use the result.

    The simplest forms that the cap admits if every earlier one succeeds are reduced first, half of
    them in a forked child (:func:`symrot.core.two_processes.computed_in_two_processes`); the search then
    runs in order on those values, reducing here what it needs beyond them (raw forms)."""
    forms: dict[str, sp.Expr | None] = {}
    if inverse is None:
        return forms
    planned = derivation.planned_expressions()
    searched = _searched(derivation)
    ahead: list[sp.Expr] = []
    sizes: list[int] = []
    work = 0
    for coefficient in searched:
        form = derivation.simplified_form(coefficient)
        size = reduction_size(form, inverse)
        if size <= REDUCTION_OPS and work + size <= ALGEBRAIC_WORK and form not in ahead:
            work += size
            ahead.append(form)
            sizes.append(size)
    reduced = computed_in_two_processes(lambda form: algebraic_in_x(form, inverse, p_max), ahead, sizes)
    work = 0
    for coefficient in searched:
        closed = planned[coefficient]
        found = None
        for form in dict.fromkeys((derivation.simplified_form(coefficient), closed)):
            size = reduction_size(form, inverse)
            if found is not None or size > REDUCTION_OPS or work + size > ALGEBRAIC_WORK:
                continue
            work += size
            found = reduced[form] if form in reduced else algebraic_in_x(form, inverse, p_max)
        forms[coefficient] = found
    return forms


def _prepare_shared_work(shared: _SharedWork) -> None:
    """Compute once, before the precisions part, the symbolic work that both plans read: the
    simplified forms and series of the coefficients without an algebraic form and of their slopes,
    the quaternion's scalar series, scale and algebraic form, Newton's forms without a closed
    inverse (a step that fails is left to the plan, which meets the same failure in its place), and
    the candidate forms of every branch (:func:`candidate_forms`), half of them in a forked child."""
    derivation, algebraic_forms, inverse = shared.derivation, shared.algebraic_forms, shared.inverse
    for coefficient in _searched(derivation):
        if algebraic_forms.get(coefficient) is None:
            _prepare(derivation, coefficient)
    for slope, (parent, _) in derivation.slopes.items():
        if derivation.constant_value(slope) is None and algebraic_forms.get(parent) is None:
            _prepare(derivation, slope)
    warm: list[Callable[[], object]] = [lambda: _scale_forms(derivation.p),
                                        lambda: _quaternion_scalar_series(derivation.p)]
    if inverse is None:
        warm.append(lambda: _newton_forms(derivation.p))
    if inverse is not None:
        warm.append(lambda: algebraic_in_x(quaternion_scalar(), inverse, shared.p_max))
    for step in warm:
        with suppress(SymrotError):
            step()
    keys = _branch_keys(shared)
    computed = computed_in_two_processes(_forms_or_failure, keys, [int(sp.count_ops(k[0])) for k in keys])
    for key, result in computed.items():
        if result is not None:
            _CANDIDATES[key] = result[0]
            remember_sources(result[1])


def _branch_keys(shared: _SharedWork) -> list[FormsKey]:
    """The :func:`candidate_forms` keys of the branches both precisions plan: the coefficients
    without an algebraic form, the slopes of such parents, and e₀."""
    derivation, p = shared.derivation, shared.derivation.p
    names = [n for n in _searched(derivation) if shared.algebraic_forms.get(n) is None]
    names += [slope for slope, (parent, _) in derivation.slopes.items()
              if derivation.constant_value(slope) is None and shared.algebraic_forms.get(parent) is None]
    closed: list[sp.Expr] = []
    for name in names:
        with suppress(SymrotError):
            closed.append(derivation.simplified_form(name))
            if name not in derivation.slopes and not shared.unbounded:  # see definition_forms
                closed.append(derivation.expression(name))
    closed.append(quaternion_scalar())
    return list(dict.fromkeys((form, p, shared.phi_max, shared.inverse, shared.complement)
                              for form in closed))


def _forms_or_failure(key: FormsKey) -> tuple[tuple[tuple[sp.Expr, ...], tuple[sp.Expr, ...]],
                                              dict[ModelKey, str]] | None:
    """:func:`_candidate_forms` and the sources of their models as :func:`_branch_for` measures them
    (printed here, where the forms are computed, half in a forked child, instead of once in each
    precision's process), or None where a step fails in any way: the plan then computes them again in
    its place and meets the failure there, as it did before they were computed ahead."""
    try:
        forms = _candidate_forms(*key)
    except Exception:  # re-raised where the plan needs the forms
        return None
    sources = {}
    for form in forms[1]:
        printed = model_key(form, BRANCH_VARIABLES)
        with suppress(ValueError):  # no model for a function: _branch_for meets it in its place
            sources[printed] = model_source(printed)
    return forms, sources


def _prepare(derivation: Derivation, coefficient: str) -> None:
    with suppress(SymrotError):
        derivation.series_in_x(coefficient, MAX_TERMS)
        derivation.simplified_form(coefficient)


def _precision_plan(shared: _SharedWork, label: str, dtype: type[np.floating]) -> PrecisionPlan:
    """The plan of every coefficient in one precision (see :func:`plan_branch`)."""
    derivation, phi_max, p_max, inverse = shared.derivation, shared.phi_max, shared.p_max, shared.inverse
    complement, unbounded, p = shared.complement, shared.unbounded, derivation.p
    x_of_phi = p ** 2
    across = {t.across_name: name for name, t in derivation.tensors.items()}
    coefficients: dict[str, Coefficient] = {}
    slopes_unrepresentable = False
    for coefficient in derivation.planned_expressions():
        tensor = across.get(coefficient)
        if tensor is not None and isinstance(coefficients[tensor + "_0"], Constant):
            continue  # c_0 exact: the backends compute t = c_0 - c_2 x, which loses nothing
        constant = derivation.constant_value(coefficient)
        if constant is not None:
            coefficients[coefficient] = Constant(constant)
            continue
        if coefficient in derivation.slopes:  # after every parent: its parent's plan is known
            try:
                coefficients[coefficient] = _plan_slope(derivation, coefficient, coefficients, phi_max,
                                                        dtype, inverse, complement, shared.det_h_own_scale)
            except UnplannableCoefficient:  # e.g. 1e-8*phi in float32: dc/dx ~ 1/kappa^4 overflows
                coefficients[coefficient] = Constant(sp.Integer(0))  # never used: see slope_limit
                slopes_unrepresentable = True
            continue
        algebraic = shared.algebraic_forms.get(coefficient)
        if algebraic is not None:
            coefficients[coefficient] = Algebraic(algebraic)
            continue
        series = derivation.series_in_x(coefficient, MAX_TERMS)
        simplest_form = derivation.simplified_form(coefficient)
        extra = difference_forms(coefficients, tensor, complement) if tensor is not None else ()
        definition = () if unbounded else definition_forms(derivation.expression(coefficient), simplest_form,
                                                           p, phi_max, inverse, complement)
        coefficients[coefficient] = plan_branch(simplest_form, series, x_of_phi, phi_max, dtype, p,
                                                inverse, complement,
                                                tensor_part(derivation, coefficient, shared.det_h_own_scale),
                                                extra, definition)
    coefficients[QUATERNION_SCALAR] = _quaternion_scalar(derivation, inverse, complement, phi_max, p_max,
                                                         dtype)
    scale = _quaternion_scale(derivation.p, min(phi_max, float(np.pi)), dtype)
    closed_angle = None if inverse is None or complement is not None else next(
        (form for form in angle_forms(inverse)
         if closed_angle_error(form, p, phi_max, dtype) <= ANGLE_TOLERANCE_ULP), None)
    angle = (ClosedAngle(closed_angle) if closed_angle is not None
             else _newton_angle(derivation, phi_max, p_max, dtype,
                                _bracket_top(shared.limits.phi_max, phi_max, dtype)))
    if complement is not None:
        assert inverse is not None
        coefficients = {n: _use_complement(c, inverse, complement) for n, c in coefficients.items()}
        angle = ClosedAngle(angle_with_complement(inverse))
    elif inverse is not None:
        coefficients = {n: replace(c, closed=closed_with_base_angle(c.closed, inverse))
                        if isinstance(c, Branch) else c for n, c in coefficients.items()}
    if isinstance(angle, NewtonAngle):
        coefficients = {n: _single_switch(c) for n, c in coefficients.items()}
    if unbounded:  # x unbounded: (k x + a)^n overflows before the value does
        coefficients = {n: Algebraic(with_bounded_powers(c.expression)) if isinstance(c, Algebraic) else c
                        for n, c in coefficients.items()}
    slopes = {n: c for n, c in coefficients.items() if n in derivation.slopes}
    kinematic = {n: c for n, c in coefficients.items()
                 if n not in derivation.slopes and n not in UNREAD_SCALARS}
    limit = _domain_limit(derivation, kinematic, angle, inverse, phi_max, p_max, dtype)
    if isinstance(angle, NewtonAngle):  # the angle's steps do not reach beyond this size
        limit = min(limit, angle.converges_below ** 2)
    slope_limit = min(limit, _domain_limit(derivation, slopes, angle, inverse, phi_max, p_max, dtype))
    if slopes_unrepresentable:  # the derivative functions are NaN everywhere in this format
        slope_limit = 0.0
    return PrecisionPlan(label, float(np.finfo(dtype).eps), angle, coefficients, scale, limit, slope_limit)


def _single_switch(coefficient: Coefficient) -> Coefficient:
    """A Branch whose smallest switch is its threshold (``Branch.smallest_switch``), for a plan whose
    angle iterates (:class:`symrot.plan.ir.NewtonAngle`). The smaller switch trusts the closed form's
    error measured on angles rounded to nearest (:func:`measured_inputs`), and an iterated angle
    is only within about an ulp (eq 35: 0.91): eq 35's float64 H⁻¹ across the axis, its closed form
    measured within 1.1 ulp, was 2.0 ulp off for |p| = 0.1–0.33 in the NumPy module, where the
    threshold's polynomial (taken by the JAX and PyTorch modules) is 0.5. Where φ is iterated the
    longer polynomial costs little beside the iteration."""
    if isinstance(coefficient, Branch):
        return replace(coefficient, accurate_threshold=None, accurate_terms=None)
    return coefficient


def definition_forms(raw: sp.Expr, simplified: sp.Expr, p: sp.Expr, phi_max: float, inverse: sp.Expr | None,
                     complement: sp.Rational | None) -> tuple[sp.Expr, ...]:
    """The candidate forms of a coefficient's definition ``raw`` (eqs 14, 22, 26, 81, 83 before
    simplification) that go through s or x: challengers of :func:`plan_branch`'s choice, taken only
    where measurably better; none when the definition is its simplified form or a step fails.

    Simplification can cancel p out of a coefficient and with it the form through x: G₂ =
    (1 − cos(φ/2))/p² of 4 sin(φ/4) cosh φ simplifies to 1/(8 cosh²φ), which inherits the rounding
    of φ̂ through cosh (float32 ``root_matrix`` 8.8 ulp next to 2π); 2 sin²(φ/4)/x, the definition
    through x, does not (1.4 ulp). Forms of the definition in φ alone are left out: the simplified
    form's stand for them. Not offered where p is unbounded: the branch is chosen before the domain
    sweep, and a definition through powers of x overflows before the value does (tan φ + tan³φ/3:
    float32's domain ended at |p|² = 2⁷⁵ instead of beyond 2⁸⁰)."""
    if raw == simplified:
        return ()
    try:
        forms = candidate_forms(raw, p, phi_max, inverse, complement)[1]
    except SymrotTimeout:  # re-raised: leaving the forms out would make the plan depend on the machine
        raise
    except Exception:  # optional candidates: a failing step only leaves them out
        return ()
    return tuple(form for form in forms if form.has(S, X))


def difference_forms(coefficients: dict[str, Coefficient], tensor: str,
                     complement: sp.Rational | None) -> tuple[sp.Expr, ...]:
    """c₀ − c₂ x (as printed and cancelled) when both are algebraic in x: candidates for the
    across-axis part t = c₀ − c₂ x of ``tensor``. Next to 2π for 6 tan(φ/6), t = (p/2) cot(φ/2) in
    φ inherits the angle's rounding through the pole of cot (2·10⁵ ulp); 9 (x − 12)/(x − 108) does not.
    With a fold complement, k² − x is written as d (as :func:`_use_complement` does for c₀ and c₂)."""
    values = [_algebraic_value(coefficients[f"{tensor}_{k}"]) for k in (0, 2)]
    if values[0] is None or values[1] is None:
        return ()
    difference = values[0] - values[1] * X
    forms = (sp.cancel(difference), difference)
    if complement is not None:
        forms = tuple(with_complement(form, complement) for form in forms)
    return tuple(dict.fromkeys(forms))


def _algebraic_value(coefficient: Coefficient) -> sp.Expr | None:
    """A coefficient's expression in x (and d) when it has no branch, else None."""
    if isinstance(coefficient, Algebraic):
        return coefficient.expression
    if isinstance(coefficient, Constant):
        return sp.sympify(coefficient.value)
    return None


def _plan_slope(derivation: Derivation, name: str, coefficients: dict[str, Coefficient], phi_max: float,
                dtype: type, inverse: sp.Expr | None, complement: sp.Rational | None,
                own_scale: bool) -> Coefficient:
    """A slope dc/dx (:mod:`symrot.core.derivatives`): the derivative in x of its parent's algebraic form when
    the parent has one (d(D)/dx = −1), else a Branch of its closed form and exact series, measured
    relative to itself with ``own_scale`` (:data:`OWN_SCALE`). Never a search of its own under the
    algebraic time budget, so that the plan is the same on a loaded machine."""
    parent = coefficients[derivation.slopes[name][0]]
    if isinstance(parent, Algebraic):
        return Algebraic(sp.diff(parent.expression, X) - sp.diff(parent.expression, D))
    series = derivation.series_in_x(name, MAX_TERMS)
    return plan_branch(derivation.simplified_form(name), series, derivation.p ** 2, phi_max, dtype,
                       derivation.p, inverse, complement, OWN_SCALE if own_scale else None)


def _check_scale(derivation: Derivation) -> None:
    """Refuse at once a p whose scale no format can hold: the coefficient of (p×)² in R at p = 0 is
    1/(2κ²) (eq 16), so κ = 1e-20 overflows float32 (any plan would fail, after a minute of
    planning, on the first coefficient; issue 17)."""
    kappa = mpmath.mpf(float(abs(derivation.kappa))) if derivation.kappa.is_number else None
    if kappa is None or kappa == 0:
        return
    needed = 1 / (2 * kappa**2)
    for label, dtype in PRECISIONS.items():
        largest = float(np.finfo(dtype).max)
        if needed > largest:
            raise SymrotError(f"no representable plan: p = {sp.sstr(derivation.p)[:60]} is too small "
                              f"in scale for {label} (kappa = {float(kappa):.3g}: 1/(2 kappa^2) = "
                              f"{float(needed):.3g}, the (p x)^2 coefficient of R at p = 0, exceeds "
                              f"{largest:.3g}); --normalize divides p by kappa")


def _domain_limit(derivation: Derivation, coefficients: dict[str, Coefficient],
                  angle: ClosedAngle | NewtonAngle, inverse: sp.Expr | None, phi_max: float, p_max: float,
                  dtype: type) -> float:
    """x_limit of :class:`PrecisionPlan`: the printed forms as the backends evaluate them above
    x = 2^32 (algebraic forms, the closed side of branches, the closed angle), swept by
    :func:`symrot.plan.domain.domain_limit`."""
    raw = {**derivation.planned_expressions(), QUATERNION_SCALAR: quaternion_scalar()}
    printed: dict[str, tuple[str, sp.Expr]] = {}
    for name, coefficient in coefficients.items():
        if isinstance(coefficient, Algebraic):
            printed[name] = ("algebraic", coefficient.expression)
        elif isinstance(coefficient, Branch) and max(coefficient.threshold,
                                                     coefficient.smallest_switch[0]) < 2.0**FIRST_POWER:
            printed[name] = ("closed", coefficient.closed)
    references = {name: raw[name] for name in coefficients}
    if isinstance(angle, ClosedAngle):
        printed["angle"], references["angle"] = ("closed", angle.expression), PHI
    return domain_limit(printed, references, derivation.p, inverse, phi_max, p_max, dtype)


def remember_plan(plan: EvaluationPlan) -> None:
    """Let :func:`evaluation_plan` return ``plan`` for its p and name in this process instead of
    computing it: for a caller that kept the plan of an earlier run (``symrot.cli.plan_cache``)."""
    _GIVEN_PLANS[(plan.p, plan.name)] = plan


def evaluation_plan(derivation: Derivation, name: str) -> EvaluationPlan:
    """The plan of every coefficient of ``derivation`` in float64 and float32."""
    given = _GIVEN_PLANS.get((derivation.p, name))
    return given if given is not None else _plan_for(derivation.p, name)
