"""Hypothesis strategy: random valid generating functions from a small grammar (issue 16).

p(φ) = (1/κ) Σ cᵢ aᵢ(φ) eᵢ(φ), 1–3 terms, where each aᵢ is an odd building block of unit slope
at 0 (φ, sin(kφ)/k, tan(kφ)/k, sinh, tanh, atan, asinh, atanh, asin, all of kφ over k) or φ³
(slope 0), each eᵢ an even factor with eᵢ(0) = 1 (1, cos(kφ), cosh(kφ), 1/(1 + kφ²),
sqrt(1 + kφ²)), cᵢ and k small positive rationals. The sum is odd and analytic at 0 and is
divided by κ = Σ cᵢ aᵢ′(0) eᵢ(0), so that p ~ φ (eq 13). Functions whose validity range (found by
:func:`tests.reference.validity_edge`) is shorter than ``MIN_PHI_MAX`` are rejected.
"""

from __future__ import annotations

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
RATIONALS = st.sampled_from([sp.Rational(n, d) for n, d in
                             ((1, 4), (1, 3), (1, 2), (2, 3), (3, 4), (1, 1), (3, 2), (2, 1))])


@st.composite
def terms(draw: st.DrawFn) -> tuple[sp.Expr, sp.Expr]:
    """(term, its slope at 0)."""
    coefficient = draw(RATIONALS)
    atom = draw(st.sampled_from(["phi", "phi3", *ODD]))
    k = draw(RATIONALS)
    if atom == "phi":
        odd, slope = PHI, sp.Integer(1)
    elif atom == "phi3":
        odd, slope = PHI ** 3, sp.Integer(0)
    else:
        odd, slope = ODD[atom](k * PHI) / k, sp.Integer(1)
    factor = EVEN[draw(st.sampled_from(list(EVEN)))](draw(RATIONALS), PHI)
    return coefficient * odd * factor, coefficient * slope


@st.composite
def generating_functions(draw: st.DrawFn) -> GeneratingFunction:
    """A random odd p(φ) with κ = 1 and φ_max ≥ MIN_PHI_MAX, with its reference."""
    drawn = draw(st.lists(terms(), min_size=1, max_size=3))
    kappa = sum(slope for _, slope in drawn)
    assume(kappa > 0)
    expression = sp.sympify(sum(term for term, _ in drawn) / kappa)
    text = str(expression)
    with mpmath.workdps(30):
        function = GeneratingFunction(text)
    assume(function.phi_max >= MIN_PHI_MAX)
    return function
