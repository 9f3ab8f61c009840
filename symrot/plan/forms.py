"""Candidate closed forms of a coefficient: rewritings that keep it accurate (half angles, the
complement near a half turn, the Gudermannian, the closed inverse φ(s) of eq 12 where p(φ) has one),
with the measured error of a closed inverse."""

from __future__ import annotations

import math
from collections.abc import Callable

import mpmath
import numpy as np
import sympy as sp
from sympy.core.traversal import bottom_up

from symrot.core.functions import RealCbrt, mpmath_namespace
from symrot.core.parsing import PHI
from symrot.core.timeouts import bounded
from symrot.plan.algebraic import (
    S,
)
from symrot.plan.algebraic import X as X  # re-exported: the symbol of the coefficients' variable x = |p|²
from symrot.plan.evaluation import (
    log_grid,
    model_function,
)
from symrot.plan.measurement import (
    EDGE_POINTS,
    GRID_POINTS,
)
from symrot.plan.newton_start import FarStart as FarStart


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
