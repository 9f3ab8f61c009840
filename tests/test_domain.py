"""The domain of generated code for unbounded p (issue 17): right up to x_limit, NaN beyond it.

Wiener–Milenkovic's tangent was 1.6e-159·I for p = (6e79, 8e79, 0) (exact first row
[-4.48e-160, 1.536e-159, 1.024e-238]) because 128/(x + 16)² overflowed; the plan's x_limit
(symrot/plan/domain.py) now ends the domain before any printed form goes wrong, and the C header and the
NumPy module both print it."""

from __future__ import annotations

import math
from pathlib import Path

import mpmath
import numpy as np
import pytest
import sympy as sp

from symrot.api import derive
from symrot.core.derivation import tensor_definitions
from symrot.plan.builder import evaluation_plan
from tests.edges import documented_x_limit
from tests.edges import ladder as edges_ladder
from tests.helpers import axial_matrix
from tests.test_numpy_backend import load

ROOT = Path(__file__).resolve().parent.parent
UNBOUNDED = ("wiener_milenkovic", "cayley_gibbs_rodrigues")
FUNCTIONS = {"rotation_matrix": "R", "tangent": "H", "tangent_inverse": "H_inverse", "root_matrix": "G",
             "root_tangent": "K"}


def _reference(name: str, tensor: str, p: np.ndarray) -> np.ndarray:
    """The tensor at p from the derivation's u-basis form, φ = 4 atan(s/4) or 2 atan(s/2), 200 digits."""
    expression = derive(name).p
    with mpmath.workdps(200):
        vector = mpmath.matrix([mpmath.mpf(float(c)) for c in p])
        s = mpmath.norm(vector)
        phi = _closed_inverse(name, s)
        matrix = axial_matrix(tensor_definitions(expression)[tensor], phi, vector / s)
        return np.array([[float(matrix[i, j]) for j in range(3)] for i in range(3)])


def _closed_inverse(name: str, s: mpmath.mpf) -> mpmath.mpf:
    return 4 * mpmath.atan(s / 4) if name == "wiener_milenkovic" else 2 * mpmath.atan(s / 2)


@pytest.mark.parametrize("name", UNBOUNDED)
def test_numpy_module_is_right_below_x_limit_and_nan_beyond(name: str) -> None:
    """The documented x_limit ("|p|^2 < 2^K (2^L in float32)" in the module's docstring, not the
    plan's): NaN from the first |p|² at or above it (tests/edges.py's ladder: every float from 3 ulps
    below to 3 ulps above it), finite below, and right at |p| = √x_limit/2."""
    path = ROOT / "generated" / "numpy" / f"{name}.py"
    module = load(path, f"domain_{name}")
    axis = np.array([0.6, 0.8, 0.0])
    for dtype in (np.float64, np.float32):
        limit = documented_x_limit(path, dtype)
        ladder = edges_ladder(mpmath.mpf(limit), dtype, "limit")
        p = np.array([probe.p for probe in ladder], dtype=dtype)
        inside = np.array([probe.inside for probe in ladder])
        eps = float(np.finfo(dtype).eps)
        for function in FUNCTIONS:
            got = getattr(module, function)(p)
            assert np.isnan(got[~inside]).all() and np.isfinite(got[inside]).all(), (function, dtype)
        half = (axis * math.sqrt(limit) * 0.5).astype(dtype)
        for function, tensor in FUNCTIONS.items():
            got = getattr(module, function)(half).astype(np.float64)
            exact = _reference(name, tensor, half.astype(np.float64))
            assert np.max(np.abs(got - exact)) <= 64 * eps * np.max(np.abs(exact)), (function, dtype)


def test_the_reported_wiener_milenkovic_tangent_is_nan_not_wrong() -> None:
    """x = 10^160 = 2^531.5: H₂ = (16/(x + 16))²/8 ≈ 3·10⁻³¹⁹ is subnormal there (18 bits), so the
    tangent would be off by ~10⁻⁵ relative; the domain (2^518 in float64) ends before."""
    module = load(ROOT / "generated" / "numpy" / "wiener_milenkovic.py", "domain_wm_report")
    assert np.all(np.isnan(module.tangent(np.array([6e79, 8e79, 0.0]))))


@pytest.mark.parametrize("name", UNBOUNDED)
def test_float32_reaches_the_last_representable_angle(name: str) -> None:
    """Every float32 angle below φ_max is inside the float32 domain and meets the 4-ulp target.

    Wiener–Milenkovic's float32 module was NaN from φ = 2π − 7.6·10⁻⁶ (x = 2^42): det H =
    4096/(x + 16)³ overflowed in its denominator (symrot.plan.algebraic.bounded_powers)."""
    module = load(ROOT / "generated" / "numpy" / f"{name}.py", f"domain32_{name}")
    m = 4 if name == "wiener_milenkovic" else 2
    phi_max = m * math.pi / 2  # p = m tan(φ/m) → ∞
    eps = float(np.finfo(np.float32).eps)
    axis = np.array([0.6, 0.8, 0.0])
    for phi in (float(np.nextafter(np.float32(phi_max), np.float32(0))), phi_max - 1e-6):
        p = (axis * m * math.tan(phi / m)).astype(np.float32)
        for function, tensor in FUNCTIONS.items():
            got = getattr(module, function)(p).astype(np.float64)
            exact = _reference(name, tensor, p.astype(np.float64))
            assert np.all(np.isfinite(got)), (function, phi)
            assert np.max(np.abs(got - exact)) <= 4 * eps * np.max(np.abs(exact)), (function, phi)
        with mpmath.workdps(60):
            s = mpmath.norm(mpmath.matrix([mpmath.mpf(float(c)) for c in p]))
            exact_det = float((m * m / (s * s + m * m)) ** (m // 2 + 1))  # cos^(m+2)(φ/m)
        assert abs(float(module.tangent_det(p)) - exact_det) <= 4 * eps * exact_det + 2.0**-149, phi


def test_c_header_prints_the_same_limit() -> None:
    plan = evaluation_plan(derive("wiener_milenkovic").derivation, "wiener_milenkovic")
    header = (ROOT / "generated" / "c" / "symrot_wiener_milenkovic.h").read_text(encoding="utf-8")
    for label in ("float64", "float32"):
        power = math.frexp(plan.precisions[label].x_limit)[1] - 1
        assert f"|p|^2 < 2^{power}" in header


def test_bounded_powers_keep_the_value_and_do_not_overflow_first() -> None:
    """symrot.plan.algebraic.bounded_powers: the same rational function, evaluated without overflow in
    float32 where the expanded denominator (x + a)^n overflows, and printed as a power of the ratio."""
    from symrot.backends.c_printer import SymrotCPrinter
    from symrot.core.functions import BoundedPower
    from symrot.plan.algebraic import X, bounded_powers
    from symrot.plan.evaluation import model_function

    forms = [4096 / (X + 16) ** 3, 128 / (X + 16) ** 2, -16 * (X - 16) / (X + 16) ** 2,
             32 * (X - 16) / (X + 16) ** 3 - 16 / (X + 16) ** 2, 3 * (X + 1) / (2 * X + 9) ** 4]
    eps, tiny = float(np.finfo(np.float32).eps), float(np.finfo(np.float32).tiny)
    for form in forms:
        rewritten = bounded_powers(form)
        assert rewritten.has(BoundedPower), form
        assert sp.simplify(rewritten.doit() - form) == 0, form
        for power in rewritten.atoms(BoundedPower):
            base = power.args[0]
            assert all(0 < float(base.subs(X, v)) <= 1 for v in (0, 1, 1e3, 1e30)), form
        plain, bounded = (model_function(f, [X]) for f in (form, rewritten))
        for k in range(20, 100):  # the first x at which the expanded form goes wrong in float32
            x = sp.Integer(2) ** k * sp.Rational(13, 10)
            exact = float(form.subs(X, sp.Float(x, 60)))
            if abs(float(plain(np.float32(x))) - exact) > 1e-3 * abs(exact):
                break
        assert abs(exact) >= tiny, (form, k)  # it goes wrong while the value is a normal number
        assert abs(float(bounded(np.float32(x))) - exact) <= 8 * eps * abs(exact), (form, k)
    cube = "((16/(x + 16))*(16/(x + 16))*(16/(x + 16)))"  # the compiler computes the ratio once
    assert SymrotCPrinter("float").doprint(bounded_powers(forms[0])) == cube
    assert bounded_powers(16 / (X + 16)) == 16 / (X + 16)  # nothing to bound
    assert bounded_powers(1 / (X - 16) ** 2) == 1 / (X - 16) ** 2  # a pole in the range: no ratio in (0, 1]


def test_a_pole_at_pi_keeps_the_domain_open_past_the_measured_range() -> None:
    """p = tan(φ/2) + sin(φ)/2 has its pole at φ = π, where e₀ = cos(φ/2) → 0. The sweep counted
    e₀ relative to itself ("e_0" read as coefficient 0 of a tensor "e") instead of against the
    unit quaternion, and ended the domain at x = 2^32, |p| = 65536 (φ = π − 3·10⁻⁵): every output
    was NaN next to the pole. Measured: 2^107 in float64 (φ̂ rounds to π beyond), 2^63 in float32."""
    from symrot.plan.domain import _weight_and_scale

    values = {"e_0": mpmath.mpf("1e-5"), "R_0": mpmath.mpf(1), "R_1": mpmath.mpf(0), "R_2": mpmath.mpf(0)}
    assert _weight_and_scale("e_0", values, mpmath.mpf(10) ** 5) == (1, 1.0)
    plan = evaluation_plan(derive("tan(phi/2) + sin(phi)/2").derivation, "pole_at_pi")
    assert plan.precisions["float64"].x_limit >= 2.0**100
    assert plan.precisions["float32"].x_limit >= 2.0**60


def test_an_ill_conditioned_det_h_of_a_bounded_p_does_not_end_the_range() -> None:
    """√(φ²/2 + 1) sinh(2φ)/2 (hypothesis row 53) reaches |p|² = 1.07·10¹¹ at 2π, where det H = μν²
    → 0 with ν: from the rounded angle its form in φ is 91 ulp off itself at φ = 6.24, which the sweep
    took for a wrong result and ended the range at 2³⁶ (every output NaN from φ = 6.06). Judged as
    the plan measures it, against det H(0) when p is bounded, it is right up to the edge (relative
    to itself, as next to a pole, the limit is 2³⁶ < p_max², measured)."""
    from symrot.core.singularities import validity
    from symrot.plan.domain import _floors, domain_limit

    derivation = derive("sqrt(phi**2/2 + 1)*sinh(2*phi)/2").derivation
    limits = validity(derivation)
    phi_max, p_max = float(limits.phi_max_float), float(limits.p_max_float)
    det_h = derivation.scalars["det_H"]
    printed = {"det_H": ("closed", det_h)}  # the form in φ the plan prints (or measures) for det H
    limit = domain_limit(printed, {"det_H": det_h}, derivation.p, None, phi_max, p_max, np.float64)
    assert limit > p_max**2
    assert _floors(lambda phi: {"det_H": mpmath.mpf(1)}, {"det_H": det_h}, bounded=False) == {}


@pytest.mark.parametrize("dtype", [np.float64, np.float32])
def test_the_sweep_in_chunks_ends_where_the_sweep_point_by_point_ends(
        dtype: type, monkeypatch: pytest.MonkeyPatch) -> None:
    """The domain sweep evaluates each model once per chunk of points (symrot.plan.domain.CHUNK) instead
    of once per point. Wiener–Milenkovic's H₀ = 16/(x + 16) written 16x(x + 17)/(x³ + 33x² + 272x)
    goes to 0 where x³ overflows, inside a chunk of the sweep (x ≈ 2^341 in float64, 2^43 in
    float32), and a chunk's first point is wrong when x² + 33x + 272 is the denominator (2^512,
    2^64): sweeping one point at a time ends the domain at the same power of two, below the
    overflow."""
    from symrot.core.singularities import validity
    from symrot.plan import domain
    from symrot.plan.algebraic import S, X

    derivation = derive("wiener_milenkovic").derivation
    limits = validity(derivation)
    phi_max, p_max = float(limits.phi_max_float), float(limits.p_max_float)
    references = {f"H_{k}": derivation.planned_expressions()[f"H_{k}"] for k in range(3)}
    inverse = 4 * sp.atan(S / 4)
    for power, form in ((3, 16 * X * (X + 17) / (X**3 + 33 * X**2 + 272 * X)),
                        (2, 16 * (X + 17) / (X**2 + 33 * X + 272))):
        printed = {"H_0": ("algebraic", form)}
        monkeypatch.setattr(domain, "CHUNK", 16)
        chunked = domain.domain_limit(printed, references, derivation.p, inverse, phi_max, p_max, dtype)
        monkeypatch.setattr(domain, "CHUNK", 1)
        one_by_one = domain.domain_limit(printed, references, derivation.p, inverse, phi_max, p_max, dtype)
        assert chunked == one_by_one, power
        overflow = float(np.finfo(dtype).max) ** (1 / power)  # x^power overflows beyond it
        assert overflow / 4 <= chunked <= overflow, power
