"""Coefficients that are algebraic in x = |p|²: the branch-free entries of an evaluation plan.

When p(φ) has a closed inverse φ = c·F(s/k) (F ∈ {asin, atan, acos}, e.g. 4 atan(s/4)), a
coefficient c(φ) of eqs 16–26, 81–83 often becomes an algebraic function of x: for 4 tan(φ/4),
ν²/ε = 16(16 − x)/(16 + x)² (eq 34). The reduction works on the base angle θ = F(s/k): multiple
angles are expanded (``expand_trig``), half angles of θ replaced by their radicals (θ ∈ [0, π/2)
on the validity range, so the positive roots), products of radicals combined and their radicands
expanded (√(4 − √x)·√(4 + √x) → √(16 − x)).

An algebraic form is only *accepted* when it is accurate in floating point: it is evaluated in
float64 (:mod:`symrot.plan.evaluation`, identical on every machine) on a log grid of x from 10⁻³⁰⁰ to
the edge of the range and compared with the closed form at 30 digits. Forms whose radicals
cancel (1 − √(1 − x) near x = 0) are rationalized (``radsimp`` of the form or of its reciprocal)
and re-checked; a form that still fails is rejected and the coefficient gets a Taylor/closed-form
branch instead.
"""

from __future__ import annotations

import math
from functools import lru_cache

import mpmath
import numpy as np
import sympy as sp

from symrot.core.functions import BoundedPower, RealCbrt, mpmath_namespace
from symrot.core.parsing import PHI
from symrot.core.simplify import expands_beyond_the_cap
from symrot.core.timeouts import bounded
from symrot.plan.evaluation import log_grid, model_function

S = sp.Symbol("s", nonnegative=True)
X = sp.Symbol("x", nonnegative=True)
THETA = sp.Symbol("theta", positive=True)
ACCEPT_ULP = 3.0
"""Worst float64 error (ulp of max(|c|, |c(0)|)) for an algebraic form to be accepted."""
CHECK_POINTS = 48
UNBOUNDED_TOP = 1e40
"""Largest x checked when p is unbounded (p → ∞ at φ_max): |φ_max − φ| down to ~1e-18 for m tan(φ/m)."""
INVERSE_FUNCTIONS = (sp.asin, sp.atan, sp.acos)
REDUCTION_OPS = 300
"""Largest expansion (:func:`reduction_size`) that :func:`reduce_to_x` simplifies: the tangent
family's H⁻¹ coefficients expand to 200–300 operations and simplify in under a second; the raw
H⁻¹₂ of 5 tan(φ/5) expands to 478 and takes 3–14 s (and failed its accuracy check anyway)."""

REDUCTION_MULTIPLE = 12
"""Largest multiple n of the half base angle η (φ = 2cη for φ = c·F(s/k)) with sin/cos/tan(nη)
expanded for :func:`reduce_to_x`: the tangent family up to m = 6 reaches 12 (sin φ of 6 tan(φ/6)).
The operation count of the expansion does not predict the simplification's time: for tan(φ/20),
4 sin²(φ/2)/((tan²(φ/20) + 1)/20·tan²(φ/20)) expands to 289 operations (n = 20) and simplified in
34 s, past the 6 s nominal bound and, on a loaded machine, its 60 s safety bound, while the
283-operation H⁻¹ coefficient of 5 tan(φ/5) (n = 10) takes 0.9 s. Beyond the cap the coefficient
is planned as a measured branch instead."""


def base_angle(inverse: sp.Expr) -> tuple[sp.Expr, sp.Expr] | None:
    """(c, F(arg)) with φ(s) = c·F(arg), c rational, F an inverse trigonometric function."""
    coefficient, rest = inverse.as_coeff_Mul()
    if isinstance(rest, INVERSE_FUNCTIONS) and coefficient.is_Rational:
        return coefficient, rest
    return None


def _half_angle_radicals(expr: sp.Expr, half: sp.Expr) -> sp.Expr:
    rules = {sp.sin: sp.sqrt((1 - sp.cos(THETA)) / 2), sp.cos: sp.sqrt((1 + sp.cos(THETA)) / 2),
             sp.tan: sp.sin(THETA) / (1 + sp.cos(THETA))}
    return expr.replace(lambda z: type(z) in rules and z.args[0] == half, lambda z: rules[type(z)])


def tidy_radicals(expr: sp.Expr) -> sp.Expr:
    """Combine products of radicals and expand their radicands; factor the result."""
    combined = sp.powsimp(expr, force=True)
    combined = combined.replace(
        lambda z: isinstance(z, sp.Pow) and z.exp.is_Rational and not z.exp.is_Integer,
        lambda z: sp.Pow(sp.factor(sp.expand(z.base)), z.exp))
    return sp.factor(combined)


def _whole_multiples(expr: sp.Expr, angle: sp.Symbol) -> bool:
    """Whether every sin/cos/tan in ``expr`` has an argument k·``angle`` with k a whole number."""
    for atom in expr.atoms(sp.sin, sp.cos, sp.tan):
        k = sp.cancel(atom.args[0] / angle)
        if not k.is_Integer:
            return False
    return True


def has_radical(expr: sp.Expr) -> bool:
    """Whether ``expr`` has a power with a non-integer exponent (a square or cube root of s, …)."""
    return any(isinstance(e, sp.Pow) and not e.exp.is_Integer for e in sp.preorder_traversal(expr))


def has_nested_radical(expr: sp.Expr) -> bool:
    """Whether ``expr`` has a root of an expression with a root, such as √(√(4x + 1) + 1)."""
    return any(isinstance(e, sp.Pow) and not e.exp.is_Integer and has_radical(e.base)
               for e in sp.preorder_traversal(expr))


@lru_cache(maxsize=1024)
def expanded_in_s(closed: sp.Expr, inverse: sp.Expr) -> sp.Expr | None:
    """c(φ(s)) with multiple and half angles of the base angle expanded, before simplification;
    None when no reduction is attempted.

    Only an inverse built on an inverse trigonometric function can make sin/cos of φ algebraic in
    s (asinh, atanh, Cardano's radicals, the identity φ = s cannot): for those, no time is spent."""
    base = base_angle(inverse)
    if base is None and not inverse.has(*INVERSE_FUNCTIONS):
        return None
    if any(has_radical(call.args[0]) for call in inverse.atoms(*INVERSE_FUNCTIONS)):
        return None  # atan of Cardano's root (tan φ + tan³φ/3): 6 s per coefficient, never simpler
    eta = sp.Symbol("eta", positive=True)
    if base is not None and expands_beyond_the_cap(closed.subs(PHI, 2 * base[0] * eta), eta,
                                                   REDUCTION_MULTIPLE):
        return None  # sin(800 η) for cayley_m800: the expansion alone ran past 20 s

    def expand() -> sp.Expr:
        if base is None:
            return sp.expand_trig(closed.subs(PHI, inverse))
        factor, function = base
        in_theta = closed.subs(PHI, factor * THETA)
        if _whole_multiples(in_theta, THETA):
            # sin/cos(kθ) with whole k are polynomials in sin θ, cos θ: no half-angle radicals
            return sp.expand_trig(in_theta).subs(THETA, function)
        # φ = factor·θ; write θ = 2η so that half angles of θ are whole angles of η
        e = sp.expand_trig(closed.subs(PHI, 2 * factor * eta))
        e = _half_angle_radicals(e.subs(eta, THETA / 2), THETA / 2)
        return sp.expand_trig(e).subs(THETA, function)

    expanded: sp.Expr | None = bounded(2, None, expand)
    return expanded


@lru_cache(maxsize=1024)
def reduction_size(closed: sp.Expr, inverse: sp.Expr) -> int:
    """The work of reducing ``closed`` to x: the operation count of :func:`expanded_in_s` (0 when
    no reduction is attempted). Deterministic, unlike the time the simplification takes."""
    expanded = expanded_in_s(closed, inverse)
    return 0 if expanded is None else int(sp.count_ops(expanded))


def reduce_to_x(closed: sp.Expr, inverse: sp.Expr) -> sp.Expr | None:
    """c(φ(√x)) with trigonometry removed, or None.

    Which inputs are simplified is decided by size, not by time (reproducibility): an expansion
    of more than ``REDUCTION_OPS`` operations is not attempted; the time bound on the rest is
    only a safety net (:mod:`symrot.core.timeouts`)."""
    expanded = expanded_in_s(closed, inverse)
    if expanded is None or reduction_size(closed, inverse) > REDUCTION_OPS:
        return None
    if expanded.atoms(sp.Function):
        # a function of s left after the expansion (atan(s) in cos φ for φ = asin(atan(s)), the
        # inverse of tan(sin φ)): SymPy evaluates trig(inverse trig) itself, and no simplification
        # turns what is left algebraic; simplify took 0.5-4 s on each of 22 such coefficients
        return None

    def reduce() -> sp.Expr | None:
        if _indeterminate_at_zero(tidy_radicals(sp.factor(expanded).subs(S, sp.sqrt(X)))):
            return None
        return tidy_radicals(sp.simplify(expanded).subs(S, sp.sqrt(X)))

    reduced: sp.Expr | None = bounded(6, None, reduce)
    if reduced is None or reduced.free_symbols - {X}:
        return None
    if any(isinstance(a, sp.Function) for a in sp.preorder_traversal(reduced)):
        return None
    if reduced.has(sp.sqrt(X)):
        return None
    if _indeterminate_at_zero(reduced):
        return None
    return reduced


def _indeterminate_at_zero(reduced: sp.Expr) -> bool:
    """A form in x that is not finite at x = 0 as written (0/0 where a radical cancels:
    √(x + 25) − 5 ~ x/10), which the plan cannot use.

    :func:`reduce_to_x` asks it of the factored expansion first (factor cancels the common
    polynomial factors in s and the radicals) and simplifies only what passes: of the 92 forms of
    the 14 named parameterizations that factoring leaves 0/0, simplification made none usable, and
    simplifying them took 8.1 of the 12.6 s spent simplifying (2.9 s for 5 tan(φ/5) alone)."""
    return not reduced.subs(X, 0).is_finite


def _check_grid(p_max: float) -> np.ndarray:
    top = (p_max * (1 - 1e-9)) ** 2 if math.isfinite(p_max) else UNBOUNDED_TOP
    return np.concatenate([[0.0], log_grid(1e-300, top, CHECK_POINTS)])


def worst_ulp(candidate: sp.Expr, closed: sp.Expr, inverse: sp.Expr, p_max: float) -> float:
    """Worst float64 error of ``candidate`` (ideal-libm model, :mod:`symrot.plan.evaluation`) against
    ``closed`` at φ(√x), 30 digits."""
    function = model_function(candidate, [X])
    reference = sp.lambdify(PHI, closed, modules=[mpmath_namespace(), "mpmath"])
    angle = sp.lambdify(S, inverse, modules=[mpmath_namespace(), "mpmath"])
    value_at_zero = candidate.subs(X, 0)
    if not (value_at_zero.is_number and value_at_zero.is_finite):
        return math.inf
    at_zero = abs(float(value_at_zero))
    worst = 0.0
    grid = _check_grid(p_max)
    digits = 30 + int(math.log10(grid[-1])) // 2 + 10  # φ is within ~1/√x of a pole
    with mpmath.workdps(digits):
        for x in grid:
            value = float(function(np.float64(x)))
            phi = angle(mpmath.sqrt(mpmath.mpf(x)))
            try:
                exact = mpmath.mpf(value_at_zero) if x == 0 else reference(phi)
            except ZeroDivisionError:  # a removable singularity of the closed form on the grid
                continue
            scale = max(abs(float(exact)), at_zero, 1e-300)
            if not math.isfinite(value) or (x == 0 and value != float(value_at_zero)):
                return math.inf  # p = 0 must give exactly the identity's coefficients
            worst = max(worst, float(abs(mpmath.mpf(value) - exact)) / (scale * np.finfo(float).eps))
    return worst


@lru_cache(maxsize=1024)
def algebraic_in_x(closed: sp.Expr, inverse: sp.Expr, p_max: float) -> sp.Expr | None:
    """An accurate algebraic form of c(φ) in x, or None (see the module docstring)."""
    reduced = reduce_to_x(closed, inverse)
    if reduced is None:
        return None
    candidates = [reduced]
    # rationalized numerator or denominator; not of nested roots, where radsimp ran for minutes on
    # 28 operations (4/((4x + 1)^(1/4) (2 (4x + 1)^(1/4) + √2 √(√(4x + 1) + 1)) (√(4x + 1) + 1)),
    # a coefficient of tan(2φ)/2), past the safety bound: the emit failed
    makers = () if has_nested_radical(reduced) else (lambda e: sp.factor(sp.radsimp(e)),
                                                    lambda e: sp.factor(1 / sp.radsimp(1 / e)))
    for make in makers:
        alternative = bounded(4, None, make, reduced)
        if alternative is not None and alternative not in candidates and not alternative.has(sp.I):
            candidates.append(alternative)
    for candidate in candidates:
        if worst_ulp(candidate, closed, inverse, p_max) <= ACCEPT_ULP:
            return candidate
    return None


def bounded_powers(expr: sp.Expr) -> sp.Expr:
    """``expr`` with each power (k x + a)^-n, n ≥ 2, a, k > 0 written through a/(k x + a) ∈ (0, 1].

    For an unbounded p the tangent family's coefficients are rational in x with such denominators
    (Wiener–Milenkovic's det H = 4096/(x + 16)³, eq 24 with eq 34): (x + 16)³ overflows in float32
    from x = 2^42.7 although the value 2^-117 is a normal number, so every output of the module was
    NaN from φ = 2π − 7.6·10⁻⁶ (the domain sweep cut the range there). In a term c·N(x)/∏(k x + a)^n,
    one power of a denominator is kept for each degree of the polynomial numerator N (N/(k x + a)
    stays bounded) and the rest becomes c·a^-m·(a/(k x + a))^m (:class:`BoundedPower`): nothing
    then overflows before the value does. Terms of another shape are left as they are."""
    terms = []
    for term in sp.Add.make_args(expr):
        coefficient, product = term.as_coeff_Mul()
        factors = sp.Mul.make_args(product)
        powers = [(base, -int(exponent)) for base, exponent in (f.as_base_exp() for f in factors)
                  if exponent.is_Integer and exponent <= -2 and _positive_linear(base)]
        numerator = [f for f in factors if not any(f == base**-n for base, n in powers)]
        if not powers or not sp.Mul(*numerator).is_polynomial(X):
            terms.append(term)
            continue
        degree = sp.Poly(sp.Mul(*numerator), X).degree() if sp.Mul(*numerator).has(X) else 0
        for base, n in powers:
            kept = min(degree, n)
            degree -= kept
            constant = base.subs(X, 0)
            numerator.append(base**-kept)
            if n > kept:
                coefficient *= constant ** (kept - n)
                numerator.append(BoundedPower(constant / base, n - kept))
        terms.append(sp.Mul(coefficient, *numerator))  # one Mul: a number is not distributed over a sum
    return sp.Add(*terms)


def _positive_linear(base: sp.Expr) -> bool:
    """k x + a with rational k, a > 0 (so that a/(k x + a) ∈ (0, 1] for x ≥ 0)."""
    if not (base.is_Add and base.free_symbols == {X} and base.is_polynomial(X)):
        return False
    polynomial = sp.Poly(base, X)
    return polynomial.degree() == 1 and all(c.is_Rational and c > 0 for c in polynomial.all_coeffs())


@lru_cache(maxsize=1024)
def with_bounded_powers(expr: sp.Expr) -> sp.Expr:
    """:func:`bounded_powers` of an algebraic form when it is as accurate as the form (float64,
    ideal libm, against the exact rational value at 40 digits, on x from 0 to 10⁴⁰); else ``expr``."""
    rewritten = bounded_powers(expr)
    if rewritten == expr:
        return expr
    exact = sp.lambdify(X, expr, modules=[mpmath_namespace(), "mpmath"])
    epsilon = float(np.finfo(float).eps)
    worst = {}
    for form in (expr, rewritten):
        function = model_function(form, [X])
        errors = []
        with mpmath.workdps(40):
            for x in _check_grid(math.inf):
                reference = exact(mpmath.mpf(x))
                value = float(function(np.float64(x)))
                if not math.isfinite(value):
                    errors.append(math.inf)
                    continue
                errors.append(float(abs(value - reference) / max(abs(reference), 1e-300)) / epsilon)
        worst[form] = max(errors)
    return rewritten if worst[rewritten] <= max(ACCEPT_ULP, worst[expr]) else expr


D = sp.Symbol("d", nonnegative=True)
"""The complement d = p_max² − x, computed by the backends with compensated arithmetic."""


@lru_cache(maxsize=256)
def linear_scale(argument: sp.Expr) -> sp.Rational | None:
    """k when ``argument`` is s/k with k a positive rational, else None. ``sp.cancel``, not
    ``sp.simplify``: for atan(sinh s), the inverse of asinh(tan φ), simplify(s/sinh s) took 67 ms
    and the plan asked 800 times (54 of its 76 s)."""
    k = sp.cancel(S / argument)
    return sp.Rational(k) if k.is_Rational and k > 0 else None


def fold_complement(inverse: sp.Expr | None, p_max: float) -> sp.Rational | None:
    """p_max² when φ(s) = c·asin(s/k) with k² = p_max² rational (the sine family, eqs 31, 32, 36).

    There p′ → 0 at |p| = k (a fold): every quantity that vanishes or blows up there is a power of
    √(k² − x) = k cos(φ/c), and k² − x loses all its digits when computed from a rounded x. With
    d = k² − x accurate, those quantities keep their relative accuracy up to the edge of the range.
    """
    base = base_angle(inverse) if inverse is not None else None
    if base is None or not isinstance(base[1], sp.asin) or not math.isfinite(p_max):
        return None
    k = linear_scale(base[1].args[0])
    if k is None or abs(float(k) - p_max) > 1e-12 * p_max:
        return None
    return k**2


def with_complement(expr: sp.Expr, complement: sp.Rational) -> sp.Expr:
    """Replace every factor a·x + b with root x = complement by −a·d."""
    def is_linear_factor(e: sp.Expr) -> bool:
        if not (e.is_Add and e.free_symbols == {X}):
            return False
        poly = sp.Poly(e, X)
        return poly.degree() == 1 and -poly.all_coeffs()[1] / poly.all_coeffs()[0] == complement

    return expr.replace(is_linear_factor, lambda e: -sp.Poly(e, X).all_coeffs()[0] * D)


def closed_with_complement(closed: sp.Expr, inverse: sp.Expr, complement: sp.Rational) -> sp.Expr:
    """A closed form in φ with sin, cos, tan of the base angle φ/c replaced by s/k, √d/k, s/√d."""
    base = base_angle(inverse)
    assert base is not None
    k = sp.sqrt(complement)
    return _replace_base_trig(closed, PHI / base[0], S / k, sp.sqrt(D) / k)


def closed_with_base_angle(closed: sp.Expr, inverse: sp.Expr) -> sp.Expr:
    """For φ = c·atan(s/k) (the tangent family, eqs 33, 34, 36): tan(φ/c) = s/k, sin(φ/c) =
    s/√(k² + x), cos(φ/c) = k/√(k² + x), exactly. Near the pole φ/c → π/2, tan(φ/c) computed from
    a rounded φ loses ~1/δ of its digits; these forms lose none. Unchanged for other inverses."""
    base = base_angle(inverse)
    if base is None or not isinstance(base[1], sp.atan):
        return closed
    k = linear_scale(base[1].args[0])
    if k is None:
        return closed
    radius = sp.sqrt(k**2 + X)
    return _replace_base_trig(closed, PHI / base[0], S / radius, k / radius)


INVERSE_REWRITE_OPS = 16
"""Largest algebraic part (SymPy operation count after substitution) that :func:`with_inverse`
simplifies: trigsimp of such parts takes milliseconds, so the plan never depends on machine load."""


SIMPLIFIED_CALLS = (sp.sinh, sp.cosh, sp.tanh, RealCbrt, BoundedPower)
"""The calls a part of :func:`with_inverse` may have besides algebraic ones. trigsimp rewrites
hyperbolic functions of the inverse (cosh(asinh s) = √(1 + s²)) but leaves log, exp and the inverse
functions as they are: a part with one of them is split into its arguments, and the call itself is
left as it is (it is p, which :func:`symrot.plan.measurement.with_length` writes as s, or something
trigsimp does not rewrite). The parts of log((1 + φ/2)/(1 − φ/2)) that held p cost 0.2–0.3 s of
trigsimp each, 3 s of its 12 s emit."""


@lru_cache(maxsize=512)
def with_inverse(expr: sp.Expr, inverse: sp.Expr) -> sp.Expr:
    """``expr`` with every maximal part free of calls other than :data:`SIMPLIFIED_CALLS` but not
    of φ (p′, 1 − φ²/4 …) written through φ = φ(s) and trigsimp'ed when that removes φ from it:
    near an edge where p′ → ∞ (p = 2 asin(φ/2)), √(1 − φ²/4) recomputed from a rounded φ loses
    every digit, cos(s/2) none. Cached, as is each part (:func:`_part_with_inverse`): both
    precisions of a plan ask for the same forms, and the forms of one plan share most of their
    parts."""
    def rewrite(part: sp.Expr) -> sp.Expr:
        if not part.has(PHI) or part == PHI:
            return part
        if isinstance(part, sp.Function) and not isinstance(part, SIMPLIFIED_CALLS):
            return part  # sin, cos, tan: the backends' φ̂; log, asinh …: p (with_length) or left
        if not _has_other_calls(part):
            return _part_with_inverse(part, inverse)
        if isinstance(part, (sp.Add, sp.Mul)) and not part.has(sp.sin, sp.cos, sp.tan):
            # the terms or factors free of log, exp … as one part
            free = [a for a in part.args if not _has_other_calls(a)]
            rest = [rewrite(a) for a in part.args if _has_other_calls(a)]
            return part.func(rewrite(part.func(*free)), *rest)
        return part.func(*[rewrite(a) for a in part.args])

    return rewrite(expr)


def _has_other_calls(part: sp.Expr) -> bool:
    return any(not isinstance(call, SIMPLIFIED_CALLS) for call in part.atoms(sp.Function))


@lru_cache(maxsize=4096)
def _part_with_inverse(part: sp.Expr, inverse: sp.Expr) -> sp.Expr:
    """One part of :func:`with_inverse`: φ → φ(s) and trigsimp, kept only when small and real."""
    substituted = part.xreplace({PHI: inverse})
    if sp.count_ops(substituted) > INVERSE_REWRITE_OPS:
        return part
    simplified = sp.powdenest(sp.trigsimp(substituted), force=True)
    return simplified if not simplified.has(sp.I, sp.nan, sp.zoo) else part


def _replace_base_trig(closed: sp.Expr, angle: sp.Expr, sine: sp.Expr, cosine: sp.Expr) -> sp.Expr:
    rules = {sp.sin(angle): sine, sp.cos(angle): cosine, sp.tan(angle): sine / cosine,
             1 - 2 * sp.sin(angle / 2) ** 2: cosine}  # the half-angle form of cos
    return closed.xreplace(rules)


def angle_with_complement(inverse: sp.Expr) -> sp.Expr:
    """c·asin(s/k) as c·atan2(s, √d): accurate up to the fold s = k."""
    base = base_angle(inverse)
    assert base is not None
    return base[0] * sp.atan2(S, sp.sqrt(D))
