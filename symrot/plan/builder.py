"""Evaluation plans: how each scalar coefficient c(x), x = |p|², is evaluated safely.

Generated code takes the parameter vector p, never φ. Every quantity is a scalar coefficient of
x = |p|²: ν, ε, μ, p′, det H (eqs 17–24), the coefficients on I, (p×), (p×)² of R (16), H (20),
H⁻¹ (26), G (81) and K (83) (names as in ``Derivation.coefficient_expressions``), the slopes dc/dx
of R's, H's and H⁻¹'s coefficients (``R_1_x`` …, :mod:`symrot.core.derivatives`), e₀ = cos(φ/2)
(``e_0``, eq 74) and φ itself. The plan decides this once per coefficient and per precision;
backends only print it.

The plan's IR (``EvaluationPlan``, ``PrecisionPlan``, ``Constant``, ``Algebraic``, ``Branch``,
``ClosedAngle``, ``NewtonAngle``) is described and defined in :mod:`symrot.plan.ir`; this module
builds it and re-exports its names.

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
from sympy.core.traversal import bottom_up

from symrot.core.derivation import Derivation, derive_expression
from symrot.core.errors import SymrotError, SymrotTimeout
from symrot.core.forked import first_here_others_in_children
from symrot.core.functions import RealCbrt, mpmath_namespace
from symrot.core.parsing import PHI
from symrot.core.series import coefficient_list, taylor_series
from symrot.core.timeouts import bounded
from symrot.core.two_processes import computed_in_two_processes, simplify_tensors
from symrot.plan.algebraic import (
    REDUCTION_OPS,
    D,
    S,
    algebraic_in_x,
    angle_with_complement,
    closed_with_base_angle,
    closed_with_complement,
    fold_complement,
    reduction_size,
    with_bounded_powers,
    with_complement,
    with_inverse,
)
from symrot.plan.algebraic import X as X  # re-exported: the symbol of the coefficients' variable x = |p|²
from symrot.plan.domain import FIRST_POWER, domain_limit
from symrot.plan.evaluation import (
    ModelKey,
    log_grid,
    model_function,
    model_key,
    model_source,
    remember_sources,
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
    QuaternionScale,
)
from symrot.plan.measurement import (
    EDGE_POINTS,
    GRID_POINTS,
    MeasuredInputs,
    angle_grid,
    measured_inputs,
    reference_values,
    with_length,
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
from symrot.plan.pole import pole_factor, with_pole_factor
from symrot.plan.quaternion import (
    QUATERNION_SCALAR,
    e0_min,
    quaternion_scalar,
    quaternion_scalar_series,
    scale_expression,
    scale_in_e0,
    scale_series,
)

MAX_TERMS = 24
CHEAP_TERMS = 8
"""A Horner polynomial of up to this many terms (8 fused multiply-adds) is cheaper than a closed
form with sin/cos (a libm call is 20–60 cycles) or a division: switches move up to where it stays
accurate, so that small rotations, the common case in time stepping, never reach libm."""
ALGEBRAIC_WORK = 4000
"""Total expansion size (:func:`symrot.plan.algebraic.reduction_size`, operations) the algebraic search
of one plan may simplify; past it, coefficients get branches. A count, not a time: the plan is
the same on every machine and under any load."""
PRECISIONS: dict[str, type[np.floating]] = {"float64": np.float64, "float32": np.float32}
CLOSED_TOLERANCE_ULP = 1.5
POLYNOMIAL_TOLERANCE_ULP = 2.0
"""A branch's Horner polynomial, measured on the grid below its switch, must stay within this
(the truncation estimate alone keeps it below a quarter ulp plus the rounding of Horner's steps)."""
ANGLE_TOLERANCE_ULP = 2.0
"""A closed inverse φ(s) is printed only when its measured error (beyond the conditioning of φ(s),
see :func:`closed_angle_error`) stays within this; otherwise the Newton angle is used."""
UNREAD_SCALARS = frozenset({"p_prime", "epsilon", "mu"})
"""Planned and printed beside the others (eqs 15, 16, 21), but no emitted function reads them (the
tangent's determinant is det H, the quaternion reads e₀ and ν): they do not bound the domain."""
NEWTON_ITERATIONS = 6
START_TERMS = 8


def well_conditioned(expr: sp.Expr) -> sp.Expr:
    """Replace cos(a) by 1 − 2 sin²(a/2): the half-angle form keeps 1 − cos φ accurate."""
    return expr.replace(lambda e: isinstance(e, sp.cos), lambda e: 1 - 2 * sp.sin(e.args[0] / 2) ** 2)


def _cos_sum(e: sp.Basic) -> tuple[sp.Expr, sp.Expr, sp.Expr, sp.Expr] | None:
    """(k, sign, a, rest) when e = k + sign·k cos(a) + rest, with a number k ≠ 0 and sign ±1: a
    two-term sum (rest = 0; SymPy distributes 7 (1 + cos φ)), or a longer one with a rational k,
    whose first such cosine term in SymPy's order is taken. K₂ of 4 tan(3φ/4)/3 is
    9 (cos(3φ/2) + 1 − 3 sin(φ/2)/tan(3φ/4))/(64 tan²(3φ/4)): next to the pole at 2π/3 the
    cos(3φ/2) + 1 from φ̂ kept no digit beside the other term, whose pole factor goes through s
    (4175 ulp of K at |p|² = 2³², where the domain sweep ended the range: NaN from φ = 2π/3 − 2.7·10⁻⁵)."""
    if not isinstance(e, sp.Add):
        return None
    if len(e.args) == 2:
        constant, term = sorted(e.args, key=lambda a: not a.is_number)
        factor, cosine = term.as_coeff_Mul()
        if (constant.is_number and constant != 0 and abs(factor) == abs(constant)
                and isinstance(cosine, sp.cos)):
            return constant, factor / constant, cosine.args[0], sp.S.Zero
        return None
    constant, _ = e.as_coeff_Add()
    if constant == 0:
        return None
    for term in e.args:
        factor, cosine = term.as_coeff_Mul()
        if isinstance(cosine, sp.cos) and abs(factor) == abs(constant):
            rest = sp.Add(*[a for a in e.args if a is not term and not a.is_Number])
            return constant, factor / constant, cosine.args[0], rest
    return None


def _cos_sums_as_products(expr: sp.Expr, signs: tuple[int, ...]) -> sp.Expr:
    """``expr`` with each sum k + sign·k cos a (sign in ``signs``) written as 2k cos²(a/2) (sign 1)
    or 2k sin²(a/2) (sign −1), exactly; no other call changes."""
    def chosen(e: sp.Basic) -> bool:
        found = _cos_sum(e)
        return found is not None and found[1] in signs

    def product(e: sp.Add) -> sp.Expr:
        found = _cos_sum(e)
        assert found is not None
        constant, sign, angle, rest = found
        half = sp.cos(angle / 2) if sign == 1 else sp.sin(angle / 2)
        return 2 * constant * half**2 + rest
    return expr.replace(chosen, product)


def near_half_turn(expr: sp.Expr) -> sp.Expr:
    """Replace k(1 + cos a) by 2k cos²(a/2), exact and accurate next to a = π, where 1 + cos a rounds
    to 0: p′ of 4 tan(φ/2) cosh(φ/3)/7 + … has 4 cosh(φ/3)/(7 (cos φ + 1)), infinite in float64
    within 3·10⁻⁹ of its pole at π (hypothesis row 113). The form is a candidate beside
    :func:`well_conditioned`'s, whose 1 − 2 sin²(a/2) cancels there too."""
    return _cos_sums_as_products(expr, (1,))


def half_angle_sums(expr: sp.Expr) -> sp.Expr:
    """Replace k − k cos a by 2k sin²(a/2) and k + k cos a by 2k cos²(a/2), and no other cos call:
    the sums that cancel become products, while a factor cos a that vanishes at a pole stays, so that
    :func:`symrot.plan.pole.with_pole_factor` can still write it through s. H₂ of 4√(2φ² + 1) tan(φ/4) has
    cos⁴(φ/4)/((cos(φ/4) − 1)(cos(φ/4) + 1)): through s entirely, cos(φ/4) − 1 cancelled (float64
    ``tangent`` 26 ulp at φ = 0.5); in half angles entirely (:func:`well_conditioned`), cos⁴(φ/4)
    from φ̂ lost every digit next to the pole at 2π; this form lets each part take the accurate one."""
    return _cos_sums_as_products(expr, (1, -1))


def gudermannian(expr: sp.Expr) -> sp.Expr:
    """Replace asin(tanh a) by atan(sinh a), the same function (the Gudermannian), accurate for large
    a, where tanh a rounds next to 1 and asin's slope 1/√(1 − u²) = cosh a multiplies its rounding:
    asin(tanh φ) (corpus entry 28) was 80 ulp off at φ = 6.27, beyond the Newton angle's residual
    tolerance, so the float64 range ended at |p| = 1.56686 < p_max = 1.56706 (NaN up to 2π).

    Likewise atanh(sin a) by asinh(tan a), the same function (the inverse Gudermannian) for
    |a| < π/2 (a form is only taken where it measures right): next to a = π/2, sin a rounds next
    to 1 and 1 − sin a keeps none of its digits; from_quaternion of atanh(sin φ) was 1.4·10¹⁰ ulp
    off at π/2 − 10⁻⁶ (tan a keeps the relative accuracy of π/2 − a)."""
    expr = expr.replace(lambda e: isinstance(e, sp.asin) and isinstance(e.args[0], sp.tanh),
                        lambda e: sp.atan(sp.sinh(e.args[0].args[0])))
    return expr.replace(lambda e: isinstance(e, sp.atanh) and isinstance(e.args[0], sp.sin),
                        lambda e: sp.asinh(sp.tan(e.args[0].args[0])))


def hyperbolic_complement(expr: sp.Expr) -> sp.Expr:
    """Replace k − k tanh²(u) in a sum by k/cosh²(u), the same function, accurate for large u where
    tanh u rounds next to 1: the forms through the inverse φ = 4 tanh(s/4) of p = 4 atanh(φ/4) read
    1 − φ²/16 as 1 − tanh²(s/4), which loses its digits next to the pole at 4 (float64 H₂ 9.6 ulp
    at the edge of the plan's grid, 1.9 with it)."""
    def complement(sum_: sp.Expr) -> sp.Expr | None:
        constant, _ = sum_.as_coeff_Add()
        if constant == 0:
            return None
        for term in sum_.args:
            factor, rest = term.as_coeff_Mul()
            if factor == -constant and rest.is_Pow and rest.exp == 2 and isinstance(rest.base, sp.tanh):
                others = [a for a in sum_.args if a is not term and a != constant]
                return sp.Add(*others, constant * sp.cosh(rest.base.args[0]) ** -2)
        return None

    def rewrite(e: sp.Expr) -> sp.Expr:
        found = complement(e) if isinstance(e, sp.Add) else None
        return e if found is None else found

    return bottom_up(expr, rewrite)  # inner sums first, each matched once


def half_angle(expr: sp.Expr) -> sp.Expr:
    """sin φ → 2 sin(φ/2) cos(φ/2), cos φ → 1 − 2 sin²(φ/2): every call on the one argument φ/2, so
    that a compiler can evaluate them with a single sincos (and 1 − cos φ stays accurate)."""
    half = PHI / 2
    return expr.xreplace({sp.sin(PHI): 2 * sp.sin(half) * sp.cos(half),
                          sp.cos(PHI): 1 - 2 * sp.sin(half) ** 2})


def trig_arguments(expr: sp.Expr) -> int:
    """Distinct arguments of sin/cos/tan calls other than φ/2, which every function shares (sin a and
    cos a cost one sincos)."""
    return len({e.args[0] for e in expr.atoms(sp.sin, sp.cos, sp.tan)} - {PHI / 2})


def closed_inverse(p: sp.Expr, kappa: sp.Expr) -> sp.Expr | None:
    """φ(s) with p(φ) = s, when SymPy finds a closed form that starts as s/κ."""
    if p == PHI:
        return S
    if p.has(RealCbrt) or not _solvable_shape(p):
        return None
    solutions: list[sp.Expr] = []
    # check=False: SymPy's own check substitutes each solution symbolically (1.5 s of the 2 s that
    # log((1 + φ/2)/(1 − φ/2)) took, 2.2 of 2.2 for a rational p); each candidate is checked below
    solvers = (_hyperbolic_solutions, lambda q: sp.solve(sp.Eq(q, S), PHI, check=False))
    for solver in solvers:
        try:  # one solver failing (NotImplementedError, its time bound) leaves the other's solutions
            solutions += bounded(10, [], solver, p)
        except Exception:
            continue
    for candidate in solutions:
        if candidate.has(sp.I) or candidate.free_symbols != {S}:
            continue
        probe = sp.Rational(1, 1000)
        value = candidate.subs(S, probe).evalf(30)
        if value.is_real and abs(value - probe / kappa) < sp.Rational(1, 10**6) and _solves(p, value, probe):
            return sp.simplify(candidate) if len(str(candidate)) < 80 else candidate
    return None


def _solves(p: sp.Expr, angle: sp.Expr, s: sp.Expr) -> bool:
    """Whether p(angle) = s to 20 digits (angle from a candidate inverse at 30)."""
    residual = (p.subs(PHI, angle) - s).evalf(30)
    return bool(residual.is_real and abs(residual) < abs(s) * sp.Rational(1, 10**20))


def _hyperbolic_solutions(p: sp.Expr) -> list[sp.Expr]:
    """The real solutions φ(s) of p(φ) = s that ``solveset`` writes with asinh/atanh, for p with
    sinh, cosh or tanh in it: ``solve`` writes them through exp, as log(s + √(s² + 1)) for sinh φ,
    which cancels for small s (every digit lost at s = 10⁻⁸) and made the plan take the Newton angle
    and coefficients in φ where 2 asinh(3s/2)/3 and 1/√(1 + 9s²/4) are exact (issue 16)."""
    if not p.has(sp.sinh, sp.cosh, sp.tanh):
        return []
    found = sp.solveset(sp.Eq(p, S), PHI, sp.S.Reals)
    finite = [found] if isinstance(found, sp.FiniteSet) else [
        part for part in getattr(found, "args", ()) if isinstance(part, sp.FiniteSet)]
    return [solution for part in finite for solution in part.args]


RATIONALIZED_OPS = 40
"""Largest closed inverse (``count_ops``) whose radicals :func:`angle_forms` moves: a size cap."""


def angle_forms(inverse: sp.Expr) -> tuple[sp.Expr, ...]:
    """The closed inverse φ(s) as solved, with asin(tanh u) as atan(sinh u) (:func:`gudermannian`),
    and with its square roots moved into the denominator (``radsimp`` of 1/φ): for
    p = φ/(1 − φ²/10), (√(10s² + 25) − 5)/s cancels for small s and was never printed (the Newton
    angle was 416 float32 ulp off next to the pole), while 10s/(√(10s² + 25) + 5) is accurate
    everywhere. For p = atanh(sin φ), asin(tanh s) loses the digits of π/2 − φ as tanh s rounds next
    to 1, and the Newton angle that replaced it converged only below |p| = 5.02 (φ = 1.5576 of π/2),
    where the range ended. The plan prints the first that measures within :data:`ANGLE_TOLERANCE_ULP`."""
    forms = (inverse, gudermannian(inverse))
    radicals = [a for a in inverse.atoms(sp.Pow) if a.exp.is_Rational and not a.exp.is_Integer]
    if not radicals or sp.count_ops(inverse) > RATIONALIZED_OPS:
        return tuple(dict.fromkeys(forms))
    return tuple(dict.fromkeys((*forms, 1 / sp.radsimp(1 / inverse))))


def _solvable_shape(p: sp.Expr) -> bool:
    """Whether ``sp.solve(p = s)`` is attempted: p algebraic in φ, or one function application
    f(…) with φ nowhere else (asinh(2φ)/2, atan(sin φ), log((1 + φ/2)/(1 − φ/2))). Sums and
    products of several transcendental terms (sin φ cos φ, sinh φ cosh φ, φ cos(φ/4)) give
    equations SymPy either cannot solve or spends its whole time bound on: the bound decided
    whether sin φ cos φ got a closed inverse on a given machine. A shape, not a time: reproducible."""
    outermost = [call for call in p.atoms(sp.Function) if call.has(PHI)
                 and not any(other != call and other.has(call) for other in p.atoms(sp.Function))]
    if not outermost:
        return True
    if len(outermost) > 1:
        return False
    level = sp.Dummy()
    outer = p.xreplace({outermost[0]: level})
    if outer.has(PHI):
        return False
    # a cubic in the call (asinh³φ + asinh φ): Cardano's root inside sinh, which solve spent its
    # whole bound on and the emit its 60 s budget; tan³φ/3 + tan φ got atan of it, never printed
    return not (outer.is_polynomial(level) and sp.degree(outer, level) > MAX_SOLVED_DEGREE)


MAX_SOLVED_DEGREE = 2
"""Largest degree of p as a polynomial in its one function application for which ``solve`` runs."""


def _exact_angle(p_of: Callable[[mpmath.mpf], mpmath.mpf], slope_of: Callable[[mpmath.mpf], mpmath.mpf],
                 angle: mpmath.mpf, s: mpmath.mpf) -> mpmath.mpf | None:
    """The angle whose p is ``s`` (the rounded p(``angle``)): Newton from ``angle`` at the current
    precision, independent of the inverse being judged. That inverse's own value at 40 digits was
    the reference before: a form that cancels (√(2√(4s² + 1) − 2)/2 for φ√(1 + φ²), corpus entry 9)
    gave 0 or divided by zero there at s = 10⁻³⁰⁰, and the emit ended in an internal error."""
    phi = angle
    try:
        for _ in range(4):  # from within 2⁻²⁴ (float32's rounding of s): 2⁻⁴⁸, 2⁻⁹⁶, 2⁻¹⁹²
            phi = phi - (p_of(phi) - s) / slope_of(phi)
    except (ZeroDivisionError, ValueError):
        return None
    return phi if mpmath.isfinite(phi) else None


def closed_angle_error(inverse: sp.Expr, p: sp.Expr, phi_max: float, dtype: type) -> float:
    """Worst error of the closed inverse φ(s) evaluated in ``dtype`` (ideal libm,
    :mod:`symrot.plan.evaluation`), in ulp of φ, beyond one rounding of s inside the formula (the
    condition number s/(φ p′) of φ(s)); the reference is the exact inverse of the rounded s.

    Measured from the smallest normal number (float32) or 10⁻³⁰⁰ to the edge of the range: a closed
    form that cancels (asinh printed as log(s + √(s² + 1)), Cardano's formula) loses every digit
    for small s or far out, and must not be printed (issue 16)."""
    epsilon = float(np.finfo(dtype).eps)
    smallest = 1e-300 if dtype is np.float64 else float(np.finfo(np.float32).tiny) * 16
    end = min(phi_max, 4 * math.pi)
    angles = np.concatenate([log_grid(smallest, end * (1 - 1e-6), GRID_POINTS),
                             end * (1 - log_grid(0.25, 1e-6, EDGE_POINTS))])
    model = model_function(inverse, [S])
    with mpmath.workdps(40):
        p_of = sp.lambdify(PHI, p, modules=[mpmath_namespace(), "mpmath"])
        slope_of = sp.lambdify(PHI, sp.diff(p, PHI), modules=[mpmath_namespace(), "mpmath"])
        worst = 0.0
        for angle in angles:
            s = dtype(float(p_of(mpmath.mpf(float(angle)))))
            if not np.isfinite(s) or s == 0:
                continue
            value = float(model(s))
            exact = _exact_angle(p_of, slope_of, mpmath.mpf(float(angle)), mpmath.mpf(float(s)))
            if exact is None or exact == 0:
                continue
            if not math.isfinite(value):
                return math.inf
            slope = slope_of(exact)
            condition = float(abs(mpmath.mpf(float(s)) / (exact * slope))) if slope != 0 else math.inf
            error = float(abs(mpmath.mpf(value) - exact) / abs(exact)) / epsilon
            worst = max(worst, error - min(condition, 1e300))  # one rounding of s inside is allowed
    return worst


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


def remember_plan(plan: EvaluationPlan) -> None:
    """Let :func:`evaluation_plan` return ``plan`` for its p and name in this process instead of
    computing it: for a caller that kept the plan of an earlier run (``symrot.cli.plan_cache``)."""
    _GIVEN_PLANS[(plan.p, plan.name)] = plan


def evaluation_plan(derivation: Derivation, name: str) -> EvaluationPlan:
    """The plan of every coefficient of ``derivation`` in float64 and float32."""
    given = _GIVEN_PLANS.get((derivation.p, name))
    return given if given is not None else _plan_for(derivation.p, name)
