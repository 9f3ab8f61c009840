"""symrot.plan.pole: the vanishing factor of a pole edge written through s = |p| (issue 16).

Next to a pole of p, forms evaluated from the rounded angle φ̂ lose digits in every factor that
vanishes there; the rewrite must (1) keep the value exactly, (2) be accurate in floating point where
the form in φ is not, and (3) reach the emitted code, whose domain then extends to the edge.
"""

from __future__ import annotations

import math

import mpmath
import numpy as np
import pytest
import sympy as sp

from symrot.core.functions import mpmath_namespace
from symrot.core.parsing import PHI
from symrot.plan.algebraic import D, S, X
from symrot.plan.evaluation import model_function
from symrot.plan.pole import pole_factor, with_pole_factor

POLES = {  # p: φ_max (the pole)
    "phi/(1 - phi**2/10)": "sqrt(10)",
    "phi/cos(phi/4)": "2*pi",
    "tan(phi)/2 + tanh(phi)/2": "pi/2",
    "tan(phi/3) + 8*tan(3*phi/4)/9": "2*pi/3",
    "4*tan(phi/4)": "2*pi",
}


def _p(text: str) -> sp.Expr:
    return sp.sympify(text, locals={"phi": PHI})


@pytest.mark.parametrize("text", list(POLES))
def test_the_factor_vanishes_at_the_pole_and_its_s_form_is_p_s_identity(text: str) -> None:
    p, phi_max = _p(text), sp.sympify(POLES[text])
    pole = pole_factor(p, float(phi_max))
    assert pole is not None
    assert abs(sp.N(pole.factor.subs(PHI, phi_max), 40)) < 1e-35
    with mpmath.workdps(50):
        assert abs(pole.phi_max - mpmath.mpf(sp.N(phi_max, 50))) < mpmath.mpf(10) ** -40
    # f = N/(D s) holds where s = p
    assert sp.simplify(pole.through_s.subs(S, p) - pole.factor) == 0


@pytest.mark.parametrize("text, phi_max", [("sin(phi)", "pi"), ("phi + phi**3/6", "2*pi"),
                                           ("phi/(1 - phi**2/10)**4", "sqrt(10)"),
                                           ("sin(phi)*cosh(phi/3)", "pi/2"),
                                           ("phi/sqrt(1 + phi**2)", "2*pi")])
def test_no_factor_without_a_pole_of_order_at_most_three(text: str, phi_max: str) -> None:
    """No pole (sin, a polynomial, a fold, a radical denominator that never vanishes), a pole of order
    4: nothing to rewrite. φ/√(1 + φ²) made ``sp.factor_list`` raise (PolificationFailed), which
    ended ``--emit`` in an internal error."""
    assert pole_factor(_p(text), float(sp.sympify(phi_max))) is None


@pytest.mark.parametrize("text, phi_max", [("phi/(1 - phi**2/10)**2", "sqrt(10)"),
                                           ("tan(phi)**3/3 + tan(phi)", "pi/2"),
                                           ("phi/cos(phi)**2", "pi/2")])
def test_a_pole_of_order_two_or_three_writes_its_factor_as_a_root_through_s(text: str, phi_max: str) -> None:
    """p = N/(D·f^m): f = (N/(D·s))^(1/m) with f's sign below the pole. Without it, every form of
    tan φ + tan³φ/3 kept cos φ from the rounded angle and the domain ended at |p|² = 2³² (NaN from
    φ = 1.56 on, of π/2)."""
    p, edge = _p(text), sp.sympify(phi_max)
    pole = pole_factor(p, float(edge))
    assert pole is not None
    assert abs(sp.N(pole.factor.subs(PHI, edge), 40)) < 1e-35
    through = sp.lambdify((PHI, S), pole.through_s, modules=[mpmath_namespace(), "mpmath"])
    factor, p_of = (sp.lambdify(PHI, e, modules=[mpmath_namespace(), "mpmath"]) for e in (pole.factor, p))
    with mpmath.workdps(50):
        for distance in ("1e-1", "1e-4", "1e-9"):
            angle = mpmath.mpf(sp.N(edge, 50)) - mpmath.mpf(distance)
            assert abs(through(angle, p_of(angle)) / factor(angle) - 1) < mpmath.mpf(10) ** -40, distance


def _relative_error(form: sp.Expr, p: sp.Expr, theta: mpmath.mpf) -> float:
    """Error of ``form`` evaluated in float64 from the backends' inputs (φ̂ = θ rounded, s = p(θ)
    rounded) against the exact value at θ, in ulp of the value."""
    p_of = sp.lambdify(PHI, p, "mpmath")
    exact = sp.lambdify(PHI, form.subs(S, p), modules=[mpmath_namespace(), "mpmath"])(theta)
    s = float(p_of(theta))
    model = model_function(form, [X, PHI, S, D])
    value = float(model(np.float64(s * s), np.float64(float(theta)), np.float64(s), np.float64(0)))
    return float(abs(value - exact) / abs(exact)) / float(np.finfo(float).eps)


def test_rewritten_forms_keep_the_value_and_their_digits_next_to_the_pole() -> None:
    """p = φ/(1 − φ²/10): p′, det H and ν as derived contain (φ² − 10)^k;
    written through s they are within a few ulp at φ_max − 10⁻⁹ where the forms in φ are not."""
    p = _p("phi/(1 - phi**2/10)")
    pole = pole_factor(p, math.sqrt(10))
    assert pole is not None
    forms = [(10 * PHI**2 + 100) / (PHI**4 - 20 * PHI**2 + 100),
             (PHI**2 - 10)**4 * sp.sin(PHI / 2)**2 / (250 * PHI**2 * (PHI**2 + 10)),
             2 * (1 - PHI**2 / 10) * sp.sin(PHI / 2) / PHI]
    with mpmath.workdps(60):
        theta = mpmath.sqrt(10) - mpmath.mpf("1e-9") * mpmath.mpf("1.37")
        for form in forms:
            rewritten = with_pole_factor(form, pole)
            assert rewritten.has(S) and sp.simplify(rewritten.subs(S, p).doit() - form) == 0, form
            assert _relative_error(rewritten, p, theta) <= 4, rewritten
            assert _relative_error(form, p, theta) > 1e4, form  # the reason for the rewrite


def test_a_form_without_the_factor_is_returned_unchanged() -> None:
    pole = pole_factor(_p("phi/cos(phi/4)"), 2 * math.pi)
    assert pole is not None
    form = sp.cos(PHI / 2) ** 2 / PHI  # cos(phi/2) = -1 at the pole: nothing vanishes
    assert with_pole_factor(form, pole) is form


def test_multiples_of_the_factor_angle_that_vanish_with_it_are_expanded() -> None:
    """p = φ/cos(φ/4): the pole coincides with the end of ν at 2π, where sin(φ/2) from φ̂ loses
    digits as fast as cos(φ/4); written as 2 sin(φ/4)·φ/s it does not."""
    p = _p("phi/cos(phi/4)")
    pole = pole_factor(p, 2 * math.pi)
    assert pole is not None
    form = 2 * sp.sin(PHI / 2) / p  # ν (eq 15)
    rewritten = with_pole_factor(form, pole)
    assert not rewritten.has(sp.sin(PHI / 2)) and sp.simplify(rewritten.subs(S, p).doit() - form) == 0
    with mpmath.workdps(60):
        theta = 2 * mpmath.pi - mpmath.mpf("1.37e-7")
        assert _relative_error(rewritten, p, theta) <= 4
        assert _relative_error(form, p, theta) > 1e4


def test_a_vanishing_sum_of_other_multiples_of_the_base_angle_is_divided_by_the_factor() -> None:
    """p = 2 tan(3φ/2)/(3(3φ²/2 + 1)), a pole at π/3: SymPy writes cos(3φ/2) in det H as
    cos(φ/2)(2 cos φ − 1), where cos(3φ/2) is no generator to divide by. Through the base angle
    φ/2, 2 cos φ − 1 = f/cos(φ/2), and det H keeps its digits next to the pole (the range of
    hypothesis row 159 ended at |p|² = 2³², det H 8·10⁵ ulp off there)."""
    p = _p("2*tan(3*phi/2)/(3*(3*phi**2/2 + 1))")
    pole = pole_factor(p, math.pi / 3)
    assert pole is not None and pole.factor == sp.cos(3 * PHI / 2)
    det_h = (-9 * (3 * PHI**2 + 2) ** 4 * (2 * sp.cos(PHI) - 1) ** 4 * sp.cos(PHI / 2) ** 4
             / (8 * (2 * sp.cos(PHI / 2) - 1) ** 2 * (2 * sp.cos(PHI / 2) + 1) ** 2
                * (-3 * PHI**2 + 2 * PHI * sp.sin(3 * PHI) - 2)))
    rewritten = with_pole_factor(det_h, pole)
    assert rewritten.has(S) and not rewritten.has(sp.cos(PHI))
    identity = sp.lambdify(PHI, rewritten.subs(S, p).doit() - det_h, modules=[mpmath_namespace(), "mpmath"])
    with mpmath.workdps(60):
        for angle in ("0.3", "0.7", "1.0"):
            assert abs(identity(mpmath.mpf(angle))) < mpmath.mpf(10) ** -45
        theta = mpmath.pi / 3 - mpmath.mpf("1.37e-8")
        assert _relative_error(rewritten, p, theta) <= 8
        assert _relative_error(det_h, p, theta) > 1e4


def test_a_vanishing_sum_of_the_cofunction_is_written_through_the_factor_squared() -> None:
    """Hypothesis row 1, p = A + 2 tan(φ/4) cosh(3φ/4), a pole at 2π: SymPy writes H⁻¹'s
    across-axis part with (sin(φ/4) − 1)(sin(φ/4) + 1) = −cos²(φ/4), whose first factor is of size
    (2π − φ)²/32 and has no generator cos(φ/4) to divide by. As −f²/(sin(φ/4) + 1), with f through
    s, it keeps its digits (it was 1.2·10⁴ ulp off at |p|² = 2³², where the range ended)."""
    p = _p("phi**3*sqrt(phi**2/2 + 1)/4 + 2*sqrt(phi**2 + 1)*asinh(phi/4) + 2*tan(phi/4)*cosh(3*phi/4)")
    pole = pole_factor(p, 2 * math.pi)
    assert pole is not None and pole.factor == sp.cos(PHI / 4)
    sine = sp.sin(PHI / 4)
    form = (-sp.cos(PHI / 2) * (PHI**3 * sp.cos(PHI / 4) + 8 * sine * sp.cosh(3 * PHI / 4))
            / (16 * sine * (sine - 1) * (sine + 1)))
    rewritten = with_pole_factor(form, pole)
    assert rewritten.has(S) and not rewritten.has(sine - 1)
    identity = sp.lambdify(PHI, rewritten.subs(S, p) - form, modules=[mpmath_namespace(), "mpmath"])
    with mpmath.workdps(60):
        for angle in ("0.5", "3.0", "6.0"):
            assert abs(identity(mpmath.mpf(angle))) < mpmath.mpf(10) ** -35 * abs(
                sp.lambdify(PHI, form, modules=[mpmath_namespace(), "mpmath"])(mpmath.mpf(angle)))
        theta = 2 * mpmath.pi - mpmath.mpf("1.37e-6")
        assert _relative_error(rewritten, p, theta) <= 8
        assert _relative_error(form, p, theta) > 1e4


def test_a_tangent_beside_other_terms_writes_its_cosine_through_s_minus_the_rest() -> None:
    """p = A + B tan(2φ/3), a pole at 3π/4 (hypothesis row 94): cos(2φ/3) = B sin(2φ/3)/(s − A),
    with no A·cos(2φ/3) from the rounded angle inside (det H was 291 ulp off at |p|² = 2³² through
    N/(D·s), and the range ended there)."""
    p = _p("8*sinh(phi)*cosh(2*phi/3)/11 + 9*tan(2*phi/3)/(22*(3*phi**2/4 + 1))")
    pole = pole_factor(p, 3 * math.pi / 4)
    assert pole is not None and pole.factor == sp.cos(2 * PHI / 3)
    assert not pole.through_s.has(sp.cos(2 * PHI / 3))
    slope = sp.diff(p, PHI)
    rewritten = with_pole_factor(slope, pole)
    identity = sp.lambdify(PHI, rewritten.subs(S, p) - slope, modules=[mpmath_namespace(), "mpmath"])
    with mpmath.workdps(60):
        for angle in ("0.5", "1.5", "2.3"):
            assert abs(identity(mpmath.mpf(angle))) < mpmath.mpf(10) ** -40
        theta = 3 * mpmath.pi / 4 - mpmath.mpf("1.37e-8")
        assert _relative_error(rewritten, p, theta) <= 8
        assert _relative_error(slope, p, theta) > 1e4


def _slope_through_s(p: sp.Expr, phi_max: sp.Expr) -> tuple[sp.Expr, sp.Expr]:
    """(p′, p′ with the edge's factor written through s), after checking that the factor vanishes at
    φ_max and that its form through s equals it where s = p (at 0.1, 0.5 and 0.9 φ_max)."""
    pole = pole_factor(p, float(phi_max))
    assert pole is not None and abs(sp.N(pole.factor.subs(PHI, phi_max), 40)) < 1e-35
    identity = sp.lambdify(PHI, pole.through_s.subs(S, p) - pole.factor,
                           modules=[mpmath_namespace(), "mpmath"])
    with mpmath.workdps(50):
        for fraction in ("0.1", "0.5", "0.9"):
            angle = mpmath.mpf(fraction) * mpmath.mpf(sp.N(phi_max, 50))
            assert abs(identity(angle)) < mpmath.mpf(10) ** -40
    slope = sp.diff(p, PHI)
    rewritten = with_pole_factor(slope, pole)
    assert rewritten.has(S)
    return slope, rewritten


LOGARITHMIC_POLES = {  # p = A + B atanh(u), u(φ_max) = 1: φ_max
    "2*cos(2*phi)*atanh(3*phi/2)/3": "2/3",
    "3*phi*cos(phi/2)/11 + 6*sinh(phi)/(11*(3*phi**2/2 + 1)) + 8*atanh(3*phi/4)/(33*(phi**2/4 + 1))": "4/3",
}


@pytest.mark.parametrize("text", list(LOGARITHMIC_POLES))
def test_a_logarithmic_pole_writes_one_minus_u_squared_through_s(text: str) -> None:
    """Hypothesis rows 31 and 15: p → ∞ like atanh(u). f = 1 − u² (the factor of p′) is
    (1 + u)² exp(−2 (s − A)/B). Its condition number with respect to s is 2s/B (≈ 2 ln(1/(φ_max − φ))),
    and p′ written through it stays within 4 (1 + s/B) ulp at φ_max − 1.37·10⁻⁹ (14 and 25 ulp),
    where p′ in φ has lost more than 10⁴ ulp (row 15: 1.5·10⁵ ulp of det H at φ_max − 10⁻⁶)."""
    _assert_slope_within_s_over_b(_p(text), sp.sympify(LOGARITHMIC_POLES[text]), sp.atanh)


def _assert_slope_within_s_over_b(p: sp.Expr, phi_max: sp.Expr, function: type[sp.Function]) -> None:
    """p′ through s within 4 (1 + s/B) ulp at φ_max − 1.37·10⁻⁹ (p = A + B·``function``(u), s/B
    the condition number of f through s), where p′ in φ̂ is more than 10⁴ ulp off."""
    slope, rewritten = _slope_through_s(p, phi_max)
    (call,) = p.atoms(function)
    weight = sp.lambdify(PHI, sp.diff(p.xreplace({call: S}), S), "mpmath")
    p_of = sp.lambdify(PHI, p, "mpmath")
    with mpmath.workdps(60):
        theta = mpmath.mpf(sp.N(phi_max, 60)) - mpmath.mpf("1e-9") * mpmath.mpf("1.37")
        condition = float(abs(p_of(theta) / weight(theta)))
        assert _relative_error(rewritten, p, theta) <= 4 * (1 + condition), rewritten
        assert _relative_error(slope, p, theta) > 1e4


ARCSINE_EDGES = {  # p = A + B asin(u) (acos), u(φ_max)² = 1, p′ → ∞: φ_max
    "4*cosh(3*phi/4)*asin(3*phi/4)/3": "4/3",
    "3*cosh(phi/3)*asin(phi/3)": "3",
    "2*asin(phi/2)": "2",
    "phi/10 + 2*acos(1 - phi/2)": "4",
}


@pytest.mark.parametrize("text", list(ARCSINE_EDGES))
def test_an_arcsine_edge_writes_one_minus_u_squared_through_s(text: str) -> None:
    """Hypothesis rows 42-44: p stays finite and p′ → ∞ through 1/√(1 − u²). f = 1 − u² is
    cos²((s − A)/B) (sin² for acos); its condition number with respect to s is 2 s tan(y)/B
    (y = (s − A)/B, cot y for acos), and p′ written through it stays within 4 (1 + that) ulp at
    φ_max − 1.37·10⁻⁹ (it stays below 1 + that: 2.7·10³ to 3.3·10⁴ ulp where the condition number is
    7·10⁴ to 1.8·10⁵), where p′ in φ̂ loses 10³ times more (54 ulp of H at 4/3 − 10⁻⁶)."""
    p, phi_max = _p(text), sp.sympify(ARCSINE_EDGES[text])
    slope, rewritten = _slope_through_s(p, phi_max)
    (call,) = p.atoms(sp.asin, sp.acos)
    linear = p.xreplace({call: S})
    weight = sp.lambdify(PHI, sp.diff(linear, S), "mpmath")
    rest = sp.lambdify(PHI, linear.subs(S, 0), "mpmath")
    p_of = sp.lambdify(PHI, p, "mpmath")
    with mpmath.workdps(60):
        theta = mpmath.mpf(sp.N(phi_max, 60)) - mpmath.mpf("1e-9") * mpmath.mpf("1.37")
        y = (p_of(theta) - rest(theta)) / weight(theta)
        slant = mpmath.tan(y) if isinstance(call, sp.asin) else mpmath.cot(y)
        condition = float(abs(2 * p_of(theta) * slant / weight(theta)))
        assert _relative_error(rewritten, p, theta) <= 4 * (1 + condition), rewritten
        # in φ̂: 800-2100 times the condition number (5.6·10⁷ to 1.9·10⁸ ulp)
        assert _relative_error(slope, p, theta) > 100 * (1 + condition)


EDGE_CALLS = {  # p = A + B F(u), F = atanh or asin, with the edge u² = 1 at φ_max: φ_max
    "2*cos(phi/4)*atanh(3*phi/2)/3": "2/3",  # hypothesis row 88
    "2*sqrt(phi**2/3 + 1)*asin(phi/3) + 4*cos(phi)*asin(phi/4)/3": "3",  # row 140: two asin calls
    "cos(phi)*asin(phi)": "1",  # row 189
}


@pytest.mark.parametrize("text", list(EDGE_CALLS))
def test_the_edge_call_itself_is_written_through_s(text: str) -> None:
    """F(u) next to its edge from the rounded φ̂ loses digits like the factor 1 − u² (F′ → ∞):
    sin φ/p of row 88 simplifies to 3 sin φ/(2 cos(φ/4) atanh(3φ/2)), 6·10⁶ ulp off at
    2/3 − 1.37·10⁻⁹ (row 88 measured `rotation_matrix` 102 ulp at 2/3 − 10⁻⁶). With F(u) = (s − A)/B
    the form keeps its value and its digits; of several calls of F only the one whose edge is φ_max
    is rewritten (row 140: asin(φ/4) stays in A)."""
    p, phi_max = _p(text), sp.sympify(EDGE_CALLS[text])
    pole = pole_factor(p, float(phi_max))
    assert pole is not None and pole.call is not None and pole.call_through_s is not None
    assert sp.simplify(pole.call_through_s.subs(S, p) - pole.call) == 0
    form = sp.simplify(sp.sin(PHI) / p)
    rewritten = with_pole_factor(form, pole)
    assert rewritten.has(S) and not rewritten.has(pole.call)
    assert sp.simplify(rewritten.subs(S, p) - form) == 0
    with mpmath.workdps(60):
        theta = mpmath.mpf(sp.N(phi_max, 60)) - mpmath.mpf("1e-9") * mpmath.mpf("1.37")
        assert _relative_error(rewritten, p, theta) <= 4, rewritten
        assert _relative_error(form, p, theta) > 100


LOG_POLES = {  # p = A + B log(N/D), a simple zero of D (or N) at φ_max: φ_max
    "log((1 + phi/2)/(1 - phi/2))": "2",  # corpus entry 21, 2 atanh(φ/2) as SymPy does not write it
    "phi/3 - 2*log(1 - phi/3)/3": "3",
}


@pytest.mark.parametrize("text", list(LOG_POLES))
def test_a_logarithm_writes_its_vanishing_part_and_itself_through_s(text: str) -> None:
    """Corpus entry 21 missed in float32 (`tangent_det` 3.9·10⁵ ulp, `omega` 2.8·10³ ulp at 2): p′
    holds 2 − φ from the rounded angle. Through s, 2 − φ = (2 + φ) exp(−s) (D = N exp(−(s − A)/B)),
    within 4 (1 + s/B) ulp at φ_max − 1.37·10⁻⁹ where the form in φ̂ is 10⁴ ulp off, and the call
    itself, in whatever form SymPy wrote its argument, is (s − A)/B."""
    p, phi_max = _p(text), sp.sympify(LOG_POLES[text])
    _assert_slope_within_s_over_b(p, phi_max, sp.log)
    pole = pole_factor(p, float(phi_max))
    assert pole is not None
    form = sp.simplify(sp.sin(PHI) / p)
    assert not with_pole_factor(form, pole).has(sp.log)


GUDERMANNIAN_POLES = {  # p = A + B asinh(tan(aφ)), cos(aφ_max) = 0: φ_max
    "asinh(tan(phi))": "pi/2",  # corpus entry 46
    "phi/3 + asinh(tan(phi/2))/2": "pi",
    # the same function as atanh(sin φ): taken as a logarithmic pole (f = 1 − sin²φ), it left
    # cos φ = 1/p′ in φ̂, and H⁻¹, ṗ and det H were 2.25·10⁵ (float64) and 6·10⁵ (float32) ulp off
    "atanh(sin(phi))": "pi/2",
}


@pytest.mark.parametrize("text", list(GUDERMANNIAN_POLES))
def test_the_inverse_gudermannian_writes_its_cosine_through_s(text: str) -> None:
    """p′ of asinh(tan φ) is 1/cos φ: H⁻¹ and ṗ of corpus entry 46 were 2.2·10⁵ ulp off at
    π/2 − 10⁻⁶ (NumPy and C, both precisions), with cos φ from the rounded φ̂. Through s,
    tan(aφ) = sinh((s − A)/B) makes cos(aφ) = 1/cosh((s − A)/B), accurate to a few ulp."""
    p, phi_max = _p(text), sp.sympify(GUDERMANNIAN_POLES[text])
    pole = pole_factor(p, float(phi_max))
    assert pole is not None and pole.call is not None and pole.call_through_s is not None
    assert abs(sp.N(pole.factor.subs(PHI, phi_max), 40)) < 1e-35
    with mpmath.workdps(50):
        theta = mpmath.mpf(sp.N(phi_max, 50)) - mpmath.mpf("1e-7")
        with mpmath.workdps(90):  # atanh(sin θ) loses 14 digits next to π/2
            exact_s = +sp.lambdify(PHI, p, modules=[mpmath_namespace(), "mpmath"])(theta)
        through = sp.lambdify((S, PHI), pole.through_s, modules=[mpmath_namespace(), "mpmath"])
        factor = sp.lambdify(PHI, pole.factor, modules=[mpmath_namespace(), "mpmath"])
        assert abs(through(exact_s, theta) / factor(theta) - 1) < mpmath.mpf(10) ** -40
    form = sp.trigsimp(1 / sp.diff(p, PHI))  # μ, the factor of H⁻¹ that vanishes at the pole
    rewritten = with_pole_factor(form, pole)
    assert rewritten.has(S)
    with mpmath.workdps(60):
        theta = mpmath.mpf(sp.N(phi_max, 60)) - mpmath.mpf("1e-6")
        assert _relative_error(rewritten, p, theta) <= 4, rewritten
        assert _relative_error(form, p, theta) > 1000
