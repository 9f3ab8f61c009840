"""The vanishing factor of a pole written through s = |p|: candidate forms next to a pole edge.

When the validity range ends by p → ∞ (Section 3.4) at a simple zero of a factor f of p's
denominator, p = N(φ)/(D(φ)·f(φ)), every coefficient that contains f (or a sum that is a multiple of
f) loses digits next to φ_max when it is evaluated from the rounded angle φ̂: f(φ̂) has the absolute
error f′·δφ ≈ ε·φ_max but the size of f → 0, so its relative error grows as 1/(φ_max − φ). For
p = φ/(1 − φ²/10), p′ = (10φ² + 100)/(φ² − 10)² is 10⁶ ulp off at φ_max − 10⁻⁶, and the domain
sweep (:mod:`symrot.plan.domain`) ended the range at |p|² = 2³² (NaN from φ_max − 4·10⁻⁴).

When p → ∞ like a logarithm, p = A + B·atanh(u) with u(φ_max) = 1, the factor 1 − u² of p′ and
of the coefficients built from it vanishes the same way (:func:`_logarithmic_pole`); so it does
where p = A + B·asin(u) stays finite and p′ → ∞ at u = ±1 (:func:`_arcsine_edge`).

The backends have s = |p| as rounded input, so f = N/(D·s) is available to a few ulp wherever N and
D are away from zero (for the logarithm, f = (1 + u)² exp(−2 (s − A)/B)): :func:`with_pole_factor`
writes f, and every sum in a form that is a polynomial multiple of f, through it, as one bounded
factor (:class:`symrot.core.functions.BoundedPower`: SymPy would merge (φ/s)³ with the form's other
powers of s into φ³/s⁵, which overflows float32 next to the pole while the value does not). The
call atanh(u) or asin(u) itself, whose slope is infinite at the edge, becomes (s − A)/B. The plan
measures those forms beside the others (:func:`symrot.plan.branches.plan_branch`) and takes them where they
are more accurate.
"""

from __future__ import annotations

from collections.abc import Callable
from functools import lru_cache
from typing import NamedTuple

import mpmath
import sympy as sp
from sympy.polys.polyerrors import BasePolynomialError

from symrot.core.functions import BoundedPower, RealCbrt, mpmath_namespace
from symrot.core.parsing import PHI
from symrot.core.timeouts import bounded
from symrot.plan.algebraic import S

ZERO_DIGITS = 50
"""Precision at which a factor is tested for a zero at φ_max."""
ROOT_DISTANCE = 1e-9
"""A factor's root found from the float φ_max must lie this close to it (relative)."""
MAX_DIVISIONS = 4
"""Largest multiplicity of f divided out of one sum ((φ² − 10)² = φ⁴ − 20φ² + 100 needs 2)."""
MAX_POLE_ORDER = 3
"""Largest order m of the pole, p = N/(D·f^m), whose f is written through s as (N/(D·s))^(1/m)."""
MAX_MULTIPLE = 4
"""Largest multiple n of the factor's angle whose sin(naφ), cos(naφ) are expanded."""
DIVISION_OPS = 120
"""Largest sum (``count_ops``) that is tried for division by f: a size cap, not a time."""

_QUOTIENTS = {
    sp.tan: lambda a: sp.sin(a) / sp.cos(a),
    sp.cot: lambda a: sp.cos(a) / sp.sin(a),
    sp.sec: lambda a: 1 / sp.cos(a),
    sp.csc: lambda a: 1 / sp.sin(a),
    sp.tanh: lambda a: sp.sinh(a) / sp.cosh(a),
    sp.coth: lambda a: sp.cosh(a) / sp.sinh(a),
    sp.sech: lambda a: 1 / sp.cosh(a),
    sp.csch: lambda a: 1 / sp.sinh(a),
}


class PoleFactor(NamedTuple):
    """p = N/(D·f) with f(φ_max) = 0 (simple): ``factor`` f and ``through_s`` = N/(D·s). For
    p = A + B·F(u) with F = atanh, asin or acos (the edge is u² = 1), also the ``call`` F(u) and
    ``call_through_s`` = (s − A)/B."""

    factor: sp.Expr
    through_s: sp.Expr
    phi_max: mpmath.mpf
    call: sp.Expr | None = None
    call_through_s: sp.Expr | None = None


def as_quotients(expr: sp.Expr) -> sp.Expr:
    """tan, cot, sec, csc and their hyperbolic kin written as quotients of sin, cos (sinh, cosh)."""
    return expr.replace(lambda z: type(z) in _QUOTIENTS, lambda z: _QUOTIENTS[type(z)](z.args[0]))


@lru_cache(maxsize=64)
def pole_factor(p: sp.Expr, phi_max: float) -> PoleFactor | None:
    """The :class:`PoleFactor` of p at ``phi_max`` when p → ∞ there through one simple zero of a
    factor of its denominator (written as a quotient, :func:`as_quotients`), else None."""
    if not mpmath.isfinite(phi_max) or phi_max <= 0:
        return None
    tangent = _tangent_pole(p, phi_max) or _gudermannian_pole(p, phi_max)
    if tangent is not None:
        return tangent
    quotient = bounded(2.0, None, lambda: sp.together(as_quotients(p)))
    if quotient is None:
        return None
    numerator, denominator = sp.fraction(quotient)
    if not denominator.has(PHI):
        return _logarithmic_pole(p, phi_max) or _log_pole(p, phi_max) or _arcsine_edge(p, phi_max)
    try:  # a denominator that is not a polynomial in its calls: √(1 + φ²) of φ/√(1 + φ²)
        factored = bounded(2.0, None, sp.factor_list, denominator)
    except BasePolynomialError:
        return None
    if factored is None:
        return None
    constant, factors = factored
    with mpmath.workdps(ZERO_DIGITS):
        roots = {f: (_root_near(f, phi_max), m) for f, m in factors if f.has(PHI)}
        vanishing = [(f, root, m) for f, (root, m) in roots.items() if root is not None]
        if not vanishing:
            return _logarithmic_pole(p, phi_max) or _arcsine_edge(p, phi_max)
        if len(vanishing) != 1 or vanishing[0][2] > MAX_POLE_ORDER:
            return None
        factor, root, order = vanishing[0]
        rest = constant * sp.Mul(*(f**m for f, m in factors if f != factor))
        if _value(numerator / rest, root) in (None, 0):
            return None  # 0/0 at φ_max: not a pole of this factor
        slope = _value(sp.diff(factor, PHI), root)
        if slope in (None, 0):
            return None
    return PoleFactor(factor, _root_of_order(numerator / (rest * S), order, slope), root)


def _root_of_order(power: sp.Expr, order: int, slope: mpmath.mpf) -> sp.Expr:
    """f from f^order = ``power`` (= N/(D·s)) below the pole, where f has the sign opposite to its
    ``slope`` f′(φ_max): p = tan φ + tan³φ/3 = N/(D cos³φ) has f = cos φ = ∛(N/(D·s))."""
    if order == 1:
        return power
    if order == 3:
        return RealCbrt(power)
    return (-1 if slope > 0 else 1) * sp.sqrt(power)


class _LinearCall(NamedTuple):
    """p = rest + weight·call for the one ``call`` of an inverse function, its edge where the
    ``factor`` 1 − u² of p′ vanishes (u the call's argument), and that edge's angle."""

    call: sp.Expr
    weight: sp.Expr
    rest: sp.Expr
    factor: sp.Expr
    root: mpmath.mpf


def _linear_call(p: sp.Expr, functions: tuple[type[sp.Function], ...],
                 vanishing: Callable[[sp.Expr], sp.Expr] | None, phi_max: float) -> _LinearCall | None:
    """p linear in the one call of ``functions`` whose 1 − u² (or ``vanishing``(u), a factor of it)
    is zero at ``phi_max`` (other calls go into the rest), with the weight and rest finite there
    (the weight nonzero), else None."""
    calls = sorted((call for call in p.atoms(*functions) if call.has(PHI)), key=sp.default_sort_key)
    factors = {call: sp.expand(1 - call.args[0] ** 2) for call in calls}
    with mpmath.workdps(ZERO_DIGITS):
        roots = [(call, _root_near(factor if vanishing is None else vanishing(call.args[0]), phi_max))
                 for call, factor in factors.items()]
    edges = [(call, root) for call, root in roots if root is not None]
    if len(edges) != 1:  # other calls (asin(φ/4) beside the edge of asin(φ/3)) belong to A
        return None
    call, root = edges[0]
    found = _weight_and_rest(p, call, root)
    if found is None:
        return None
    return _LinearCall(call, found[0], found[1], factors[call], root)


def _weight_and_rest(p: sp.Expr, call: sp.Expr, root: mpmath.mpf) -> tuple[sp.Expr, sp.Expr] | None:
    """(B, A) with p = A + B·call, both finite at ``root`` and B nonzero there, else None."""
    level = sp.Dummy("L")
    linear = p.xreplace({call: level})
    if not linear.is_polynomial(level) or sp.degree(linear, level) != 1:
        return None
    weight, rest = sp.diff(linear, level), linear.subs(level, 0)
    with mpmath.workdps(ZERO_DIGITS):
        if _value(weight, root) in (None, 0) or _value(rest, root) is None:
            return None
    return weight, rest


def _tangent_pole(p: sp.Expr, phi_max: float) -> PoleFactor | None:
    """p = A + B·tan(aφ) with cos(aφ_max) = 0 (the one tangent whose cosine vanishes there, A and B
    finite, B nonzero): f = cos(aφ) = B sin(aφ)/(s − A). The quotient route N/(D·s) keeps A·cos(aφ)
    from the rounded angle inside N: for 8 sinh(φ) cosh(2φ/3)/11 + 9 tan(2φ/3)/(22(3φ²/4 + 1))
    (hypothesis row 94) det H was 291 ulp off at |p|² = 2³², where the range ended. s − A loses
    digits only where B tan(aφ) is small beside A, far from the pole; the plan measures both."""
    with mpmath.workdps(ZERO_DIGITS):
        roots = {call: _root_near(sp.cos(call.args[0]), phi_max) for call in p.atoms(sp.tan) if call.has(PHI)}
    vanishing = [(call, root) for call, root in roots.items() if root is not None]
    if len(vanishing) != 1:
        return None
    call, root = vanishing[0]
    found = _weight_and_rest(p, call, root)
    if found is None:
        return None
    weight, rest = found
    return PoleFactor(sp.cos(call.args[0]), weight * sp.sin(call.args[0]) / (S - rest), root)


def _gudermannian_pole(p: sp.Expr, phi_max: float) -> PoleFactor | None:
    """p = A + B·asinh(tan(aφ)) with cos(aφ_max) = 0 (the inverse Gudermannian function: p → ∞ like
    a logarithm, corpus entry 46): f = cos(aφ), the factor of p′ = A′ + B′ asinh(tan aφ) + aB/cos(aφ).
    Through s, tan(aφ) = sinh((s − A)/B), so f = 1/cosh((s − A)/B), whose relative error is that of
    (s − A)/B times tanh of it, a few ε; from the rounded φ̂, f loses ε φ_max/(φ_max − φ) (the
    derivatives of asinh(tan φ) were 6·10⁵ ulp off at π/2 − 10⁻⁶). The call itself is (s − A)/B.

    atanh(sin(aφ)) is the same function on |aφ| < π/2 and is taken the same way: as a logarithmic
    pole (f = 1 − sin²(aφ)) it left cos(aφ) = 1/p′ of the coefficients in the rounded φ̂, and the
    domain of atanh(sin φ) ended at |p| = 5.02 (φ = 1.5576 of π/2) in both precisions."""
    calls = [call for call in p.atoms(sp.asinh, sp.atanh) if call.has(PHI)
             and isinstance(call.args[0], sp.tan if isinstance(call, sp.asinh) else sp.sin)]
    with mpmath.workdps(ZERO_DIGITS):
        roots = [(call, _root_near(sp.cos(call.args[0].args[0]), phi_max)) for call in calls]
        edges = [(call, root) for call, root in roots if root is not None]
        if len(edges) != 1:
            return None
        call, root = edges[0]
        found = _weight_and_rest(p, call, root)
    if found is None:
        return None
    weight, rest = found
    level = (S - rest) / weight
    return PoleFactor(sp.cos(call.args[0].args[0]), 1 / sp.cosh(level), root, call, level)


def _logarithmic_pole(p: sp.Expr, phi_max: float) -> PoleFactor | None:
    """p = A + B·atanh(u) with u(φ_max) = 1 (p → ∞ like a logarithm): f = 1 − u², the factor that
    vanishes in p′ = A′ + B′ atanh(u) + B u′/(1 − u²) and in the coefficients built from it, written
    through s as f = (1 + u)² exp(−2 (s − A)/B) (from 1 − u = (1 + u) e^(−2 atanh u)). Its relative
    error is twice the absolute error of (s − A)/B, a few ε wherever B is not small; f from the
    rounded φ loses ε φ_max/(φ_max − φ) (10⁵ ulp of det H for atanh(φ/2) terms at 2 − 10⁻⁶)."""
    found = _linear_call(p, (sp.atanh,), lambda u: 1 - u, phi_max)
    if found is None:
        return None
    inner = found.call.args[0]
    through_s = (1 + inner) ** 2 * sp.exp(-2 * (S - found.rest) / found.weight)
    return PoleFactor(1 - inner**2, through_s, found.root, found.call, (S - found.rest) / found.weight)


def _log_pole(p: sp.Expr, phi_max: float) -> PoleFactor | None:
    """p = A + B·log(N/D) with a simple zero of D (or of N) at φ_max: atanh written as a logarithm,
    log((1 + φ/2)/(1 − φ/2)) (corpus entry 21). f = D is N·exp(−(s − A)/B) through s (N·exp((s − A)/B)
    when N vanishes), the factor of p′ = B (N′/N − D′/D); the call itself is (s − A)/B."""
    calls = [call for call in p.atoms(sp.log) if call.has(PHI)]
    if len(calls) != 1:
        return None
    call = calls[0]
    fraction = bounded(2.0, None, lambda: sp.fraction(sp.together(call.args[0])))
    if fraction is None:
        return None
    numerator, denominator = fraction
    with mpmath.workdps(ZERO_DIGITS):
        roots = [(part, _root_near(part, phi_max)) for part in (denominator, numerator) if part.has(PHI)]
        edges = [(part, root) for part, root in roots if root is not None]
        if len(edges) != 1 or _value(sp.diff(edges[0][0], PHI), edges[0][1]) in (None, 0):
            return None  # no edge of this call at φ_max, or not a simple zero
        factor, root = edges[0]
        found = _weight_and_rest(p, call, root)
    if found is None:
        return None
    weight, rest = found
    level = (S - rest) / weight
    other = numerator if factor is denominator else denominator
    through_s = other * sp.exp(-level if factor is denominator else level)
    return PoleFactor(factor, through_s, root, call, level)


def _arcsine_edge(p: sp.Expr, phi_max: float) -> PoleFactor | None:
    """p = A + B·asin(u) (or acos(u)) with u(φ_max)² = 1: p stays finite, but p′ = A′ + B′ asin(u)
    + B u′/√(1 − u²) → ∞, and f = 1 − u², in p′ and the coefficients built from it, loses digits
    from the rounded φ̂ as a pole's factor does (hypothesis row 42, 4 cosh(3φ/4) asin(3φ/4)/3:
    H 54 ulp off at 4/3 − 10⁻⁶). Through s, asin(u) = (s − A)/B, so f = cos²((s − A)/B)
    (sin² for acos), whose error is that of (s − A)/B, next to π/2 (0): as conditioned as μ."""
    found = _linear_call(p, (sp.asin, sp.acos), None, phi_max)
    if found is None:
        return None
    angle = (S - found.rest) / found.weight
    through_s = (sp.cos(angle) if isinstance(found.call, sp.asin) else sp.sin(angle)) ** 2
    return PoleFactor(found.factor, through_s, found.root, found.call, angle)


def _value(expr: sp.Expr, phi: mpmath.mpf) -> mpmath.mpf | None:
    """expr at φ (current mpmath precision), None where it cannot be evaluated (or has s in it)."""
    if expr.free_symbols - {PHI}:
        return None
    try:
        value = sp.lambdify(PHI, expr, modules=[mpmath_namespace(), "mpmath"])(phi)
    except (ZeroDivisionError, ValueError, OverflowError, TypeError):
        return None
    return value if mpmath.isfinite(value) else None


def _root_near(factor: sp.Expr, phi_max: float) -> mpmath.mpf | None:
    """The zero of ``factor`` next to the float ``phi_max`` (Newton at the current precision), or None."""
    function = sp.lambdify(PHI, factor, modules=[mpmath_namespace(), "mpmath"])
    try:
        root = mpmath.findroot(function, mpmath.mpf(phi_max))
    except (ValueError, ZeroDivisionError, OverflowError, TypeError):
        return None
    if abs(root - phi_max) > ROOT_DISTANCE * phi_max:
        return None
    return root


def with_pole_factor(form: sp.Expr, pole: PoleFactor) -> sp.Expr:
    """``form`` with the pole's factor f, and every sum that is f^k times a polynomial quotient,
    written through s (f = N/(D·s)), and the edge's call F(u) as (s − A)/B (3 sin φ/(2 cos(φ/4)
    atanh(3φ/2)) of hypothesis row 88 becomes sin φ/s); a form with none of them is returned as it
    is. For f = cos(aφ) (or sin(aφ)), the multiples sin(naφ), cos(naφ) (n ≤ :data:`MAX_MULTIPLE`)
    that vanish with it are first expanded into powers of f: for p = φ/cos(φ/4),
    sin(φ/2) = 2 sin(φ/4) cos(φ/4) next to the pole at 2π, where sin(φ/2) from φ̂ has lost as many
    digits as f."""
    quotients = _expanded_multiples(as_quotients(form), pole)
    rewritten = _rewrite(quotients, pole)
    return form if rewritten == quotients else rewritten


def _expanded_multiples(expr: sp.Expr, pole: PoleFactor) -> sp.Expr:
    if not isinstance(pole.factor, (sp.sin, sp.cos)):
        return expr
    base = pole.factor.args[0]
    angle = sp.Dummy("angle")

    def multiple(call: sp.Expr) -> int | None:
        ratio = sp.simplify(call.args[0] / base)
        if ratio.is_Integer and 2 <= ratio <= MAX_MULTIPLE:
            with mpmath.workdps(ZERO_DIGITS):
                value = _value(call, pole.phi_max)
            if value is not None and abs(value) < mpmath.mpf(10) ** (10 - ZERO_DIGITS):
                return int(ratio)
        return None

    return expr.replace(lambda z: isinstance(z, (sp.sin, sp.cos)) and multiple(z) is not None,
                        lambda z: sp.expand_trig(type(z)(multiple(z) * angle)).subs(angle, base))


def _rewrite(expr: sp.Expr, pole: PoleFactor) -> sp.Expr:
    if expr == pole.factor:
        return BoundedPower(pole.through_s, 1)
    if pole.call_through_s is not None and _is_the_call(expr, pole.call):
        return pole.call_through_s
    if not expr.args or not expr.has(PHI):
        return expr
    rebuilt = expr.func(*(_rewrite(arg, pole) for arg in expr.args))
    if expr.is_Add and rebuilt == expr:
        return _divided(expr, pole)
    return rebuilt


def _is_the_call(expr: sp.Expr, call: sp.Expr | None) -> bool:
    """``expr`` is the edge's ``call``; for a logarithm, also when SymPy wrote its argument in
    another form (log((φ/2 + 1)/(1 − φ/2)) becomes log(−(φ + 2)/(φ − 2)) in sin φ/p)."""
    if expr == call or (call is not None and expr == as_quotients(call)):  # asinh(sin aφ/cos aφ)
        return True
    if not (isinstance(call, sp.log) and isinstance(expr, sp.log) and expr.has(PHI)):
        return False
    return bool(bounded(1.0, None, lambda: sp.cancel(expr.args[0] / call.args[0])) == 1)


def _divided(total: sp.Expr, pole: PoleFactor) -> sp.Expr:
    """A sum that vanishes at φ_max as quotient · (N/(D·s))^k when it is f^k times a polynomial."""
    if sp.count_ops(total) > DIVISION_OPS:
        return total
    with mpmath.workdps(ZERO_DIGITS):
        value = _value(total, pole.phi_max)
    if value is None or abs(value) > mpmath.mpf(10) ** (10 - ZERO_DIGITS):
        return total
    quotient, power = _repeatedly_divided(total, pole.factor)
    if power == 0:
        divided = _divided_through_base_angle(total, pole)
        return divided if divided != total else _divided_through_cofunction(total, pole)
    return quotient * BoundedPower(pole.through_s, power)


def _divided_through_cofunction(total: sp.Expr, pole: PoleFactor) -> sp.Expr:
    """A vanishing sum that is a polynomial in the cofunction g of f = cos(a) (g = sin a; for
    f = sin(a), g = cos a), which is σ = ±1 at φ_max, written through f²: P(g) = (g − σ)^k·Q(g) and
    g − σ = −f²/(g + σ) (g² + f² = 1), so P = Q·(−1/(g + σ))^k·(N/(D·s))^(2k). SymPy writes
    1 − sin²(φ/4) as (sin(φ/4) − 1)(sin(φ/4) + 1), and the first factor, of size (2π − φ)²/32 next
    to the pole at 2π, lost every digit from the rounded angle in H⁻¹'s across-axis part of
    hypothesis row 1 (2 tan(φ/4) cosh(3φ/4) + …: 1.2·10⁴ ulp at |p|² = 2³², where the range ended)."""
    if not isinstance(pole.factor, (sp.sin, sp.cos)):
        return total
    argument = pole.factor.args[0]
    cofunction = sp.sin(argument) if isinstance(pole.factor, sp.cos) else sp.cos(argument)
    with mpmath.workdps(ZERO_DIGITS):
        value = _value(cofunction, pole.phi_max)
    if value is None or abs(abs(value) - 1) > mpmath.mpf(10) ** (10 - ZERO_DIGITS):
        return total
    sigma = sp.Integer(1 if value > 0 else -1)
    quotient, power = _repeatedly_divided(total, cofunction - sigma, cofunction)
    if power == 0:
        return total
    return quotient * (-1 / (cofunction + sigma)) ** power * BoundedPower(pole.through_s, 2 * power)


def _repeatedly_divided(total: sp.Expr, divisor: sp.Expr, *generators: sp.Expr) -> tuple[sp.Expr, int]:
    """(total/divisor^k, k) for the largest k ≤ :data:`MAX_DIVISIONS` that leaves no remainder, as
    polynomials in ``generators`` (SymPy's choice when none are given)."""
    quotient, power = total, 0
    while power < MAX_DIVISIONS:
        try:
            divided, remainder = sp.div(quotient, divisor, *generators)
        except (sp.PolynomialError, sp.GeneratorsNeeded, sp.CoercionFailed):
            break
        if remainder != 0 or divided == 0:
            break
        quotient, power = divided, power + 1
    return quotient, power


def _divided_through_base_angle(total: sp.Expr, pole: PoleFactor) -> sp.Expr:
    """A vanishing sum of sines and cosines of multiples of one base angle h, whose f = sin(mh) or
    cos(mh) is not a generator of it, as (sum/f)·(N/(D·s)): both written as polynomials in sin h,
    cos h (``expand_trig``) and the quotient cancelled. SymPy's simplification writes
    cos(3φ/2) = cos(φ/2)(2 cos φ − 1), so det H of 2 tan(3φ/2)/(3(3φ²/2 + 1)) has (2 cos φ − 1)⁴,
    which vanishes at the pole π/3 (hypothesis row 159; 8·10⁵ ulp at |p|² = 2³², where the range
    ended); the quotient is 1/cos(φ/2)."""
    if not isinstance(pole.factor, (sp.sin, sp.cos)):
        return total
    calls = total.atoms(sp.sin, sp.cos) | {pole.factor}
    multiples = [sp.nsimplify(call.args[0] / PHI) for call in calls]
    if not all(m.is_Rational and m != 0 for m in multiples):
        return total
    base = sp.Rational(sp.igcd(*(m.p for m in multiples)), sp.ilcm(*(m.q for m in multiples)))
    if max(abs(m / base) for m in multiples) > 2 * MAX_MULTIPLE:  # row 159 needs 6 (sin 3φ, h = φ/2)
        return total
    h = sp.Dummy("h")

    def in_base(expr: sp.Expr) -> sp.Expr:
        return sp.expand_trig(expr.replace(
            lambda z: isinstance(z, (sp.sin, sp.cos)) and z.has(PHI),
            lambda z: type(z)(sp.nsimplify(z.args[0] / PHI) / base * h)))

    ratio = bounded(2.0, None, lambda: sp.cancel(in_base(total) / in_base(pole.factor)))
    if ratio is None:
        return total
    quotient = ratio.subs(h, base * PHI)
    with mpmath.workdps(ZERO_DIGITS):
        value = _value(quotient, pole.phi_max)
    if value is None or value == 0:  # not a multiple of f after all
        return total
    return quotient * BoundedPower(pole.through_s, 1)
