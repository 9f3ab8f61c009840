"""The exact series engine against independent references (SymPy on simple inputs, mpmath)."""

from __future__ import annotations

import mpmath
import pytest
import sympy as sp
from hypothesis import given, settings
from hypothesis import strategies as st

from symrot.core.errors import NonAnalyticError
from symrot.core.parsing import PHI, parse_expression
from symrot.core.series import coefficient_list, compose_even_in_x, revert, taylor_series

SIMPLE = [
    "sin(phi)/phi", "tan(phi/4)", "(1 - cos(phi))/phi**2", "exp(phi)*cos(phi)",
    "sqrt(1+phi)", "log(1+phi)", "atan(phi)", "asin(phi)", "asinh(phi)", "atanh(phi)",
    "tanh(phi)", "cosh(phi)", "1/(1+phi**2)", "(phi - sin(phi))/phi**3", "acos(phi)",
]


@pytest.mark.parametrize("text", SIMPLE)
def test_matches_sympy_series_on_simple_inputs(text: str) -> None:
    expr = parse_expression(text)
    ours = coefficient_list(taylor_series(expr, 10), 0, 10)
    reference = sp.series(expr, PHI, 0, 10).removeO()
    expected = [sp.nsimplify(reference.coeff(PHI, k)) for k in range(10)]
    assert [sp.simplify(a - b) for a, b in zip(ours, expected, strict=True)] == [0] * 10


def test_cube_root_of_eq_35_against_mpmath_taylor() -> None:
    """The twelve coefficients of cbrt(6(φ − sin φ)) against mpmath's numerical Taylor expansion at
    0 (60 digits, the odd real cube root): within 10⁻⁴⁰ (measured 3·10⁻⁷⁰); the series summed at
    φ = 0.01 agrees with the function to 10⁻²⁵ (the first omitted term, φ¹³, is ~10⁻²⁷)."""
    expr = parse_expression("cbrt(6*(phi-sin(phi)))")
    exact = coefficient_list(taylor_series(expr, 12), 0, 12)
    with mpmath.workdps(60):
        ours = [mpmath.mpf(sp.Rational(c).p) / sp.Rational(c).q for c in exact]

        def function(t: mpmath.mpf) -> mpmath.mpf:
            return mpmath.sign(t) * mpmath.cbrt(abs(6 * (t - mpmath.sin(t)))) if t else mpmath.mpf(0)

        reference = mpmath.taylor(function, 0, 11)
        assert len(reference) == len(ours) == 12
        assert all(abs(a - b) < mpmath.mpf(10) ** -40 for a, b in zip(ours, reference, strict=True)), \
            [mpmath.nstr(a - b, 5) for a, b in zip(ours, reference, strict=True)]
        t = mpmath.mpf("0.01")
        series_value = sum(c * t**k for k, c in enumerate(ours))
        assert abs(series_value - function(t)) < mpmath.mpf(10) ** -25


def test_identically_zero_expression_does_not_hang() -> None:
    # sympy.series hangs on such inputs; the engine returns an exact zero series.
    p = 2 * sp.sin(PHI / 2)
    mu = 1 / sp.diff(p, PHI)
    epsilon = 2 * sp.tan(PHI / 2) / p
    coefficient = (1 / epsilon - 1 / mu) / p**2
    assert coefficient_list(taylor_series(coefficient, 20), 0, 20) == [0] * 20


def test_reversion_of_wiener_milenkovic_is_four_atan() -> None:
    p = coefficient_list(taylor_series(4 * sp.tan(PHI / 4), 16), 0, 16)
    inverse = revert(p, 16)
    expected = coefficient_list(taylor_series(4 * sp.atan(PHI / 4), 16), 0, 16)
    assert inverse == expected


def test_composition_gives_series_in_x() -> None:
    # For 4 tan(phi/4): (mu - nu^2/eps)/p^2 = 32/(16 + x)^2 (issue 4's example).
    p = 4 * sp.tan(PHI / 4)
    nu, eps, mu = 2 * sp.sin(PHI / 2) / p, 2 * sp.tan(PHI / 2) / p, 1 / sp.diff(p, PHI)
    in_phi = coefficient_list(taylor_series((mu - nu**2 / eps) / p**2, 16), 0, 16)
    phi_of_p = revert(coefficient_list(taylor_series(p, 16), 0, 16), 16)
    x = sp.Symbol("x")
    expected = sp.series(32 / (16 + x) ** 2, x, 0, 8).removeO()
    assert compose_even_in_x(in_phi, phi_of_p, 8) == [expected.coeff(x, j) for j in range(8)]


@pytest.mark.parametrize("text", ["sqrt(phi)", "log(phi)", "exp(1/phi)", "cbrt(phi**2)",
                                  "sqrt(phi**2)", "asin(1+phi)"])
def test_branch_points_are_reported(text: str) -> None:
    with pytest.raises(NonAnalyticError):
        taylor_series(parse_expression(text), 8)


@settings(max_examples=25, deadline=None)
@given(
    a=st.fractions(min_value=-3, max_value=3, max_denominator=7),
    b=st.fractions(min_value=-3, max_value=3, max_denominator=7),
    k=st.integers(min_value=1, max_value=4),
)
def test_product_rule_property(a: object, b: object, k: int) -> None:
    """series(f*g) == series(f)*series(g) truncated, for f = sin(a phi + ...), g = exp(b phi^k)."""
    f = sp.sin(sp.Rational(a) * PHI + PHI**3)
    g = sp.exp(sp.Rational(b) * PHI**k)
    fg = coefficient_list(taylor_series(f * g, 12), 0, 12)
    fs = coefficient_list(taylor_series(f, 12), 0, 12)
    gs = coefficient_list(taylor_series(g, 12), 0, 12)
    product = [sum(fs[i] * gs[n - i] for i in range(n + 1)) for n in range(12)]
    assert fg == product


@pytest.mark.parametrize(("expr", "order"), [
    (PHI**2 * sp.cot(PHI), 9), (PHI * sp.csc(PHI), 9), (sp.sec(PHI), 9), (PHI * sp.coth(PHI), 9),
    (PHI * sp.csch(PHI), 9),
    (-sp.cot(PHI + 1), 6),  # its coefficients in cot(1), csc(1) grow fast: order 9 took 21 s in the suite
])
def test_reciprocal_trigonometric_functions_match_sympy(expr: sp.Expr, order: int) -> None:
    ours = coefficient_list(taylor_series(expr, order), 0, order)
    reference = sp.series(expr, PHI, 0, order).removeO()
    # equal at 60 digits: simplify(ours - reference) == 0 took 143 s on the cot(1), csc(1) terms
    # of cot(φ + 1)
    for k in range(order):
        exact = reference.coeff(PHI, k)
        assert abs(sp.N(ours[k] - exact, 60)) <= sp.Float(10, 60) ** -50 * (1 + abs(sp.N(exact, 60))), k


def test_cot_has_a_pole_not_a_missing_rule() -> None:
    assert taylor_series(parse_expression("tan(pi/2 + phi)"), 4).valuation == -1


def test_exact_rational_coefficients_survive_the_symbolic_domain() -> None:
    """pi/2 − acos(φ) has its series in the EX domain (pi in the constant term); its φ^27
    coefficient 1300075/226492416 once went through nsimplify, which returned an irrational number
    equal to 15 digits only, so the series was wrong and reverting it ran for minutes."""
    from symrot.core.series_engine import exact_number

    rational = sp.Rational(1300075, 226492416)
    assert exact_number(rational) == rational
    assert exact_number(sp.sqrt(2) * sp.sqrt(8) / 8) == sp.Rational(1, 2)
    ours = coefficient_list(taylor_series(parse_expression("pi/2 - acos(phi)"), 50), 0, 50)
    exact = sp.series(sp.asin(PHI), PHI, 0, 50).removeO()
    assert ours == [exact.coeff(PHI, k) for k in range(50)]
    assert all(c.is_Rational for c in ours)


def test_acos_is_expanded_as_asin_so_that_the_series_stays_rational() -> None:
    """p = π/2 − acos φ: its π/2 put every series over EX, ten times slower (28 s of a 51 s
    profiled plan); written as asin φ the π/2 cancel and the coefficients are asin's."""
    series = taylor_series(sp.pi / 2 - sp.acos(PHI), 12)
    assert series.ring.domain == sp.QQ
    assert coefficient_list(series, 0, 12) == coefficient_list(taylor_series(sp.asin(PHI), 12), 0, 12)
    # where acos stays (no π/2 to cancel) the series is acos's own: φ acos(φ/2) over EX
    expected = sp.series(PHI * sp.acos(PHI / 2), PHI, 0, 8).removeO()
    mixed = coefficient_list(taylor_series(PHI * sp.acos(PHI / 2), 8), 0, 8)
    assert [sp.simplify(c - expected.coeff(PHI, k)) for k, c in enumerate(mixed)] == [0] * 8
