"""Hypothesis strategy: random valid generating functions from a small grammar (issue 16).

p(φ) = (1/κ) Σ cᵢ aᵢ(φ) eᵢ(φ), 1–3 terms, where each aᵢ is an odd building block of unit slope
at 0 (φ, sin(kφ)/k, tan(kφ)/k, sinh, tanh, atan, asinh, atanh, asin, all of kφ over k) or φ³
(slope 0), each eᵢ an even factor with eᵢ(0) = 1 (1, cos(kφ), cosh(kφ), 1/(1 + kφ²),
sqrt(1 + kφ²)), cᵢ and k small positive rationals. The sum is odd and analytic at 0 and is
divided by κ = Σ cᵢ aᵢ′(0) eᵢ(0), so that p ~ φ (eq 13). Functions whose validity range (found by
:func:`tests.reference.validity_edge`) is shorter than ``MIN_PHI_MAX`` are rejected.

:func:`sampled_functions` draws from the same grammar with a seeded :class:`random.Random`, so its
sample is the same on every run and every hypothesis version (hypothesis's derandomized draw is
not: it changes with the version).
"""

from __future__ import annotations

import random
from collections.abc import Callable

import mpmath
import sympy as sp
from hypothesis import assume
from hypothesis import strategies as st

from .reference import PHI, GeneratingFunction

MIN_PHI_MAX = 0.5

ODD: dict[str, Callable[[sp.Expr], sp.Expr]] = {
    "sin": sp.sin, "tan": sp.tan, "sinh": sp.sinh, "tanh": sp.tanh, "atan": sp.atan,
    "asinh": sp.asinh, "atanh": sp.atanh, "asin": sp.asin,
}
EVEN: dict[str, Callable[[sp.Expr, sp.Expr], sp.Expr]] = {
    "one": lambda k, phi: sp.Integer(1),
    "cos": lambda k, phi: sp.cos(k * phi),
    "cosh": lambda k, phi: sp.cosh(k * phi),
    "lorentz": lambda k, phi: 1 / (1 + k * phi ** 2),
    "sqrt": lambda k, phi: sp.sqrt(1 + k * phi ** 2),
}
RATIONAL_VALUES = [sp.Rational(n, d) for n, d in
                   ((1, 4), (1, 3), (1, 2), (2, 3), (3, 4), (1, 1), (3, 2), (2, 1))]
RATIONALS = st.sampled_from(RATIONAL_VALUES)
ATOMS = ["phi", "phi3", *ODD]


def term(coefficient: sp.Expr, atom: str, k: sp.Expr, even: str, k_even: sp.Expr) -> tuple[sp.Expr, sp.Expr]:
    """(c · a(φ) · e(φ), its slope at 0) for the building blocks of the grammar above."""
    if atom == "phi":
        odd, slope = PHI, sp.Integer(1)
    elif atom == "phi3":
        odd, slope = PHI ** 3, sp.Integer(0)
    else:
        odd, slope = ODD[atom](k * PHI) / k, sp.Integer(1)
    return coefficient * odd * EVEN[even](k_even, PHI), coefficient * slope


def normalized(drawn: list[tuple[sp.Expr, sp.Expr]]) -> GeneratingFunction | None:
    """Σ terms / κ with its reference, or None where κ ≤ 0 or φ_max < MIN_PHI_MAX."""
    kappa = sum(slope for _, slope in drawn)
    if not kappa > 0:
        return None
    text = str(sp.sympify(sum(t for t, _ in drawn) / kappa))
    with mpmath.workdps(30):
        function = GeneratingFunction(text)
    return function if function.phi_max >= MIN_PHI_MAX else None


@st.composite
def terms(draw: st.DrawFn) -> tuple[sp.Expr, sp.Expr]:
    """(term, its slope at 0)."""
    coefficient, atom, k = draw(RATIONALS), draw(st.sampled_from(ATOMS)), draw(RATIONALS)
    return term(coefficient, atom, k, draw(st.sampled_from(list(EVEN))), draw(RATIONALS))


@st.composite
def generating_functions(draw: st.DrawFn) -> GeneratingFunction:
    """A random odd p(φ) with κ = 1 and φ_max ≥ MIN_PHI_MAX, with its reference."""
    function = normalized(draw(st.lists(terms(), min_size=1, max_size=3)))
    assume(function is not None)
    assert function is not None
    return function


def sampled_expression(seed: int, index: int, max_terms: int = 3) -> str:
    """Function ``index`` of sample ``seed``: 1 to ``max_terms`` terms drawn with
    ``random.Random(seed * 10007 + index)`` until κ > 0, φ_max ≥ MIN_PHI_MAX and p is no named
    parameterization (φ, sin φ, 2 tan(φ/2), …); the same expression on every run and version.
    Each index is drawn on its own, so a test of one function pays for that one only."""
    from symrot.core.parsing import parse_expression
    from symrot.core.registry import find_by_expression

    rng = random.Random(seed * 10007 + index)
    while True:
        drawn = [term(rng.choice(RATIONAL_VALUES), rng.choice(ATOMS), rng.choice(RATIONAL_VALUES),
                      rng.choice(list(EVEN)), rng.choice(RATIONAL_VALUES))
                 for _ in range(rng.randint(1, max_terms))]
        function = normalized(drawn)
        if function is not None and find_by_expression(parse_expression(function.expression)) is None:
            return function.expression
