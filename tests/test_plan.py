"""Evaluation plans (issue 4): constants, algebraic forms, branches per precision, the angle."""

from __future__ import annotations

import mpmath
import numpy as np
import pytest
import sympy as sp

from symrot.api import derive
from symrot.core.parsing import PHI
from symrot.plan.algebraic import S, X
from symrot.plan.builder import evaluation_plan
from symrot.plan.forms import near_half_turn
from symrot.plan.ir import Algebraic, Branch, ClosedAngle, Constant, NewtonAngle
from symrot.plan.targets import CHEAP_TERMS

from .reference import GeneratingFunction, Reference


@pytest.fixture(scope="module")
def det_h_one_plan():
    return evaluation_plan(derive("det_h_one").derivation, "det_h_one")


def test_identically_constant_coefficients_are_constants() -> None:
    derivation = derive("euler_rodrigues").derivation
    plan = evaluation_plan(derivation, "euler_rodrigues")
    coefficient = plan.precisions["float64"].coefficients["H_inverse_2"]
    assert isinstance(coefficient, Constant)
    assert coefficient.value == derivation.constant_value("H_inverse_2")


def test_algebraic_coefficients_have_no_branch() -> None:
    plan = evaluation_plan(derive("cayley_gibbs_rodrigues").derivation, "cgr")
    h_inverse_0 = plan.precisions["float64"].coefficients["H_inverse_0"]
    assert isinstance(h_inverse_0, Algebraic)
    assert sp.simplify(h_inverse_0.expression - (1 + X / 4)) == 0
    assert isinstance(plan.precisions["float64"].angle, ClosedAngle)


def test_wiener_milenkovic_nu_squared_over_epsilon_is_rational_in_x() -> None:
    derivation = derive("wiener_milenkovic").derivation
    plan = evaluation_plan(derivation, "wiener_milenkovic")
    coefficients = plan.precisions["float64"].coefficients
    nu, epsilon = coefficients["nu"], coefficients["epsilon"]
    assert isinstance(nu, Algebraic) and isinstance(epsilon, Algebraic)
    ratio = sp.simplify(nu.expression ** 2 / epsilon.expression - 16 * (16 - X) / (16 + X) ** 2)
    assert ratio == 0


def test_branches_use_exact_series_and_differ_per_precision(det_h_one_plan) -> None:
    derivation = derive("det_h_one").derivation
    wide = det_h_one_plan.precisions["float64"].coefficients["R_2"]
    narrow = det_h_one_plan.precisions["float32"].coefficients["R_2"]
    assert isinstance(wide, Branch) and isinstance(narrow, Branch)
    series = derivation.series_in_x("R_2", len(wide.horner))
    assert list(wide.horner) == series
    assert len(narrow.horner) < len(wide.horner)
    # not the usual |p| ~ 1e-3 switch with 2-3 terms: the switch sits where the closed form is good
    assert wide.threshold > 1e-2 and len(wide.horner) > 3
    # the polynomial up to its switch against tests/reference.py (not the plan's own measured_ulp):
    # within an ulp (measured 0.23 float64, 0.25 float32)
    reference = Reference(GeneratingFunction("cbrt(6*(phi - sin(phi)))", cancels=True))
    for branch, dtype in ((wide, np.float64), (narrow, np.float32)):
        for x in (dtype(branch.threshold), dtype(branch.threshold / 2), dtype(branch.threshold / 10)):
            value = dtype(0)
            for c in reversed(branch.horner):
                value = dtype(value * x + dtype(float(c)))
            exact = axial_coefficient(reference, "R_2", float(x))
            assert abs(float(value) - exact) <= np.finfo(dtype).eps * abs(exact), (dtype, float(x))


def test_angle_without_closed_inverse_uses_newton(det_h_one_plan) -> None:
    angle = det_h_one_plan.precisions["float64"].angle
    assert isinstance(angle, NewtonAngle)
    assert angle.start[:2] == (1, sp.Rational(1, 60))
    assert angle.phi_max == pytest.approx(2 * np.pi)


def test_an_iterated_angle_gives_every_backend_one_switch(det_h_one_plan) -> None:
    """Where φ iterates, the smaller switch's closed forms (measured on angles rounded to nearest)
    take the iteration's error too: eq 35's float64 H⁻¹ across the axis was 2.0 ulp off in the
    NumPy module for |p| = 0.1–0.33, where the threshold's polynomial is 0.5. Such a plan gives
    every backend the threshold (plan._single_switch); a plan with a closed angle keeps both."""
    for precision in det_h_one_plan.precisions.values():
        branches = [c for c in precision.coefficients.values() if isinstance(c, Branch)]
        assert branches
        for branch in branches:
            assert branch.smallest_switch == (branch.threshold, branch.horner)
    closed = evaluation_plan(derive("rotation_vector").derivation, "rotation_vector")
    r_2 = closed.precisions["float64"].coefficients["R_2"]
    assert isinstance(r_2, Branch) and r_2.smallest_switch[0] < r_2.threshold


def test_forms_through_s_are_also_measured_in_half_angles(det_h_one_plan) -> None:
    """s·sin φ/(4 sin²(φ/2)), H⁻¹'s part across the axis written through s, has the half-angle form
    s cos(φ/2)/(2 sin(φ/2)) (one rounding of φ less): float32 eq 35 takes it (0.79 ulp on the plan's
    grid; the form it replaced, 1.24)."""
    branch = det_h_one_plan.precisions["float32"].coefficients["H_inverse_across"]
    assert isinstance(branch, Branch)
    half = PHI / 2
    assert sp.simplify(branch.closed - S * sp.cos(half) / (2 * sp.sin(half))) == 0


def test_sine_family_inverse_is_closed_form() -> None:
    plan = evaluation_plan(derive("sine_m4").derivation, "sine_m4")
    angle = plan.precisions["float32"].angle
    # 4 asin(s/4) rewritten as 4 atan2(s, sqrt(d)), d = 16 - |p|^2 computed with compensated sums
    assert isinstance(angle, ClosedAngle) and angle.expression.has(sp.atan2)
    assert plan.complement == 16


def axial_coefficient(reference: Reference, name: str, x: float) -> mpmath.mpf:
    """c_k of T = c₀ I + c₁ (p×) + c₂ (p×)² (``name`` = "T_k", T one of R, H, G) at |p|² = x, read off
    the reference's T at p = √x e₃: T₂₂ = c₀, T₁₀ = c₁ √x, T₂₂ − T₀₀ = c₂ x."""
    tensor, k = name.split("_")
    with mpmath.workdps(80):
        s = mpmath.sqrt(mpmath.mpf(x))
        t = getattr(reference.state([mpmath.mpf(0), mpmath.mpf(0), s]), tensor)
        return +[t[2, 2], t[1, 0] / s, (t[2, 2] - t[0, 0]) / s**2][int(k)]


@pytest.mark.parametrize("label, dtype", [("float64", np.float64), ("float32", np.float32)])
def test_small_rotations_take_short_polynomials_not_library_calls(label: str, dtype: type) -> None:
    """The switch moves up as far as CHEAP_TERMS terms stay accurate: for the rotation vector,
    R's coefficients are polynomials up to |φ| > 0.5 (the accuracy alone would switch at
    |φ| ~ 1e-6), and those polynomials match the independent reference of tests/reference.py (eq 1
    and ω = H ṗ, 60 digits) at the switch to within an ulp."""
    derivation = derive("rotation_vector").derivation
    plan = evaluation_plan(derivation, "rotation_vector")
    epsilon = float(np.finfo(dtype).eps)
    reference = Reference(GeneratingFunction("phi", phi_max_text="2*pi"))
    for name in ("R_1", "R_2", "H_1", "G_1"):
        branch = plan.precisions[label].coefficients[name]
        assert isinstance(branch, Branch)
        assert branch.threshold > 0.25 and len(branch.horner) <= CHEAP_TERMS, (name, branch.threshold)
        x = dtype(branch.threshold)
        value = dtype(0)
        for c in reversed(branch.horner):
            value = dtype(value * x + dtype(float(c)))
        exact = axial_coefficient(reference, name, float(x))
        assert abs(float(value) - float(exact)) <= 1.0 * epsilon * abs(float(exact)), name


def test_across_axis_part_is_planned_where_c0_is_not_constant(det_h_one_plan) -> None:
    """T = c0 I + c1 (p x) + c2 (p x)^2 = t I + c1 (p x) + c2 p p^T with t = c0 - c2 |p|^2: t is
    derived (the planar part a - c of the u-basis) and planned as a coefficient of its own where c0
    varies (H = mu I + ... of det_h_one), while R and G (c0 = 1) compute t from c2."""
    from symrot.core.validation import evaluate

    derivation = derive("det_h_one").derivation
    for tensor in derivation.tensors.values():
        c0, _, c2 = tensor.coefficients
        for angle in ("0.31", "1.7", "2.9"):
            expected = evaluate(c0 - c2 * derivation.p**2, angle)
            assert abs(derivation.evaluate(tensor.across_name, angle) - expected) < \
                mpmath.mpf(10) ** -40 * max(1, abs(expected))
    across = det_h_one_plan.across_tensors()
    assert "H" in across and "K" in across
    assert "R" not in across and "G" not in across
    for precision in det_h_one_plan.precisions.values():
        assert "R_across" not in precision.coefficients
        assert not isinstance(precision.coefficients["H_across"], Constant)


def test_forms_in_s_and_x_are_found_inside_products_and_sums() -> None:
    """p = sinh(phi) cosh(phi): 1/p^2 appears as sinh^-2 cosh^-2 inside a larger product, which
    must still become 1/x (the form that does not amplify the angle's rounding)."""
    from symrot.core.parsing import PHI
    from symrot.plan.algebraic import S
    from symrot.plan.measurement import with_length

    product = sp.sinh(PHI) * sp.cosh(PHI)
    assert with_length(2 * sp.sin(PHI / 4) ** 2 / product**2, product) == 2 * sp.sin(PHI / 4) ** 2 / X
    assert with_length(sp.sin(PHI / 2) / product, product) == sp.sin(PHI / 2) / S
    total = sp.sin(PHI) / 2 + sp.sinh(PHI) / 2
    assert with_length(8 * sp.sin(PHI / 4) ** 2 / (sp.sin(PHI) + sp.sinh(PHI)) ** 2, total) == \
        2 * sp.sin(PHI / 4) ** 2 / X
    # a constant factor in p that the product does not share (hypothesis rows 42-43: R_1 recomputed
    # asin(3 phi/4) from the rounded angle, 73 ulp of R at 4/3 - 1e-5), and powers left over
    scaled = sp.Rational(4, 3) * sp.cosh(3 * PHI / 4) * sp.asin(3 * PHI / 4)
    forms = [3 * sp.sin(PHI) / (4 * sp.cosh(3 * PHI / 4) * sp.asin(3 * PHI / 4)),
             9 * sp.sin(PHI / 2) ** 2 / (8 * sp.cosh(3 * PHI / 4) ** 2 * sp.asin(3 * PHI / 4) ** 2),
             sp.cosh(3 * PHI / 4) ** 3 * sp.asin(3 * PHI / 4) * sp.sin(PHI)]
    written = [with_length(form, scaled) for form in forms]
    assert written[:2] == [sp.sin(PHI) / S, 2 * sp.sin(PHI / 2) ** 2 / X]
    assert written[2] == 3 * S * sp.sin(PHI) * sp.cosh(3 * PHI / 4) ** 2 / 4
    for form, rewritten in zip(forms, written, strict=True):  # the same function of phi
        back = rewritten.xreplace({X: scaled**2, S: scaled})
        assert all(abs(sp.N((back - form).subs(PHI, angle), 30)) < 1e-25 for angle in (0.3, 1.1, 1.3))
    # a sum written otherwise by simplification (hypothesis row 22: G_2 recomputed p from the
    # rounded angle, 7 ulp next to 2 pi); a sum that is not a multiple of p stays
    total = PHI * sp.cosh(3 * PHI / 2) / 2 + 2 * sp.atan(PHI / 4) / (PHI**2 / 2 + 1)
    other = PHI * sp.cosh(3 * PHI / 2) + 8 * sp.atan(PHI / 4) / (PHI**2 + 2)  # 2 p
    assert with_length(2 * sp.sin(PHI / 4) ** 2 / other**2, total) == sp.sin(PHI / 4) ** 2 / (2 * X)
    assert with_length(sp.sin(PHI / 2) * other, total) == 2 * S * sp.sin(PHI / 2)
    unrelated = PHI * sp.cosh(3 * PHI / 2) + sp.atan(PHI / 4)
    assert with_length(1 / unrelated, total) == 1 / unrelated


@pytest.mark.parametrize(("argument", "form", "expected"), [
    # p² simplified to (φ² + 2) sinh²(2φ)/8: the sum φ²/2 + 1 of p appears doubled (hypothesis row
    # 53: G_2 recomputed sinh(2φ̂)², 17.7 ulp of G in float32 at 2π − 10⁻⁶)
    ("sqrt(phi**2/2 + 1)*sinh(2*phi)/2", 16 * sp.sin(PHI / 4) ** 2 / ((PHI**2 + 2) * sp.sinh(2 * PHI) ** 2),
     2 * sp.sin(PHI / 4) ** 2 / X),
    ("sqrt(phi**2/2 + 1)*sinh(2*phi)/2", 2 * sp.sin(PHI / 2) / (sp.sqrt(PHI**2 + 2) * sp.sinh(2 * PHI)),
     sp.sqrt(2) * sp.sin(PHI / 2) / (2 * S)),
    # a sum p whose terms share factors: its factored form is a product (hypothesis row 80)
    ("13*phi**3*cosh(phi/2)/3 + phi*cosh(phi/2)",
     18 * sp.sin(PHI / 4) ** 2 / (PHI**2 * (13 * PHI**2 + 3) ** 2 * sp.cosh(PHI / 2) ** 2),
     2 * sp.sin(PHI / 4) ** 2 / X),
])
def test_forms_in_s_and_x_are_found_when_a_factor_of_p_is_rescaled(argument: str, form: sp.Expr,
                                                                   expected: sp.Expr) -> None:
    from symrot.core.parsing import parse_expression
    from symrot.plan.measurement import with_length

    p = parse_expression(argument)
    written = with_length(form, p)
    assert written == expected
    back = written.xreplace({X: p**2, S: p})
    angles = (sp.Rational(3, 10), sp.Rational(11, 10), sp.Rational(59, 10))
    assert all(abs(sp.N((back - form).subs(PHI, angle), 30)) < 1e-25 for angle in angles)


def test_the_half_angle_form_through_x_is_a_candidate_when_p_is_a_sum_of_cosines() -> None:
    """Hypothesis row 120: G_2 = 25 (1 - cos(phi/2))/(5 p)^2. Its half-angle form rewrites cos(phi/3)
    inside p, so p is no longer recognized in it; written through x first, (1 - cos(phi/2))/x
    cancels at small phi. The planned form recomputed p from the rounded angle (9 ulp of G in
    float32 at 6.18); 2 sin^2(phi/4)/x must be measured."""
    from symrot.core.parsing import parse_expression
    from symrot.plan.branches import candidate_forms

    p = parse_expression("3*phi*cos(phi/3)/5 + 2*sqrt(2*phi**2 + 1)*sinh(phi)/5")
    closed = 25 * (1 - sp.cos(PHI / 2)) / (3 * PHI * sp.cos(PHI / 3)
                                           + 2 * sp.sqrt(2 * PHI**2 + 1) * sp.sinh(PHI)) ** 2
    _, forms = candidate_forms(closed, p, 2 * np.pi, None, None)
    assert 2 * sp.sin(PHI / 4) ** 2 / X in forms


def test_tensor_coefficients_are_measured_as_they_enter_the_tensor() -> None:
    """G_2 of sinh(phi) cosh(phi) next to 2 pi is ~ 2/x, far below G_2(0) = 1/8: measured relative
    to 1/8 its form in phi (sinh amplifies the float32 angle's rounding 4 times, 6 ulp of G_2 x)
    would tie with 2 sin^2(phi/4)/x; measured relative to |G| / |p|^2 it must lose."""
    from symrot.core.singularities import validity
    from symrot.plan.branches import plan_branch, tensor_part
    from symrot.plan.forms import closed_inverse
    from symrot.plan.targets import MAX_TERMS

    derivation = derive("sinh(phi)*cosh(phi)").derivation
    phi_max = float(validity(derivation).phi_max_float)
    branch = plan_branch(derivation.simplified_form("G_2"), derivation.series_in_x("G_2", MAX_TERMS),
                         derivation.p ** 2, phi_max, np.float32, derivation.p,
                         closed_inverse(derivation.p, derivation.kappa), None, tensor_part(derivation, "G_2"))
    assert branch.closed.has(X)
    assert sp.simplify(branch.closed - 2 * sp.sin(PHI / 4) ** 2 / X) == 0
    # that form in float32 on rounded inputs (|p| on e₃, x = fl(|p|²), the angle rounded to nearest)
    # against tests/reference.py's G (not the plan's own edge_ulp), relative to |G|/|p|²: within
    # 4 ulp (measured 1.8 at 2π(1 − 10⁻³))
    function = GeneratingFunction("sinh(phi)*cosh(phi)", phi_max_text="2*pi")
    reference, f32 = Reference(function), np.float32
    for k in range(1, 7):
        with mpmath.workdps(40):
            s = f32(float(function.value(2 * mpmath.pi * (1 - mpmath.mpf(10) ** -k))))
            phi = f32(float(function.inverse(mpmath.mpf(float(s)))))
        x = f32(s * s)
        value = f32(f32(2) * f32(np.sin(f32(phi / f32(4)))) ** 2 / x)
        exact = axial_coefficient(reference, "G_2", float(s) ** 2)
        assert abs(float(value) - exact) * float(s) ** 2 <= 4 * np.finfo(f32).eps, k


def test_the_reduction_to_x_is_sized_by_the_largest_multiple_angle() -> None:
    """symrot.plan.algebraic.REDUCTION_MULTIPLE: for tan(φ/20) the coefficient 4 sin²(φ/2)/(…) expands
    sin(20η) (η = atan(s)/2) and simplified in 34 s, past its nominal bound; it is not attempted.
    The tangent family up to m = 6 (sin φ = sin(12η) for 6 tan(φ/6)) still is."""
    from symrot.core.parsing import PHI
    from symrot.plan.algebraic import REDUCTION_MULTIPLE, expanded_in_s

    assert REDUCTION_MULTIPLE >= 12
    tangent = sp.tan(PHI / 20)
    beyond = 4 * sp.sin(PHI / 2) ** 2 / ((tangent**2 / 20 + sp.Rational(1, 20)) * tangent**2)
    s = sp.Symbol("s", nonnegative=True)
    assert expanded_in_s(beyond, 20 * sp.atan(s)) is None
    within = sp.sin(PHI) / (6 * sp.tan(PHI / 6))
    assert expanded_in_s(within, 6 * sp.atan(s / 6)) is not None


def test_an_inverse_of_a_radical_is_not_reduced_to_x() -> None:
    """The closed inverse of tan φ + tan³φ/3 is the atan of Cardano's root of a cubic: SymPy's
    simplify ran into its 6 s bound on each coefficient expanded through it, and ``--emit`` ran out
    of its 60 s budget during planning. No reduction is attempted (the coefficients get branches);
    one whose inverse is an atan of s/k still is."""
    from symrot.plan.algebraic import S, expanded_in_s

    p = sp.tan(PHI) ** 3 / 3 + sp.tan(PHI)
    root = (-81 * S / 2 + sp.sqrt(6561 * S**2 + 2916) / 2) ** sp.Rational(1, 3)
    inverse = -sp.atan(root / 3 - 3 / root)  # as sp.solve wrote it (no longer asked: MAX_SOLVED_DEGREE)
    closed = sp.sin(PHI) / p
    assert expanded_in_s(closed, inverse) is None
    assert expanded_in_s(sp.sin(PHI) / (4 * sp.tan(PHI / 4)), 4 * sp.atan(S / 4)) is not None


def test_whole_multiples_of_the_base_angle_reduce_without_half_angle_radicals() -> None:
    """sin φ/(5 tan(φ/5)) of 5 tan(φ/5) has only whole multiples of θ = atan(s/5): expanded in θ it
    is algebraic in x. Through the half angle η = θ/2 (radicals √((1 ± cos θ)/2)) SymPy's simplify
    found nothing, in 1–2 s; the R₁ of 3 tan(φ/3) was a branch with sin φ/s for the same reason."""
    from symrot.plan.algebraic import S, algebraic_in_x, reduce_to_x

    closed = sp.sin(PHI) / (5 * sp.tan(PHI / 5))
    reduced = reduce_to_x(closed, 5 * sp.atan(S / 5))
    assert reduced is not None
    assert sp.simplify(reduced - (X**2 - 250 * X + 3125) / (X + 25) ** sp.Rational(5, 2)) == 0
    r_1 = algebraic_in_x(sp.sin(PHI) / (3 * sp.tan(PHI / 3)), 3 * sp.atan(S / 3), float("inf"))
    assert r_1 is not None and sp.simplify(r_1 + (X - 27) / (X + 9) ** sp.Rational(3, 2)) == 0


@pytest.mark.parametrize("text, expected", [
    ("sinh(phi)", "asinh(s)"), ("2*sinh(3*phi/2)/3", "2*asinh(3*s/2)/3"), ("tanh(phi)", "atanh(s)")])
def test_hyperbolic_inverses_are_inverse_hyperbolic_functions(text: str, expected: str) -> None:
    """sp.solve writes φ(s) for sinh φ = s as log(s + √(s² + 1)), which loses every digit for small s:
    the plan took the Newton angle, and cosh(φ) = √(1 + x) was never found for H₀ = 1/p′."""
    from symrot.core.parsing import PHI
    from symrot.plan.algebraic import S
    from symrot.plan.forms import closed_angle_error, closed_inverse
    from symrot.plan.targets import ANGLE_TOLERANCE_ULP

    p = sp.sympify(text, locals={"phi": PHI})
    inverse = closed_inverse(p, sp.Integer(1))
    assert inverse is not None and sp.simplify(inverse - sp.sympify(expected, locals={"s": S})) == 0
    assert not inverse.has(sp.log)
    for dtype in (np.float64, np.float32):
        assert closed_angle_error(inverse, p, 2 * np.pi, dtype) <= ANGLE_TOLERANCE_ULP


def test_one_plus_cosine_is_written_through_the_half_angle_next_to_a_half_turn() -> None:
    """k(1 + cos a) → 2k cos²(a/2) (exact), and other sums of a cosine are left: in float64,
    1 + cos φ is 0 within 3·10⁻⁹ of π, and p′ of hypothesis row 113 was infinite there."""
    slope = 4 * sp.cosh(PHI / 3) / (7 * (sp.cos(PHI) + 1)) + 1 / (1 - sp.cos(PHI)) + 2 / (3 + 2 * sp.cos(PHI))
    rewritten = near_half_turn(slope)
    assert rewritten == (2 * sp.cosh(PHI / 3) / (7 * sp.cos(PHI / 2) ** 2) + 1 / (1 - sp.cos(PHI))
                         + 2 / (3 + 2 * sp.cos(PHI)))
    near_pi = np.pi - 3e-9
    with np.errstate(divide="ignore"):
        plain, half = (float(sp.lambdify(PHI, e, "numpy")(near_pi))
                       for e in (1 / (1 + sp.cos(PHI)), near_half_turn(1 / (1 + sp.cos(PHI)))))
    with mpmath.workdps(30):
        exact = 1 / (1 + mpmath.cos(mpmath.mpf(near_pi)))
    assert not np.isfinite(plain) or abs(plain / float(exact) - 1) > 1e-3
    assert abs(half / float(exact) - 1) < 1e-13


def test_every_branch_measures_candidate_forms_computed_before_the_precisions(monkeypatch) -> None:
    """The candidate forms of every branch in x are computed once, half in a forked child, before
    the precisions part (plan._prepare_shared_work), and equal those computed in place."""
    import symrot.plan.branches as branches
    import symrot.plan.builder as plan
    from symrot.core.derivation import derive_expression
    from symrot.core.parsing import parse_expression

    original_forms, original_precision = plan._candidate_forms, plan._precision_plan
    late: list[sp.Expr] = []
    in_precision = False

    def forms(*key):
        if in_precision and key[1] != PHI:
            late.append(key[0])
        return original_forms(*key)

    def precision(shared, label, dtype):
        nonlocal in_precision
        in_precision = True
        try:
            return original_precision(shared, label, dtype)
        finally:
            in_precision = False

    monkeypatch.setattr(plan, "_candidate_forms", forms)
    monkeypatch.setattr(branches, "_candidate_forms", forms)
    monkeypatch.setattr(plan, "_precision_plan", precision)
    derivation = derive_expression(parse_expression("2*asinh(phi/2)"))  # a p no other test plans
    result = plan.evaluation_plan(derivation, "two_asinh_half")
    assert late == []  # float64, planned in this process, computed none of them itself
    keys = [key for key in plan._CANDIDATES if key[1] == derivation.p]
    assert keys and any(isinstance(c, Branch) for c in result.precisions["float64"].coefficients.values())
    for key in keys:
        assert plan._CANDIDATES[key] == original_forms(*key), key[0]


def test_hyperbolic_complement_is_the_same_function_without_cancellation() -> None:
    """k − k tanh²(u) in a sum becomes k/cosh²(u) (the forms through φ = 4 tanh(s/4) of 4 atanh(φ/4));
    other sums are left alone; the value is unchanged (40 digits at a large u, where the old form
    has lost every digit in float64)."""
    from symrot.plan.forms import hyperbolic_complement
    from symrot.plan.measurement import S

    form = 16 - 16 * sp.tanh(S / 4) ** 2 + PHI
    rewritten = hyperbolic_complement(form)
    assert rewritten == PHI + 16 / sp.cosh(S / 4) ** 2
    assert hyperbolic_complement(2 - sp.tanh(S) ** 2) == 2 - sp.tanh(S) ** 2
    point = {S: sp.Integer(160), PHI: sp.Rational(1, 3)}
    assert abs(sp.N((form - rewritten).subs(point), 40)) < sp.Float("1e-60")
    assert float(16 - 16 * np.tanh(40.0) ** 2) == 0.0 != float(16 / np.cosh(40.0) ** 2)
