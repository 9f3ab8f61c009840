"""Singular angles and validity ranges (Section 3.4, Table 1's last column)."""

from __future__ import annotations

import time

import pytest
import sympy as sp

from symrot.core.derivation import derive_expression
from symrot.core.parsing import parse_expression
from symrot.core.registry import PAPER_TABLE_1_VALIDITY, family_member, lookup
from symrot.core.singularities import _validity_of, validity

pi = sp.pi
EXPECTED = {
    "cayley_gibbs_rodrigues": (pi, "p"),
    "wiener_milenkovic": (2 * pi, "p"),
    "rotation_vector": (2 * pi, "nu"),
    "euler_rodrigues": (pi, "p_prime"),
    "linear": (pi / 2, "p_prime"),
    "sine_m4": (2 * pi, "nu"),
    "det_h_one": (2 * pi, "nu"),
    "tangent_m3": (3 * pi / 2, "p"),
}
# Families: sine m -> min(m pi/2, 2 pi) (p' = cos(phi/m) -> 0 or nu -> 0);
# tangent m -> min(m pi/2, 2 pi) (p -> oo or nu -> 0).
for m in range(1, 7):
    EXPECTED[f"sine_m{m}"] = (min(sp.Rational(m, 2) * pi, 2 * pi), "p_prime" if m < 4 else "nu")
    EXPECTED[f"tangent_m{m}"] = (min(sp.Rational(m, 2) * pi, 2 * pi), "p" if m <= 4 else "nu")


@pytest.mark.parametrize("name", sorted(EXPECTED))
def test_validity_range(name: str) -> None:
    result = validity(derive_expression(lookup(name).expression))
    phi_max, first_cause = EXPECTED[name]
    assert result.phi_max == phi_max
    assert not result.numeric_only
    assert first_cause in {s.quantity for s in result.singularities if s.phi == phi_max}


def test_det_h_one_has_det_h_one_throughout() -> None:
    result = validity(derive_expression(lookup("det_h_one").expression))
    assert all(s.quantity != "det_H" for s in result.singularities)


def test_table_1_differs_only_for_linear_parameters() -> None:
    differences = {name for name, printed in PAPER_TABLE_1_VALIDITY.items()
                   if validity(derive_expression(lookup(name).expression)).phi_max != printed}
    assert differences == {"linear"}
    linear = validity(derive_expression(lookup("linear").expression))
    causes = {s.quantity for s in linear.singularities if s.phi == pi / 2}
    assert causes == {"p_prime", "det_H", "monotonicity"}


def test_edge_values() -> None:
    assert validity(derive_expression(lookup("euler_rodrigues").expression)).p_max_float == pytest.approx(2)
    assert validity(derive_expression(lookup("wiener_milenkovic").expression)).p_max_float == float("inf")
    rv = validity(derive_expression(lookup("rotation_vector").expression))
    assert rv.p_max_float == pytest.approx(2 * 3.141592653589793)


def test_non_pi_multiple_is_reported_numerically() -> None:
    # p = phi (1 + phi^2/10): p' > 0 always; nu -> 0 at 2 pi; det H involves 1/p'.
    result = validity(derive_expression(parse_expression("atan(phi)*2")))
    # atan is bounded: p' = 2/(1+phi^2) never vanishes, nu -> 0 at 2 pi.
    assert result.phi_max == 2 * pi


def test_analysis_is_fast() -> None:
    _validity_of.cache_clear()
    for name in ("cayley_gibbs_rodrigues", "det_h_one", "tangent_m5", "sine_m3"):
        d = derive_expression(family_member("tangent", 5).expression if name == "tangent_m5"
                              else lookup(name).expression)
        started = time.process_time()  # CPU time: the wall time of a loaded CI run measures the load
        validity(d)
        assert time.process_time() - started < 30  # hang-catcher only (was 1.5 s)


def test_symbolic_candidates_find_poles_inside_tan_and_zeros_of_p_prime() -> None:
    from symrot.core.singularities import _symbolic_candidates

    p = 2 * sp.tan(parse_expression("phi") / 2)
    poles, confirmed = _symbolic_candidates(p, sp.diff(p, parse_expression("phi")))
    assert set(poles) == {pi, 3 * pi} and confirmed


def test_transcendental_angle_falls_back_to_numeric() -> None:
    # p = phi cos(phi): p' = cos(phi) - phi sin(phi) = 0 at phi tan(phi) = 1; solveset gives a
    # ConditionSet, so the angle is numeric only.
    result = validity(derive_expression(parse_expression("phi*cos(phi)")))
    assert result.numeric_only
    assert isinstance(result.phi_max, sp.Float)
    assert result.phi_max_float == pytest.approx(0.8603335890193798, abs=1e-15)
    assert "monotonicity" in {s.quantity for s in result.singularities
                              if s.phi_float == result.phi_max_float}


@pytest.mark.parametrize("text, edge, limit", [
    ("asin(phi)", sp.S.One, "edge"),
    ("2*asin(phi/2)", sp.Integer(2), "edge"),
    ("phi/sqrt(1-phi**2)", sp.S.One, "oo"),
    ("log((1+phi)/(1-phi))/2", sp.S.One, "oo"),
])
def test_the_edge_of_the_real_domain_is_a_singularity(text: str, edge: sp.Expr, limit: str) -> None:
    started = time.monotonic()
    result = validity(derive_expression(parse_expression(text)))
    assert result.phi_max == edge
    p_events = [s for s in result.singularities if s.quantity == "p"]
    assert p_events and p_events[0].phi == edge and p_events[0].limit == limit
    assert (result.p_max_float == float("inf")) == (limit == "oo")
    assert time.monotonic() - started < 120  # hang-catcher: 2x DERIVE_TIME_LIMIT (was 20 s)


def test_solveset_is_tried_on_one_frequency_or_on_sines_and_cosines_only() -> None:
    """A shape decides (symrot.core.singularities._one_frequency_or_polynomial): solveset took 7–400 s
    on p′ of sums of tangents of several frequencies; their edges are then located numerically."""
    from symrot.core.singularities import _one_frequency_or_polynomial

    shapes = {"tan(phi/4)**2 + 1": True, "sin(phi) + sin(2*phi)/4": True, "cos(phi/3) + cos(phi/2)": True,
              "tan(phi/2)**2/2 + cos(phi)/2 + 1/2": False, "tan(phi/3)**2 + tan(3*phi/4)**2": False}
    for text, expected in shapes.items():
        assert _one_frequency_or_polynomial(parse_expression(text)) is expected, text


@pytest.mark.parametrize(("text", "edge"), [("tan(phi/3) + 8*tan(3*phi/4)/9", 2 * sp.pi / 3),
                                            ("tan(phi/2) + sin(phi)/2", sp.pi)])
def test_sums_of_tangents_have_their_pole_as_the_edge(text: str, edge: sp.Expr) -> None:
    found = validity(derive_expression(parse_expression(text)))
    assert abs(found.phi_max_float - float(edge)) < 1e-12


@pytest.mark.parametrize(("text", "edge"), [("2*sin(phi/2)/cos(phi/2)**3", sp.pi),
                                            ("tan(phi)**3/3 + tan(phi)", sp.pi / 2)])
def test_a_quantity_that_is_merely_small_next_to_a_pole_is_not_a_zero(text: str, edge: sp.Expr) -> None:
    """det H ~ cos¹⁰(φ/2) of 2 sin(φ/2)/cos³(φ/2) is 10⁻²⁸ at φ = 3.1377 and below the absolute
    threshold of a zero all around there: it was read as a zero of det H, which ended the range at
    |p| = 2.6·10⁸ (NaN from φ = 3.1377 in every emitted function). A zero is small relative to the
    values next to it too; the edge is the pole at π, and p is unbounded."""
    found = validity(derive_expression(parse_expression(text)))
    assert abs(found.phi_max_float - float(edge)) < 1e-12
    assert found.p_max_float == float("inf")


def test_infinitely_many_zeros_are_polished_only_near_the_smallest_angles() -> None:
    """p′ = cos(sinh φ) cosh φ of sin(sinh φ) vanishes wherever sinh φ = π/2 + kπ: ~10⁵ zeros in
    (0, 4π]. At most MAX_CANDIDATES brackets per quantity are polished (smallest angles first); the
    edge is the first fold, asinh(π/2)."""
    from symrot.core.singularities import MAX_CANDIDATES, QUANTITIES

    result = validity(derive_expression(parse_expression("sin(sinh(phi))")))
    assert abs(result.phi_max_float - float(sp.asinh(sp.pi / 2))) < 1e-12
    assert len(result.singularities) <= 2 * len(QUANTITIES) * MAX_CANDIDATES  # fold: 2 entries each


def test_the_scale_of_a_base_angle_is_read_without_simplify() -> None:
    from symrot.plan.algebraic import S, linear_scale

    assert linear_scale(S / 4) == 4 and linear_scale(3 * S / 2) == sp.Rational(2, 3)
    assert linear_scale(sp.sinh(S)) is None and linear_scale(-S) is None
    assert linear_scale(sp.sqrt(2) * S) is None


def test_a_jump_of_p_prime_across_zero_ends_the_range() -> None:
    """asin(sin φ) rises to π/2 and falls back: p′ = cos φ/√(1 − sin²φ) jumps from 1 to −1 at π/2,
    never 0 nor ∞, so no zero or pole marked it. The range ran to π with |p| < 0, and every
    ``--emit`` ended in an internal error (ZeroDivisionError)."""
    found = validity(derive_expression(parse_expression("asin(sin(phi))")))
    assert found.phi_max == sp.pi / 2
    assert abs(found.p_max_float - 1.5707963267948966) < 1e-12
    assert found.singularities[0].quantity == "monotonicity" and found.singularities[0].limit == "jump"
    # zeros and poles of p′ that change its sign are not jumps
    for text in ("sin(phi)", "phi/(1 - phi**2/10)"):
        listed = validity(derive_expression(parse_expression(text))).singularities
        assert all(s.limit != "jump" for s in listed)


def test_every_cause_has_its_latex_meaning() -> None:
    """A cause without a meaning made ``symrot sheet`` fail on the functions that have it."""
    from symrot.backends.latex import CAUSE_MEANINGS
    from symrot.core.singularities import CAUSES

    assert set(CAUSES) == set(CAUSE_MEANINGS)


def test_a_cubic_in_the_cosine_is_left_to_the_numeric_scan() -> None:
    """p′ = 1 + 3 sin²φ cos φ of φ + sin³φ is a cubic in cos φ: solveset ran past its 15 s safety
    bound on it and ``derive`` exited 2. It is not attempted (shape, not time); the scan finds the
    zero of p′ at 1.97679 (3c³ − 3c − 1 = 0 in c = cos φ)."""
    from symrot.core.parsing import PHI
    from symrot.core.singularities import _low_degree_in_calls

    assert not _low_degree_in_calls(1 + 3 * sp.sin(PHI) ** 2 * sp.cos(PHI))
    assert _low_degree_in_calls(sp.cos(PHI / 4)) and _low_degree_in_calls(1 / sp.cos(PHI) ** 2)
    found = validity(derive_expression(parse_expression("phi + sin(phi)**3")))
    assert abs(found.phi_max_float - 1.9767889011924048) < 1e-12
    assert found.singularities[0].quantity == "p_prime" and found.numeric_only


def test_inverse_functions_in_p_prime_are_left_to_the_numeric_scan() -> None:
    """p′ of this function (held-out seed 2028, row 10) mixes atan and asin with radicals: solveset
    ran 283 s on it, past its safety bound, and ``--emit`` exited 2. It is not attempted (shape, not
    time); the scan finds the arcsine edge at 3/2, where p′ → ∞."""
    text = ("4*sqrt(3*phi**2/2 + 1)*atan(2*phi)/35 + 2*atan(3*phi/2)/(35*(3*phi**2/2 + 1))"
            " + 36*asin(2*phi/3)/(35*(2*phi**2/3 + 1))")
    started = time.monotonic()
    found = validity(derive_expression(parse_expression(text)))
    assert found.phi_max == sp.Rational(3, 2) and found.numeric_only
    assert {("p", "edge"), ("p_prime", "oo")} <= {(s.quantity, s.limit) for s in found.singularities}
    assert time.monotonic() - started < 120  # hang-catcher: 2x DERIVE_TIME_LIMIT (was 20 s)


def test_a_jump_of_p_itself_ends_the_range() -> None:
    """2 atan(tan(φ/2)) is φ up to π and falls to −π there, while SymPy's p′ is 1 everywhere: the
    analysis reported no singular angle in (0, 4π] and the emitted code an unbounded range. A fall
    of p across a pole or a logarithm (tan φ, asinh(tan φ) at π/2) is not a jump."""
    found = validity(derive_expression(parse_expression("2*atan(tan(phi/2))")))
    assert found.phi_max == sp.pi and abs(found.p_max_float - 3.141592653589793) < 1e-15
    assert (found.singularities[0].quantity, found.singularities[0].limit) == ("p", "jump")
    for text in ("tan(phi)", "asinh(tan(phi))"):
        listed = validity(derive_expression(parse_expression(text))).singularities
        assert all(s.limit != "jump" for s in listed), text
