"""Branches of a coefficient: the Horner series of its Taylor expansion below a switch and the best
closed form above it, measured against mpmath per precision (:func:`plan_branch`), and the error
floors of the tensors they build (:func:`tensor_floors`)."""

from __future__ import annotations

import math
from functools import lru_cache
from typing import Any, NamedTuple

import mpmath
import numpy as np
import sympy as sp

from symrot.core.derivation import Derivation
from symrot.core.errors import SymrotError
from symrot.core.functions import mpmath_namespace
from symrot.core.parsing import PHI
from symrot.plan.algebraic import (
    D,
    S,
    closed_with_base_angle,
    closed_with_complement,
    with_inverse,
)
from symrot.plan.algebraic import X as X  # re-exported: the symbol of the coefficients' variable x = |p|²
from symrot.plan.evaluation import (
    model_function,
)
from symrot.plan.forms import (
    gudermannian,
    half_angle,
    half_angle_sums,
    hyperbolic_complement,
    near_half_turn,
    trig_arguments,
    well_conditioned,
)
from symrot.plan.ir import (
    Branch,
)
from symrot.plan.measurement import (
    MeasuredInputs,
    angle_grid,
    measured_inputs,
    reference_values,
    with_length,
)
from symrot.plan.newton_start import FarStart as FarStart
from symrot.plan.pole import pole_factor, with_pole_factor
from symrot.plan.targets import (
    CHEAP_TERMS,
    CLOSED_TOLERANCE_ULP,
    MAX_TERMS,
    POLYNOMIAL_TOLERANCE_ULP,
)


class UnplannableCoefficient(SymrotError):
    """No form of a coefficient is finite on the grid in the format (the scale of p is too small or
    too large for it)."""


FormsKey = tuple[sp.Expr, sp.Expr, float, sp.Expr | None, sp.Rational | None]
"""(closed form, argument s(φ), φ_max, closed inverse, fold complement): what :func:`candidate_forms`
depends on (not the precision)."""
_CANDIDATES: dict[FormsKey, tuple[tuple[sp.Expr, ...], tuple[sp.Expr, ...]]] = {}
CANDIDATES_KEPT = 4096
"""Most entries :func:`candidate_forms` remembers (then it starts again)."""
BRANCH_VARIABLES = (PHI, S, X, D)
"""The variables of a branch's closed form as :func:`_branch_for` measures it."""


def candidate_forms(closed: sp.Expr, argument: sp.Expr, phi_max: float, inverse: sp.Expr | None,
                    complement: sp.Rational | None) -> tuple[tuple[sp.Expr, ...], tuple[sp.Expr, ...]]:
    """(the forms in φ that the reference evaluates, every candidate form :func:`plan_branch`
    measures) for one coefficient; the same for both precisions, so remembered, and computed for
    all coefficients before the precisions part (:func:`_prepare_shared_work`)."""
    key: FormsKey = (closed, argument, phi_max, inverse, complement)
    if key not in _CANDIDATES:
        if len(_CANDIDATES) >= CANDIDATES_KEPT:
            _CANDIDATES.clear()
        _CANDIDATES[key] = _candidate_forms(*key)
    return _CANDIDATES[key]


def _candidate_forms(closed: sp.Expr, argument: sp.Expr, phi_max: float, inverse: sp.Expr | None,
                     complement: sp.Rational | None) -> tuple[tuple[sp.Expr, ...], tuple[sp.Expr, ...]]:
    """Besides the forms in φ (half angles, cancellation-free rewrites), the same with p written as
    s (:func:`with_length`), with a pole's vanishing factor through s, and, given the closed
    ``inverse`` φ(s), with their algebraic parts written through it
    (:func:`symrot.plan.algebraic.with_inverse`); each as the backends print it (base angle of the
    tangent family, fold complement d of the sine family)."""
    forms = [half_angle(closed)] if closed.has(sp.sin(PHI), sp.cos(PHI)) else []
    forms += ([well_conditioned(closed), near_half_turn(closed), half_angle_sums(closed)]
              if closed.has(sp.cos) else [])
    forms.append(closed)
    if closed.has(sp.asin, sp.atanh):
        forms.append(gudermannian(closed))
    plain = tuple(dict.fromkeys([closed, *forms]))
    written = [with_length(form, argument) for form in forms]
    forms += written
    # cos a → 1 − 2 sin²(a/2) after p is written as s: before, it changes the sums that
    # with_length recognizes as p (cos(φ/3) in 3φ cos(φ/3)/5 + …), and (1 − cos(φ/2))/x cancels
    # at small φ (hypothesis row 120: G₂ recomputed p from φ̂, 9 ulp of G in float32 at 6.18)
    for form in written:
        conditioned = well_conditioned(form)
        if form.has(S, X) and conditioned not in forms:
            forms.append(conditioned)
        halved = half_angle(form)
        if form.has(S, X) and halved not in forms:
            forms.append(halved)
    pole = pole_factor(argument, phi_max) if argument != PHI else None
    if pole is not None:  # p → ∞ at φ_max: its vanishing factor through s (symrot.plan.pole)
        forms += [with_pole_factor(form, pole) for form in forms]
    if inverse is not None and argument != PHI:
        forms += [with_inverse(form, inverse) for form in forms]
        forms += [hyperbolic_complement(form) for form in forms if form.has(sp.tanh)]
        forms = [closed_with_base_angle(form, inverse) for form in forms]
        if complement is not None:
            forms = [closed_with_complement(form, inverse, complement) for form in forms]
    return plain, tuple(forms)


def plan_branch(closed: sp.Expr, series: list[sp.Expr], variable_of_phi: sp.Expr, phi_max: float,
                dtype: type, argument: sp.Expr = PHI, inverse: sp.Expr | None = None,
                complement: sp.Rational | None = None, part: TensorPart | None = None,
                extra_forms: tuple[sp.Expr, ...] = (), challengers: tuple[sp.Expr, ...] = (),
                whole: float | None = None) -> Branch:
    """Choose the form, the switch t₀ and the Horner degree for one coefficient in one precision.

    The coefficient is evaluated from s = ``argument``(φ) (p for the coefficients of x, φ itself
    for Newton's ratio and slope). Besides the forms in φ, the same with p written as s
    (:func:`with_length`) and, given the closed ``inverse`` φ(s), with their algebraic parts written
    through it (:func:`symrot.plan.algebraic.with_inverse`); each as the backends print it (base angle of
    the tangent family, fold complement d of the sine family) (:func:`candidate_forms`), measured on
    the inputs of :func:`measured_inputs` against one reference at REFERENCE_DIGITS. A coefficient of a tensor
    (``part``) is measured as it enters the tensor: relative to ‖T‖/|p|^k where that is below c(0)
    (:func:`_branch_for`). ``extra_forms``: more candidates, already in the backends' variables
    (e.g. c₀ − c₂ x from algebraic c₀ and c₂ for the across-axis part). ``challengers``: forms in the
    backends' variables (:func:`definition_forms`) that replace the choice only where they are
    measurably better: a smaller error class or a shorter polynomial (:func:`_accuracy_first`).
    ``whole``: the branch is the tail of Newton's ratio (:func:`_branch_for`)."""
    plain, candidates = candidate_forms(closed, argument, phi_max, inverse, complement)
    forms = [*candidates, *extra_forms]
    inputs = measured_inputs(argument, phi_max, dtype, complement)
    reference = reference_values(plain, argument, phi_max, dtype, complement)
    floors = None if part is None else tensor_floors(part, argument, phi_max, dtype, complement)

    def measured(candidates: list[sp.Expr]) -> list[Branch]:
        branches = []
        for form in dict.fromkeys(candidates):
            try:
                branches.append(_branch_for(form, series, variable_of_phi, phi_max, dtype, inputs, reference,
                                            floors, whole))
            except ZeroDivisionError:  # 0/0 of this form at a grid angle: another form is measured
                continue
        return branches

    branches = measured(forms)
    if not branches:
        raise UnplannableCoefficient(f"cannot plan {closed} in {np.dtype(dtype).name}: every form divides "
                                     "by zero on the grid")
    chosen = min(branches, key=_preference)
    others = measured([form for form in challengers if form not in forms])
    if others:
        challenger = min(others, key=_preference)
        if _accuracy_first(challenger) < _accuracy_first(chosen):
            chosen = challenger
    return chosen


def _accuracy_first(branch: Branch) -> tuple[float, float, int]:
    """The worse and the better of the branch's error classes (inside, at the edge), then the
    length of its polynomial: what makes one branch measurably better than another."""
    worse, better = sorted((_error_class(branch.measured_ulp), _error_class(branch.edge_ulp)), reverse=True)
    return worse, better, len(branch.smallest_switch[1])


def _preference(branch: Branch) -> tuple[float, float, int, bool, int, float, float]:
    """The order of :func:`plan_branch`'s choice: the smallest worst error class, then the smaller
    other class (sinh φ: H₂ through √(1 + x) is 3.5 ulp at the edge where the form in φ̂ is 7, both 11
    inside: the edge decides); equally accurate forms: the shortest polynomial, then a form in φ alone
    (a form in s and x is taken where it is measurably more accurate), then the fewest sin/cos
    arguments."""
    return (*_accuracy_first(branch), branch.closed.has(S, X), trig_arguments(branch.closed),
            branch.edge_ulp, branch.measured_ulp)


class TensorPart(NamedTuple):
    """Where a coefficient enters its tensor T = c₀ I + c₁ (p×) + c₂ (p×)²: as c_k |p|^k (``power``;
    0 for the across-axis part c₀ − c₂|p|²), in a tensor of norm ``norm`` (an expression in φ)."""

    norm: sp.Expr
    power: int


QUATERNION_PART = TensorPart(sp.Integer(2), 1)
"""How ν enters the quaternion's vector part (ν/2) p (eq 75), of unit scale: its error counts as
|δν| s/2 against 1, as :func:`symrot.plan.domain.domain_limit` counts it (relative to max(|ν|, ν(0)) a
form in φ that loses every digit of ν → 0 next to a pole passed, and the sweep then ended the
domain at |p|² = 2³²)."""

OWN_SCALE = TensorPart(sp.Integer(0), 0)
"""Where p → ∞ at φ_max, det H (``tangent_det``) and the slopes dc/dx are measured relative to
themselves, as the domain sweep counts them: s then resolves the distance to the edge, and every
coefficient of s is well conditioned up to it (det H = μν² ~ 1/x² next to a pole, where a form in
φ̂ loses every digit). The same where det H → 0 at φ_max because p′ → ∞ there (a logarithmic pole
such as asinh(tan φ), an arcsine edge): H₀ = cos φ of asinh(tan φ) and its slope vanish at π/2, and
measured against a fixed floor, their forms in φ̂ looked as good as those through s (1/cosh s) while
float32 ∂(H a)/∂p was 5·10⁵ ulp off at π/2 − 10⁻⁶. With p finite at the edge otherwise (ν → 0 at 2π, a
fold) det H(s) is ill conditioned there, and they keep the floor max(|c|, |c(0)|)."""


def tensor_part(derivation: Derivation, coefficient: str, det_h_own_scale: bool = False) -> TensorPart | None:
    """The :class:`TensorPart` of a coefficient of R, H, H⁻¹, G or K (or of its across-axis part),
    :data:`QUATERNION_PART` for ν, :data:`OWN_SCALE` for det H with ``det_h_own_scale`` (p unbounded,
    or det H → 0 at φ_max with p′ → ∞), None for the other scalars and the slopes. The norm is the
    largest eigenvalue modulus, max(|a|, |a − c|, |b|) of the u-basis a I + b U + c U² (axial a,
    across the axis (a − c) ± i b; eqs 17, 23, 27)."""
    if coefficient == "nu":
        return QUATERNION_PART
    if coefficient == "det_H":
        return OWN_SCALE if det_h_own_scale else None
    for tensor in derivation.tensors.values():
        names = (*tensor.coefficient_names(), tensor.across_name)
        if coefficient in names:
            u = tensor.u_basis
            # unevaluated: only evaluated numerically, and Max's pairwise comparisons cost 40 ms
            norm = sp.Max(sp.Abs(u.a), sp.Abs(u.a - u.c), sp.Abs(u.b), evaluate=False)
            return TensorPart(norm, 0 if coefficient == tensor.across_name else names.index(coefficient))
    return None


@lru_cache(maxsize=64)
def tensor_floors(part: TensorPart, argument: sp.Expr, phi_max: float, dtype: type,
                  complement: sp.Rational | None) -> tuple[np.ndarray, ...]:
    """‖T‖/|p|^k at the exact angles of :func:`measured_inputs` (30 digits, NaN where it cannot be
    evaluated): the size of the error of c_k that the tensor can absorb. ‖T‖ and |p| are evaluated
    once per tensor (:func:`_norm_and_length`) and shared by its parts c₀, c₁, c₂ and c₀ − c₂ x."""
    values = []
    with mpmath.workdps(30):
        for row in _norm_and_length(part.norm, argument, phi_max, dtype, complement):
            floors = []
            for norm, length in row:
                try:
                    floors.append(float(norm / length ** part.power))
                except (ZeroDivisionError, OverflowError, ValueError, TypeError):
                    floors.append(math.nan)
            values.append(np.asarray(floors, dtype=np.float64))
    return tuple(values)


@lru_cache(maxsize=16)
def _norm_and_length(norm: sp.Expr, argument: sp.Expr, phi_max: float, dtype: type,
                     complement: sp.Rational | None) -> tuple[tuple[tuple[Any, Any], ...], ...]:
    """(‖T‖, |p|) at the exact angles of :func:`measured_inputs`, 30 digits; (NaN, 1) where ‖T‖
    or p cannot be evaluated (mpmath numbers, read-only)."""
    inputs = measured_inputs(argument, phi_max, dtype, complement)
    norm_of = sp.lambdify(PHI, norm, modules=[mpmath_namespace(), "mpmath"], cse=True)
    p_of = sp.lambdify(PHI, argument, modules=[mpmath_namespace(), "mpmath"])
    rows = []
    with mpmath.workdps(30):
        for thetas in inputs.exact:
            row = []
            for theta in thetas:
                try:
                    row.append((norm_of(theta), abs(p_of(theta))))
                except (ZeroDivisionError, OverflowError, ValueError, TypeError):
                    row.append((mpmath.nan, mpmath.mpf(1)))
            rows.append(tuple(row))
    return tuple(rows)


def _error_class(ulp: float) -> float:
    """0 within tolerance, else the error's binary order of magnitude (inf for inf/NaN results):
    a form 2 ulp off everywhere beats one that is exact inside but infinite next to φ_max."""
    if ulp <= CLOSED_TOLERANCE_ULP:
        return 0.0
    if not math.isfinite(ulp):
        return math.inf
    mantissa, exponent = math.frexp(ulp / CLOSED_TOLERANCE_ULP)  # exact: no libm log2
    return float(exponent if mantissa > 0.5 else exponent - 1)


def _magnitude(coefficient: sp.Expr) -> float:
    """|coefficient| as a float64, inf when it exceeds the largest double."""
    try:
        return abs(float(coefficient))
    except OverflowError:
        return math.inf


def _branch_for(closed: sp.Expr, series: list[sp.Expr], variable_of_phi: sp.Expr, phi_max: float,
                dtype: type, inputs: MeasuredInputs, reference: tuple[np.ndarray, ...],
                floors: tuple[np.ndarray, ...] | None = None, whole: float | None = None) -> Branch:
    """The switch and polynomial of :func:`plan_branch` for one form ``closed``. ``whole``: the branch is
    the tail g − g(0) of Newton's ratio g, whose errors count relative to |g(0)| = ``whole``, and its
    polynomial is the longest that truncates below a quarter ulp on the grid's lower half
    (φ below min(φ_max, 4π)/2), for every backend:
    the residual (φ g(0) − s) + φ (g − g(0)) then keeps the digits that the closed form loses
    (:class:`symrot.plan.ir.NewtonAngle`)."""
    epsilon, tiny = float(np.finfo(dtype).eps), float(np.finfo(dtype).tiny)
    model_closed = model_function(closed, BRANCH_VARIABLES)
    angles = angle_grid(phi_max)
    t_values = _switch_values(variable_of_phi, phi_max, dtype)
    scale0 = (abs(float(series[0])) or 1.0) if whole is None else whole
    # a coefficient of a tensor counts relative to what it adds to the tensor where that is below
    # c(0): G_2 ~ 2/x next to 2 pi (G_2 x is of order 1, c(0) = 1/8 would hide any relative error of
    # G_2 itself); H_across ~ mu next to 2 pi for phi + phi^3/6 (~ 0.05, with c(0) = 1)
    # every grid angle's points at once (the models are elementwise); per angle k: points_of[k]
    joined = [np.concatenate(columns) for columns in (inputs.angles, inputs.lengths, inputs.squares,
                                                      inputs.complements)]
    ends = np.cumsum([len(a) for a in inputs.angles])
    points_of = [slice(int(end) - len(a), int(end)) for end, a in zip(ends, inputs.angles, strict=True)]
    exact = np.concatenate(reference) if len(reference) else np.zeros(0)
    floor = scale0 if floors is None else np.fmin(scale0, np.concatenate(floors))
    with np.errstate(all="ignore"):
        scale = np.maximum(np.abs(exact), floor)
    # a value below the format's normal range has no digits to lose: every finite form ties
    # there (det H ~ 1/x² of tan φ + tan³φ/3 underflows float32 next to its pole, and that tie
    # chose the form in φ̂ over the one through s, which is right up to the underflow)
    unmeasured = np.isnan(exact) | ((exact != 0) & (np.abs(exact) < tiny))

    def relative_errors(values: np.ndarray) -> np.ndarray:
        """ulp of ``values`` at every grid point (inf where not finite)."""
        with np.errstate(all="ignore"):
            errors = np.abs(values - exact) / (scale * epsilon)
        return np.where(np.isfinite(values), np.where(unmeasured, 0.0, errors), np.inf)

    closed_errors = relative_errors(np.broadcast_to(np.asarray(model_closed(*joined), dtype=np.float64),
                                                    joined[0].shape))
    closed_error = np.array([float(np.max(closed_errors[points])) if points.stop > points.start else 0.0
                             for points in points_of])
    floats = [_magnitude(c) for c in series]
    # every Horner coefficient must be finite in the format (e.g. 1000 tan(φ/1000) has a
    # coefficient 1.1e42 of x in H⁻¹, beyond float32): the polynomial keeps only the leading terms
    # that are, and the switch moves down until those truncate below the tolerance
    largest = float(np.finfo(dtype).max)
    top = min(MAX_TERMS - 2, next((n for n, c in enumerate(floats) if not c <= largest), len(floats)))
    if top == 0:
        raise UnplannableCoefficient(f"cannot plan {closed} in {np.dtype(dtype).name}: its value at p = 0 "
                                     f"({float(series[0]):.3g}) is not finite in that format")

    def truncation(t: float, n: int) -> float:
        # the first two terms left out that are not zero: sin φ/p of p = φ − φ³/6 + φ⁵/120 is
        # 1 − x³/5040 + …, and its terms x, x² (zero) said that 1 alone was exact up to x = 0.02
        rest = [(j, c) for j, c in enumerate(floats[n:], start=n) if c != 0][:2]
        with np.errstate(all="ignore"):  # coefficients beyond float64 are inf here: inf or NaN expected
            return sum(c * t ** j for j, c in rest) / (scale0 * epsilon)

    best, best_k = np.inf, len(angles) - 1
    near_zero = int(np.searchsorted(angles, 0.5 * min(phi_max, 4 * np.pi)))
    for k in range(near_zero):
        worst_closed = float(np.max(closed_error[k:near_zero]))
        worst = max(worst_closed, truncation(t_values[k], top))
        if worst <= CLOSED_TOLERANCE_ULP and best <= CLOSED_TOLERANCE_ULP:
            # both acceptable: prefer the smaller switch (fewer terms)
            if truncation(t_values[k], top) <= truncation(t_values[best_k], top):
                best, best_k = worst, k
        elif worst < best:
            best, best_k = worst, k
    if best_k >= near_zero:  # every error estimate is inf/NaN: e.g. p = 1e-20*phi, the series overflows
        raise UnplannableCoefficient(f"cannot plan {closed} in {np.dtype(dtype).name}: neither it nor its "
                                     "series in x = |p|^2 is finite on the grid (p is too small or too large "
                                     "in scale)")
    def terms_at(threshold: float) -> int:
        target = max(0.25, truncation(threshold, top))
        return next((n for n in range(1, top + 1) if truncation(threshold, n) <= target), top)

    accurate_threshold = float(t_values[best_k])
    # speed: a polynomial of up to CHEAP_TERMS terms costs less than the closed form's library
    # calls, so the switch moves up while such a polynomial still truncates below a quarter ulp
    # (the closed form then serves a smaller range, where its error can only be smaller)
    while best_k + 1 < near_zero and truncation(t_values[best_k + 1], min(CHEAP_TERMS, top)) <= 0.25:
        best_k += 1
    if whole is not None:  # Newton's ratio: the longest polynomial that truncates below a quarter ulp
        while best_k + 1 < near_zero and truncation(t_values[best_k + 1], top) <= 0.25:
            best_k += 1
    best = min(best, max(float(np.max(closed_error[best_k:near_zero])),
                         truncation(t_values[best_k], top)))

    def polynomial_misses(below: float, terms: int) -> bool:
        """Whether the first ``terms`` terms, measured on the grid points with t < ``below`` (Horner
        in float64: for float32 the truncation alone), are somewhere off by more than
        POLYNOMIAL_TOLERANCE_ULP and by more than the closed form at that grid angle."""
        value = np.zeros_like(squares)
        for c in reversed([float(c) for c in series[:terms]]):
            value = value * squares + c
        served = below_edge & (squares < below)
        return bool(np.any(relative_errors(value)[served] > allowed[served]))

    squares = joined[2].astype(np.float64)
    # the grid's lower half (a polynomial's range), and per point the closed form's worst at its angle
    below_edge = np.arange(len(squares)) < (int(ends[near_zero - 1]) if near_zero else 0)
    allowed = np.maximum(POLYNOMIAL_TOLERANCE_ULP, np.repeat(closed_error, np.diff(ends, prepend=0)))

    # the truncation is an estimate from a few terms: the polynomials are also measured against the
    # reference, and a switch moves down while its polynomial misses
    accurate_terms = terms_at(accurate_threshold)
    lowered = False
    while best_k > 0 and polynomial_misses(float(t_values[best_k]),
                                           max(terms_at(float(t_values[best_k])), accurate_terms)):
        best_k, lowered = best_k - 1, True
        if float(t_values[best_k]) < accurate_threshold:
            accurate_threshold = float(t_values[best_k])
            accurate_terms = terms_at(accurate_threshold)
    while accurate_threshold > float(t_values[0]) and polynomial_misses(accurate_threshold, accurate_terms):
        accurate_threshold = float(t_values[int(np.searchsorted(t_values, accurate_threshold)) - 1])
        accurate_terms = terms_at(accurate_threshold)
    if lowered:  # the closed form now serves more of the range
        best = max(float(np.max(closed_error[best_k:near_zero])), truncation(t_values[best_k], top))
    threshold = float(t_values[best_k])
    degree = max(terms_at(threshold), accurate_terms)
    if whole is not None:  # every backend takes this switch: the accuracy is the point
        accurate_threshold, accurate_terms = threshold, degree
    edge = float(np.max(closed_error[near_zero:])) if near_zero < len(angles) else 0.0
    return Branch(threshold, tuple(series[:degree]), closed, float(angles[best_k]), best, edge,
                  accurate_threshold, accurate_terms)


@lru_cache(maxsize=16)
def _switch_values(variable_of_phi: sp.Expr, phi_max: float, dtype: type) -> np.ndarray:
    """The candidate switches: the variable t(φ) of the series (x = p² or φ²) at the angles of
    :func:`angle_grid` rounded to ``dtype``, 30 digits. The same for every form of every
    coefficient of a plan: computed once (read-only)."""
    to_t = sp.lambdify(PHI, variable_of_phi, modules=[mpmath_namespace(), "mpmath"])
    with mpmath.workdps(30):
        values = np.array([float(to_t(mpmath.mpf(float(dtype(angle))))) for angle in angle_grid(phi_max)])
    values.setflags(write=False)
    return values
