"""Quaternion conversion, composition and rescaling (eqs 18-19, 41-47, 53, 74-75), at 50 digits."""

from __future__ import annotations

import random

import mpmath
import pytest
import sympy as sp

from symrot.core.derivation import derive_expression
from symrot.core.operations import (
    from_quaternion_scale,
    from_quaternion_series,
    paper_rescaling_claims,
    quaternion_coefficients,
    rescale_factor,
)
from symrot.core.parsing import PHI
from symrot.core.registry import lookup

from .helpers import DIGITS, axial_matrix, max_abs, mp_function, random_axis

WIDE = ["rotation_vector", "wiener_milenkovic", "sine_m4", "det_h_one", "tangent_m3", "sine_m6"]


@pytest.mark.parametrize("name", ["wiener_milenkovic", "det_h_one", "linear", "sine_m3"])
def test_to_quaternion_is_euler_rodrigues(name: str) -> None:
    p = lookup(name).expression
    e0, c = (mp_function(f) for f in quaternion_coefficients(p))
    with mpmath.workdps(DIGITS):
        for angle in (mpmath.mpf("0.2"), mpmath.mpf("1.1")):
            assert abs(e0(angle) - mpmath.cos(angle / 2)) < mpmath.mpf(10) ** -45
            assert abs(c(angle) * mp_function(p)(angle) - mpmath.sin(angle / 2)) < mpmath.mpf(10) ** -45


@pytest.mark.parametrize("name", ["rotation_vector", "wiener_milenkovic", "det_h_one"])
def test_from_quaternion_series_matches_closed_form(name: str) -> None:
    p = lookup(name).expression
    coefficients = from_quaternion_series(p, 8)
    sigma = mp_function(from_quaternion_scale(p))
    with mpmath.workdps(DIGITS):
        angle = mpmath.mpf("0.05")
        y = (2 * mpmath.sin(angle / 2)) ** 2
        series = sum(mpmath.mpf(c.p) / c.q * y**j for j, c in enumerate(coefficients))
        assert abs(series - sigma(angle)) < mpmath.mpf(10) ** -25


@pytest.mark.parametrize("name", WIDE)
def test_rescaled_vector_represents_the_same_rotation(name: str) -> None:
    p = lookup(name).expression
    d = derive_expression(p)
    factor = mp_function(rescale_factor(p))
    rng = random.Random(name)
    with mpmath.workdps(DIGITS):
        for _ in range(3):
            angle = mpmath.mpf(rng.uniform(3.3, 6.0))
            u = random_axis(rng)
            p_hat_length = factor(angle) * mp_function(p)(angle)  # signed, along u
            hat_angle = angle - 2 * mpmath.pi
            assert abs(mp_function(p)(hat_angle) - p_hat_length) < mpmath.mpf(10) ** -40
            assert abs(hat_angle) <= mpmath.pi
            R = axial_matrix(d.tensors["R"].u_basis, angle, u)
            R_hat = axial_matrix(d.tensors["R"].u_basis, hat_angle, u)
            assert max_abs(R - R_hat) < mpmath.mpf(10) ** -40


def test_paper_rescaling_41_holds_and_45_has_the_wrong_sign() -> None:
    findings = {}
    for claim in paper_rescaling_claims():
        f = mp_function(claim.printed_factor - claim.mechanism_factor)
        g = mp_function(claim.printed_factor + claim.mechanism_factor)
        with mpmath.workdps(DIGITS):
            angles = [mpmath.mpf(a) for a in ("3.4", "4.5", "5.9")]
            if all(abs(f(a)) < mpmath.mpf(10) ** -40 for a in angles):
                findings[claim.equation] = "holds"
            elif all(abs(g(a)) < mpmath.mpf(10) ** -40 for a in angles):
                findings[claim.equation] = "sign"
            else:
                findings[claim.equation] = "fails"
    assert findings == {"41": "holds", "45": "sign"}


@pytest.mark.parametrize("name", ["wiener_milenkovic", "sine_m4", "det_h_one"])
def test_composition_18_19_equals_matrix_product(name: str) -> None:
    """p3 from eqs (18)-(19) gives R(p3) = R(p2) R(p1) (p1 applied first)."""
    p = lookup(name).expression
    d = derive_expression(p)
    nu, eps = (mp_function(d.scalars_raw[k]) for k in ("nu", "epsilon"))
    p_of = mp_function(p)
    rng = random.Random(3)
    with mpmath.workdps(DIGITS):
        a1, a2 = mpmath.mpf("0.8"), mpmath.mpf("1.3")
        u1, u2 = random_axis(rng), random_axis(rng)
        v1, v2 = p_of(a1) * u1, p_of(a2) * u2
        c3 = nu(a1) / eps(a1) * nu(a2) / eps(a2) - (nu(a1) * v1).T * (nu(a2) * v2) / 4  # (18)
        c3 = c3[0] if hasattr(c3, "rows") else c3
        cross = mpmath.matrix([v1[1] * v2[2] - v1[2] * v2[1], v1[2] * v2[0] - v1[0] * v2[2],
                               v1[0] * v2[1] - v1[1] * v2[0]])
        w = (nu(a1) / eps(a1)) * nu(a2) * v2 + (nu(a2) / eps(a2)) * nu(a1) * v1 \
            - nu(a1) * nu(a2) * cross / 2  # (19): nu3 p3
        a3 = 2 * mpmath.atan2(mpmath.norm(w) / 2, c3)
        u3 = w / mpmath.norm(w)
        R1 = axial_matrix(d.tensors["R"].u_basis, a1, u1)
        R2 = axial_matrix(d.tensors["R"].u_basis, a2, u2)
        R3 = axial_matrix(d.tensors["R"].u_basis, a3, u3)
        assert max_abs(R3 - R2 * R1) < mpmath.mpf(10) ** -40
        assert abs(mpmath.norm(w) - nu(a3) * p_of(a3)) < mpmath.mpf(10) ** -40


def test_rescale_factor_closed_forms() -> None:
    assert sp.simplify(rescale_factor(4 * sp.tan(PHI / 4)) + 1 / sp.tan(PHI / 4) ** 2) == 0
    assert sp.simplify(rescale_factor(PHI) - (PHI - 2 * sp.pi) / PHI) == 0


def test_the_scale_is_reduced_to_e0_only_for_trigonometric_p(monkeypatch: pytest.MonkeyPatch) -> None:
    """σ = p/sin(φ/2) becomes algebraic in e₀ = cos(φ/2) (eq 74) for trigonometric p, and the
    reduction's simplification (up to 3.2 s) is not run where another call of φ would leave a
    transcendental function of acos e₀ (sinh, asin, atan, the real cube root of eq 35)."""
    from symrot.core.parsing import parse_expression
    from symrot.plan import quaternion as quaternion_plan

    e0 = quaternion_plan.E0
    assert sp.simplify(quaternion_plan.scale_in_e0(4 * sp.tan(PHI / 4)) - 4 / (e0 + 1)) == 0
    assert sp.simplify(quaternion_plan.scale_in_e0(sp.sin(PHI)) - 2 * e0) == 0

    def refused(*args: object) -> None:
        raise AssertionError("the reduction ran")

    monkeypatch.setattr(quaternion_plan, "bounded", refused)
    for text in ("4*sqrt(3*phi**2/2 + 1)*sinh(2*phi)/35 + 36*cos(2*phi/3)*asin(2*phi/3)/35",
                 "cbrt(6*(phi - sin(phi)))", "2*atan(phi/2)", "tanh(phi)"):
        assert quaternion_plan.scale_in_e0(parse_expression(text)) is None, text
