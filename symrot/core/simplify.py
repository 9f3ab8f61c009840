"""Bounded simplification: present derived scalar functions in their simplest form.

``sympy.simplify`` can run for minutes on these expressions. The strategy here cannot:

1. *Base-angle reduction.* Every trigonometric argument that is a rational multiple of φ is
   written as n·θ with θ = φ/L (L the lcm of the denominators), expanded to polynomials in
   s = sin θ, c = cos θ, and numerator and denominator are reduced modulo s² + c² − 1 before
   cancelling. Non-trigonometric functions (e.g. the real cube root of eq 35) become opaque
   symbols so that powers of them cancel, each with a name of its own (SymPy orders polynomial
   generators by name, so shared names made the result depend on the string hash seed). This is
   plain polynomial algebra; only square-free factors that are not plainly irreducible are
   factored.
2. A time-bounded ``trigsimp`` of the candidates, which contracts 2cos²θ − 1 into cos 2θ.

The shortest candidate (by operation count, then by printed length) wins. Which inputs a step
is tried on is decided by size (``BASE_ANGLE_OPS``, ``TRIGSIMP_OPS`` operations, the largest
multiple ``BASE_ANGLE_MULTIPLE`` of the base angle, the terms and degree ``REDUCTION_TERMS``,
``REDUCTION_DEGREE`` of the reduced polynomials), so that the result does not depend on the
machine's speed; every step also has a time bound as a safety net (:mod:`symrot.core.timeouts`), whose
expiry is an error (deterministic mode), never a silent change of the result.
"""

from __future__ import annotations

from functools import lru_cache, reduce
from math import lcm

import sympy as sp
from sympy.functions.elementary.hyperbolic import HyperbolicFunction

from symrot.core.parsing import PHI
from symrot.core.timeouts import bounded

_TRIG = (sp.sin, sp.cos, sp.tan)
BASE_ANGLE_OPS = 150
"""Largest input (operation count) of the base-angle reduction; the derivations of the named
parameterizations reach 47 (≤ 0.05 s)."""
BASE_ANGLE_MULTIPLE = 24
"""Largest n with sin(nθ) or cos(nθ) expanded by the base-angle reduction: its time grows steeply
with n (0.11 s at n = 12, 0.72 s at 40, 4.2 s at 100, past 5 s at 800 for the higher-order Cayley
family, cayley_m800); the named parameterizations reach 12 (sine_m12, tangent_m12)."""
REDUCTION_TERMS = 40
REDUCTION_DEGREE = 40
"""Largest reduced numerator or denominator (terms, total degree in the sine and cosine of the
base angle and the opaque symbols) that the base-angle reduction cancels and factors. The named
parameterizations reach 11 terms; the factoring is what grows: for tan(2φ)cosh(φ/3)/4 +
3 sin(2φ/3)/(4(φ² + 1)) polynomials of 44–490 terms (φ and cosh(φ/3) as further generators) ran
past the 5 s safety bound, and for tan(φ/3) + 8 tan(3φ/4)/9 one of 30 terms and degree 64 took
over 0.5 s, while 19 terms of degree 36 took 0.48 s."""
TRIGSIMP_OPS = 40
"""Largest trigonometric sum factor (operation count) given to ``trigsimp``; the named
parameterizations reach 24 (≤ 0.1 s)."""


def _vanishing_denominators(expr: sp.Expr) -> int:
    """Number of divisors that vanish at φ = 0: each hides a 0/0 form from the reader."""
    count = 0
    for power in expr.atoms(sp.Pow):
        if power.exp.is_negative and power.base.has(PHI):
            at_zero: sp.Expr | None = bounded(0.2, None, power.base.subs, PHI, 0)
            count += bool(at_zero is not None and at_zero.is_zero)
    return count


def complexity(expr: sp.Expr) -> tuple[int, int, int]:
    """Ranking key: size, with sums and hidden 0/0 quotients penalised, then printed length."""
    sums = sum(1 for node in sp.preorder_traversal(expr) if isinstance(node, sp.Add))
    size = int(sp.count_ops(expr, visual=False)) + sums + 3 * _vanishing_denominators(expr)
    return (size, sums, _printed_length(expr))


def _printed_length(expr: sp.Expr) -> int:
    """len(str(expr)); an integer beyond Python's 4300-digit str limit counts by its bits."""
    try:
        return len(str(expr))
    except ValueError:
        numbers = expr.atoms(sp.Rational)
        return sum(int(max(abs(n.p), n.q).bit_length() * 0.302) + 2 for n in numbers) + sp.count_ops(expr)


def _trig_multiples(expr: sp.Expr) -> list[sp.Rational] | None:
    """Rational multiples k with trig(k φ) in expr, or None if some argument is not of that form."""
    multiples = []
    for atom in expr.atoms(*_TRIG):
        k = sp.simplify(atom.args[0] / PHI) if atom.args[0].has(PHI) else None
        if k is None or not k.is_Rational:
            return None
        multiples.append(sp.Rational(k))
    return multiples


def expands_beyond_the_cap(expr: sp.Expr, angle: sp.Expr, cap: int = BASE_ANGLE_MULTIPLE) -> bool:
    """Whether some sin/cos/tan(k·``angle``) of ``expr`` has |k| > ``cap``: expanding it as a
    polynomial in the sine and cosine of ``angle`` is not attempted (a size, not a time)."""
    for atom in expr.atoms(*_TRIG):
        k = atom.args[0] / angle
        if k.is_Rational and abs(k) > cap:
            return True
    return False


def _numbered_dummy(name: str, number: int) -> sp.Dummy:
    """A Dummy named ``name`` + ``number``: opaque symbols that share one name tie in the order
    SymPy's polynomial code gives its generators (``_sort_gens`` sorts by the printed name), and the
    tie fell to the iteration order of a set, i.e. to Python's string hash seed. The reduction of
    R₂ = (1 − cos φ)/p² of hypothesis row 1 then factored over another generator order: its sign
    arrangement differed between hash seeds, and once Wang's factorization ran past its 15 s safety
    bound (0.2 s otherwise), which stopped the plan."""
    return sp.Dummy(f"{name}{number}")


def base_angle_reduction(expr: sp.Expr) -> sp.Expr | None:
    """Reduce a rational function of φ and trig(kφ) modulo sin² + cos² = 1 (see module doc)."""
    opaque: dict[sp.Expr, sp.Symbol] = {}
    for function in sorted(expr.atoms(sp.Function), key=sp.default_sort_key):
        if not isinstance(function, _TRIG) and function.has(PHI):
            opaque[function] = _numbered_dummy("f", len(opaque))
    # Powers with symbolic bases and fractional exponents are opaque too (e.g. sqrt(1 - p^2)).
    for power in sorted(expr.atoms(sp.Pow), key=sp.default_sort_key):
        if power.has(PHI) and not power.exp.is_Integer and power not in opaque:
            opaque[power] = _numbered_dummy("r", len(opaque))
    hidden = expr.xreplace(opaque)
    multiples = _trig_multiples(hidden)
    if multiples is None:
        return None
    if not multiples:
        reduced = sp.cancel(sp.together(hidden))
        return reduced.xreplace({v: k for k, v in opaque.items()})
    denominator = reduce(lcm, (k.q for k in multiples), 1)
    if max(abs(k) * denominator for k in multiples) > BASE_ANGLE_MULTIPLE:
        return None
    theta = sp.Dummy("theta")
    s, c = sp.Dummy("s"), sp.Dummy("c")

    def expand(atom: sp.Expr) -> sp.Expr:
        n = int(sp.Rational(atom.args[0] / PHI) * denominator)
        sin_n = sp.expand_trig(sp.sin(n * theta)).subs({sp.sin(theta): s, sp.cos(theta): c})
        cos_n = sp.expand_trig(sp.cos(n * theta)).subs({sp.sin(theta): s, sp.cos(theta): c})
        if isinstance(atom, sp.sin):
            return sin_n
        if isinstance(atom, sp.cos):
            return cos_n
        return sin_n / cos_n

    polynomial_form = hidden.xreplace({atom: expand(atom) for atom in hidden.atoms(*_TRIG)})
    numerator, denom = sp.fraction(sp.together(polynomial_form))
    relation = s**2 + c**2 - 1
    best: sp.Expr | None = None
    for order in ((s, c), (c, s)):
        others = sorted(numerator.free_symbols | denom.free_symbols - {s, c}, key=sp.default_sort_key)
        gens = [*order, *others]
        gens = list(dict.fromkeys(gens))
        num_r, den_r = (_reduced_modulo(part, relation, gens) for part in (numerator, denom))
        if any(_beyond_the_factoring_cap(part, gens) for part in (num_r, den_r)):
            return None
        candidate = _factored(sp.cancel(num_r / den_r))
        if best is None or complexity(candidate) < complexity(best):
            best = candidate
    assert best is not None
    back = {s: sp.sin(PHI / denominator), c: sp.cos(PHI / denominator)}
    result = best.xreplace(back).xreplace({v: k for k, v in opaque.items()})
    return result


def _factored(quotient: sp.Expr) -> sp.Expr:
    """``sp.factor(quotient)``, without asking SymPy to factor what is already irreducible: the
    numerator and the denominator are split into square-free factors, and only those that are not
    plainly irreducible (:func:`_plainly_irreducible`) go to ``sp.factor``. Wang's multivariate
    algorithm, which ``factor`` runs on every factor, depends on the generator order and its random
    evaluation points: on the square of p·cos(φ/4) of hypothesis row 1 (7 generators, degree one
    in several) it ran past a minute in one order and took 0.2 s in the others."""
    numerator, denominator = sp.fraction(quotient)
    return _factored_polynomial(numerator) / _factored_polynomial(denominator)


def _factored_polynomial(polynomial: sp.Expr) -> sp.Expr:
    """``polynomial`` as its square-free factors, each factored by SymPy unless plainly irreducible."""
    if not polynomial.free_symbols:
        return polynomial
    coefficient, factors = sp.sqf_list(polynomial)
    return sp.Mul(coefficient, *((factor if _plainly_irreducible(factor) else sp.factor(factor))**k
                                 for factor, k in factors))


def _plainly_irreducible(factor: sp.Expr) -> bool:
    """Whether ``factor`` has degree one in one of its symbols with coprime coefficients there (then
    it has no factor of positive degree: one of degree zero in that symbol would divide both)."""
    for symbol in sorted(factor.free_symbols, key=sp.default_sort_key):
        poly = sp.Poly(factor, symbol)
        if poly.degree() == 1 and not sp.gcd(*poly.all_coeffs()).free_symbols:
            return True
    return False


def _beyond_the_factoring_cap(polynomial: sp.Expr, gens: list[sp.Expr]) -> bool:
    """Whether a reduced numerator or denominator has more than ``REDUCTION_TERMS`` terms or total
    degree above ``REDUCTION_DEGREE``: cancelling and factoring it is not attempted (a size, not a
    time; see the constants)."""
    poly = sp.Poly(polynomial, *gens)
    return len(poly.terms()) > REDUCTION_TERMS or poly.total_degree() > REDUCTION_DEGREE


def _reduced_modulo(polynomial: sp.Expr, relation: sp.Expr, gens: list[sp.Expr]) -> sp.Expr:
    """The remainder of ``polynomial`` modulo ``relation`` = g₀² + g₁² − 1 in lex order of ``gens``
    (unique: one polynomial is a Gröbner basis): every g₀^e becomes g₀^(e mod 2)·(1 − g₁²)^(e div 2).
    Expanded and substituted by ring arithmetic over QQ (``sp.expand`` of the Expr tree took 4.5 of
    6 s for tan(φ/3) + 8 tan(3φ/4)/9, the generic multivariate division 4.6 s for
    tan(2φ) cosh(φ/3)/4 + 3 sin(2φ/3)/(4(φ² + 1))); with other coefficients (√3, π) through
    ``sp.reduced``, whose remainder is the same polynomial."""
    try:
        ring, lead, other, *_ = sp.polys.rings.ring(gens, sp.QQ, sp.polys.orderings.lex)
        element = ring.from_expr(polynomial)
    except (ValueError, sp.polys.polyerrors.PolynomialError, sp.polys.polyerrors.CoercionFailed):
        return sp.reduced(sp.expand(polynomial), [relation], *gens, order="lex")[1]
    assert ring.from_expr(relation) == lead**2 + other**2 - 1
    complement = 1 - other**2
    powers = [ring.one]
    remainder = ring.zero
    for monomial, coefficient in element.terms():
        half, parity = divmod(monomial[0], 2)
        while len(powers) <= half:
            powers.append(powers[-1] * complement)
        rest = ring({(parity, *monomial[1:]): coefficient})
        remainder += rest * powers[half]
    return remainder.as_expr()


def contract_sums(expr: sp.Expr, seconds: float) -> sp.Expr:
    """trigsimp each trigonometric sum factor separately (small inputs keep it fast), each within
    its own bound of ``seconds``: one bound over all factors grew with their number (a derivation
    with 25 factors met the safety bound under load)."""
    factors = sp.Mul.make_args(sp.factor_terms(expr))
    out = []
    for factor in factors:
        base, exponent = factor.as_base_exp()
        if isinstance(base, sp.Add) and base.has(*_TRIG) and sp.count_ops(base) <= TRIGSIMP_OPS:
            base = bounded(seconds, base, _trigsimp, base)
        out.append(base**exponent)
    return sp.Mul(*out)


@lru_cache(maxsize=4096)
def _trigsimp(base: sp.Expr) -> sp.Expr:
    """``sp.trigsimp`` of a sum that has circular functions, with its hyperbolic functions as opaque
    symbols, remembered.

    Hidden: ``trigsimp`` rewrites hyperbolic functions as circular ones of imaginary arguments and back,
    and no identity joins cosh(aφ) to a circular function of a real multiple of φ. For
    tan(2φ)cosh(φ/3)/4 + 3 sin(2φ/3)/(4(φ² + 1)) one sum factor of 32 operations took 1.5–3.7 s with
    them and 0.9–1.3 s without, with the same result (all measured beside a CI run; the 5 s safety
    bound of a whole derivation was met once in CI). Remembered: the derived coefficients share
    their sum factors (p′, p and their powers in every denominator); for tan(φ/3) + 8 tan(3φ/4)/9,
    127 calls had 27 distinct arguments, and the repeats were 5.9 of the 8.5 s spent in
    ``trigsimp``. An interrupted call (the time bound's exception) is not remembered."""
    hyperbolic = sorted(base.atoms(HyperbolicFunction), key=sp.default_sort_key)
    opaque = {function: _numbered_dummy("h", k) for k, function in enumerate(hyperbolic)}
    contracted: sp.Expr = sp.trigsimp(base.xreplace(opaque))
    return contracted.xreplace({symbol: function for function, symbol in opaque.items()})


@lru_cache(maxsize=4096)
def simplest(expr: sp.Expr, seconds: float = 0.5) -> sp.Expr:
    """The simplest equivalent form of ``expr`` that bounded strategies find (cached)."""
    expr = sp.sympify(expr)
    if expr.is_Number:
        return expr
    candidates = [expr]
    reduced: sp.Expr | None = (bounded(seconds, None, base_angle_reduction, expr)
                               if sp.count_ops(expr) <= BASE_ANGLE_OPS else None)
    if reduced is not None:
        candidates.append(reduced)
    for candidate in list(candidates):
        candidates.append(contract_sums(candidate, seconds))
    return min(candidates, key=complexity)
