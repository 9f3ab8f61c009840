"""Derivatives for implicit solvers (issue 19): ∂(T a)/∂p, Ḣ ṗ, α, Jacobians of compose and rescale.

(The symbolic core: tests/test_derivatives_core.py; the C functions: tests/test_derivatives_c.py.)

* the emitted NumPy functions against the independent reference of tests/reference.py (R from eq 1,
  H from ω = H ṗ, each differentiated again at 150 digits): within 8 ulp of the reference matrix's
  largest entry over a φ sweep from p = 0 and 1e-300 to φ_max − 1e-6, in float64 and float32, no
  NaN inside the range; Ḣ ṗ and α = ω̇ along a trajectory; compose and rescale Jacobians against
  difference quotients of the reference's compose and rescale;
* a worked check against GXBeam.jl's Wiener–Milenkovic derivatives (``get_C_θ``, ``get_Q_θ``,
  ``get_Qinv_θ``), their formulas re-implemented here in our conventions.
"""

from __future__ import annotations

import importlib.util
import warnings
from pathlib import Path
from types import ModuleType
from typing import Any

import mpmath
import numpy as np
import pytest

from symrot.api import derive
from symrot.backends.numpy_backend import module_source
from symrot.plan.builder import evaluation_plan

from .corpus import by_expression
from .reference import GeneratingFunction, Reference

ROOT = Path(__file__).resolve().parent.parent
GENERATED = ROOT / "generated" / "numpy"
TARGET_ULP = 8.0
FUNCTIONS = {"rotation_derivative": "R", "rotation_transpose_derivative": "R_T", "tangent_derivative": "H",
             "tangent_transpose_derivative": "H_T", "tangent_inverse_derivative": "H_inverse"}
NAMED = {"rotation_vector": "phi", "cayley_gibbs_rodrigues": "2*tan(phi/2)",
         "wiener_milenkovic": "4*tan(phi/4)",
         "euler_rodrigues": "2*sin(phi/2)", "det_h_one": "cbrt(6*(phi - sin(phi)))",
         "linear": "sin(phi)", "sine_m4": "4*sin(phi/4)"}
SWEPT = ("rotation_vector", "wiener_milenkovic", "euler_rodrigues", "det_h_one")
"""Closed inverse with a pole, algebraic forms, the fold complement of the sine family, Newton's angle."""
CORPUS_SAMPLE = ("sinh(phi)",)
"""Of the user corpus (tests/corpus.py): the ν edge (φ_max = 2π, H⁻¹ singular there), p unbounded in
the hyperbolic category. bench/accuracy_derivatives.py sweeps the named parameterizations more densely."""


def load(path: Path, name: str) -> ModuleType:
    spec = importlib.util.spec_from_file_location(name, path)
    assert spec and spec.loader
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def _as_array(m: mpmath.matrix) -> np.ndarray:
    return np.array([[float(m[i, j]) for j in range(m.cols)] for i in range(m.rows)])


def _ulp(value: np.ndarray, reference: np.ndarray, dtype: type) -> float:
    """max |M − M_ref| in units of ε max |M_ref| (inf for NaN)."""
    error = float(np.max(np.abs(value.astype(np.float64) - reference)))
    scale = float(np.max(np.abs(reference)))
    if not np.isfinite(error):
        return float("inf")
    return error / (float(np.finfo(dtype).eps) * scale) if scale > 0 else (0.0 if error == 0 else np.inf)


# -- emitted NumPy against the independent reference -------------------------------------------------

_MODULES: dict[str, ModuleType] = {}


def module_of(name: str) -> ModuleType:
    """The generated module of a named parameterization, or one emitted now for a corpus function."""
    if name not in _MODULES:
        path = GENERATED / f"{name}.py"
        if name in NAMED:
            _MODULES[name] = load(path, f"derivatives_{name}")
        else:
            plan = evaluation_plan(derive(name).derivation, "user")
            target = Path(__import__("tempfile").mkdtemp()) / "user.py"
            target.write_text(module_source(plan), encoding="utf-8")
            _MODULES[name] = load(target, f"derivatives_user_{len(_MODULES)}")
    return _MODULES[name]


def sweep(phi_max: float) -> list[float]:
    """|φ|: 0, 1e-300, 1e-8, 0.5, 0.6 φ_max, φ_max − 10⁻³ and φ_max − 10⁻⁶ (bench/accuracy_derivatives.py
    runs the full sweep of bench/accuracy.py)."""
    top = min(phi_max, 4 * np.pi)
    return [0.0, 1e-300, 1e-8, 0.5, 0.6 * top, top - 1e-3, top - 1e-6]


def _function(name: str) -> tuple[GeneratingFunction, str]:
    if name in NAMED:
        return GeneratingFunction(NAMED[name]), NAMED[name]
    return by_expression(name).generating_function(), name


def radial_condition(reference: Reference, p: np.ndarray, a: np.ndarray, tensor: str,
                     base: np.ndarray) -> float:
    """κ of ∂(T a)/∂p under p → p (1 + δ): how much the one rounding of x = |p|² (relative 1.5 ε, a
    radial change of p) moves the result, relative to its largest entry. Large next to a singular
    edge (H⁻¹ at φ → 2π): there no evaluation through x can be closer than κ ulp."""
    delta = mpmath.mpf(10) ** -20
    with mpmath.workdps(150):
        moved = [mpmath.mpf(v) * (1 + delta) for v in p]
        other = reference.derivative(moved, list(a), tensor)
        change = max(abs(other[i, j] - mpmath.mpf(base[i, j])) for i in range(3) for j in range(3))
    return float(change / delta) / float(np.max(np.abs(base)))


def acceleration_condition(reference: Reference, p: np.ndarray, pdot: np.ndarray, pddot: np.ndarray,
                           alpha: np.ndarray) -> float:
    """κ of α = H p̈ + Ḣ ṗ: the larger of its radial condition (as :func:`radial_condition`: how much
    the rounding of x = |p|² moves α) and the cancellation of its two terms, (|H p̈| + |Ḣ ṗ|) / |α|
    (largest entries): correctly rounded terms summed in floating point can be no closer than that."""
    delta = mpmath.mpf(10) ** -20
    scale = float(np.max(np.abs(alpha)))
    with mpmath.workdps(150):
        rate, exact = reference.along(list(p), list(pdot), list(pddot))
        moved = reference.along([mpmath.mpf(v) * (1 + delta) for v in p], list(pdot), list(pddot))[1]
        radial = float(max(abs(moved[i] - exact[i]) for i in range(3)) / delta) / scale
        terms = max(abs(rate[i]) for i in range(3)) + max(abs(exact[i] - rate[i]) for i in range(3))
    return max(radial, float(terms) / scale)


def check_sweep(module: ModuleType, function: GeneratingFunction, angles: list[float],
                functions: dict[str, str], seed: int = 19) -> dict[tuple[str, str], float]:
    """Worst ulp / max(1, κ) of each (function, precision) over ``angles``; asserts no NaN inside."""
    reference = Reference(function)
    rng = np.random.default_rng(seed)
    p_max = float(function.p_max())
    worst: dict[tuple[str, str], float] = {}
    for angle in angles:
        axis = rng.normal(size=3)
        axis /= np.linalg.norm(axis)
        a = rng.normal(size=3).astype(np.float32).astype(np.float64)
        with mpmath.workdps(40):
            size = float(function.value(mpmath.mpf(angle)))
        p64 = size * axis
        p32 = p64.astype(np.float32)
        shared = bool((np.all((p32 == 0) | (np.abs(p32) > 1e-30)) and np.any(p32 != 0)) or angle == 0)
        cases = [(p32.astype(np.float64), (np.float64, np.float32))] if shared else \
            [(p64, (np.float64,)), (p32.astype(np.float64), (np.float32,))]
        for p, dtypes in cases:
            if float(np.linalg.norm(p)) >= p_max * (1 - 4e-7) or (angle > 0 and not np.any(p)):
                continue  # float32 p rounded onto the edge (NaN by design) or underflowed to 0
            limits = [float(module._DERIVATIVE_X_LIMIT["64" if d is np.float64 else "32"]) for d in dtypes]
            assert min(limits) >= 2.0**32
            if float(p @ p) >= min(limits):
                continue  # beyond the documented domain of unbounded p (x_limit): NaN by design
            refs = {f: _as_array(reference.derivative(list(p), list(a), t)) for f, t in functions.items()}
            kappas: dict[str, float] = {}
            for dtype in dtypes:
                with warnings.catch_warnings():
                    warnings.simplefilter("error")
                    for f, tensor in functions.items():
                        value = getattr(module, f)(p.astype(dtype), a.astype(dtype))
                        assert value.dtype == dtype and value.shape == (3, 3)
                        assert np.all(np.isfinite(value)), (f, angle, dtype)
                        ulp = _ulp(value, refs[f], dtype)
                        if ulp > TARGET_ULP and f not in kappas:
                            kappas[f] = radial_condition(reference, p, a, tensor, refs[f])
                        key = (f, np.dtype(dtype).name)
                        worst[key] = max(worst.get(key, 0.0), ulp / max(1.0, kappas.get(f, 1.0)))
    return worst


@pytest.mark.parametrize("name", [*SWEPT, *CORPUS_SAMPLE])
def test_emitted_derivatives_within_8_ulp(name: str) -> None:
    """Every derivative within 8 ulp (of the reference's largest entry) over the sweep, or 8 κ ulp where
    the radial condition number κ exceeds 1 (next to a singular edge), both precisions, evaluated at
    the rounded input (float32-representable p serve both precisions); no NaN inside the range."""
    function, _ = _function(name)
    worst = check_sweep(module_of(name), function, sweep(float(function.phi_max)), FUNCTIONS)
    failures = {k: v for k, v in worst.items() if v > TARGET_ULP}
    assert not failures, failures


def test_derivatives_next_to_a_logarithmic_pole() -> None:
    """asinh(tan φ) (tests/corpus.py, 46): p′ → ∞ and det H → 0 at π/2 while |p| is still finite
    10⁻¹² from it. The slopes of H, R and H⁻¹ are measured relative to themselves there (plan.OWN_SCALE),
    so that the factor that vanishes at the edge, cos φ, is taken through s (1/cosh s) and not from
    the rounded angle: float32 ∂(H a)/∂p was 5·10⁵ ulp off at π/2 − 10⁻⁶ before."""
    function, _ = _function("asinh(tan(phi))")
    angles = [0.5, float(np.pi / 2) - 1e-4, float(np.pi / 2) - 1e-5, float(np.pi / 2) - 1e-6]
    worst = check_sweep(module_of("asinh(tan(phi))"), function, angles, FUNCTIONS)
    failures = {k: v for k, v in worst.items() if v > TARGET_ULP}
    assert not failures, failures


@pytest.mark.parametrize("name", ["rotation_vector", "euler_rodrigues", "sinh(phi)"])
def test_rates_along_a_trajectory(name: str) -> None:
    """Ḣ ṗ = [∂(H a)/∂p]_(a=ṗ) ṗ against d/dt H(p(t)) ṗ, and α = angular_acceleration against
    d/dt of ω = H(p(t)) ṗ(t), on p(t) = p + t ṗ + t² p̈/2 (150-digit differences of the reference)."""
    module = module_of(name)
    reference = Reference(_function(name)[0])
    rng = np.random.default_rng(7)
    for scale in (0.0, 1e-9, 0.2, 0.9):
        p = rng.normal(size=3) * scale
        pdot, pddot = rng.normal(size=3), rng.normal(size=3)
        rate, acceleration = (np.array([float(v) for v in m]) for m in reference.along(p, pdot, pddot))
        got_rate = module.tangent_derivative(p, pdot) @ pdot
        got = module.angular_acceleration(p, pdot, pddot)
        tolerance = 8 * np.finfo(np.float64).eps
        assert np.max(np.abs(got_rate - rate)) <= tolerance * max(np.max(np.abs(rate)), 1.0), scale
        assert np.max(np.abs(got - acceleration)) <= tolerance * np.max(np.abs(acceleration)), scale
        if scale == 0.0:
            assert np.array_equal(got, module.omega(p, pddot))  # Ḣ = 0 at p = 0
    # batches broadcast, float32 stays float32
    batch = module.angular_acceleration(np.zeros((4, 1, 3), np.float32), np.ones((5, 3), np.float32),
                                        np.ones(3, np.float32))
    assert batch.shape == (4, 5, 3) and batch.dtype == np.float32


def _jacobian(function: Any, p: list[Any]) -> np.ndarray:
    """Central differences of a reference map at 80 digits, step 10⁻²⁵."""
    with mpmath.workdps(80):
        step = mpmath.mpf(10) ** -25
        columns = []
        for j in range(3):
            plus, minus = [mpmath.mpf(v) for v in p], [mpmath.mpf(v) for v in p]
            plus[j] += step
            minus[j] -= step
            f_plus, f_minus = function(plus), function(minus)
            columns.append([(f_plus[i] - f_minus[i]) / (2 * step) for i in range(3)])
        return np.array([[float(columns[j][i]) for j in range(3)] for i in range(3)])


@pytest.mark.parametrize("name", ["wiener_milenkovic"])
def test_compose_and_rescale_jacobians(name: str) -> None:
    """∂p₃/∂p₁ = H(p₃)⁻¹ R(p₂) H(p₁), ∂p₃/∂p₂ = H(p₃)⁻¹ H(p₂) for p₃ = compose(p₁, p₂) (R(p₃) =
    R(p₂) R(p₁)), including results that compose rescales, and ∂ rescale(p)/∂p, against difference
    quotients of the reference's quaternion composition and rescaling."""
    module = module_of(name)
    function = GeneratingFunction(NAMED[name])
    reference = Reference(function)
    size = float(function.value(mpmath.mpf("2.6")))  # |φ| = 2.6 each: compositions beyond π are rescaled
    cases = [([0.3, -0.2, 0.5], [-0.1, 0.4, 0.2]),
             (list(np.array([1.0, 2.0, -0.5]) / np.linalg.norm([1.0, 2.0, -0.5]) * size),
              list(np.array([0.8, 1.5, 0.3]) / np.linalg.norm([0.8, 1.5, 0.3]) * size))]
    flipped = 0
    for p1, p2 in cases:
        j1, j2 = module.compose_jacobians(np.array(p1), np.array(p2))
        e1 = _jacobian(lambda q, p2=p2: reference.compose(q, p2), p1)
        e2 = _jacobian(lambda q, p1=p1: reference.compose(p1, q), p2)
        for got, expected in ((j1, e1), (j2, e2)):
            assert np.max(np.abs(got - expected)) <= 64 * np.finfo(float).eps * np.max(np.abs(expected))
        big = reference.state(p1).angle + reference.state(p2).angle > mpmath.pi
        flipped += bool(big)
    assert flipped == 1
    phi_top = min(float(function.phi_max), 2 * np.pi) - 0.3
    for angle in (1.0, 3.3, phi_top):
        axis = np.array([0.6, -0.48, 0.64])
        p = float(function.value(mpmath.mpf(angle))) * axis
        got = module.rescale_jacobian(p)
        expected = _jacobian(lambda q: reference.rescale(q), list(p))
        assert np.max(np.abs(got - expected)) <= 64 * np.finfo(float).eps * np.max(np.abs(expected)), angle
        if angle < np.pi:
            assert np.array_equal(got, np.eye(3))
    assert np.all(np.isnan(module.rescale_jacobian(np.array([1e301, 0, 0]))))


# -- GXBeam.jl's Wiener–Milenkovic derivatives ------------------------------------------------------

def _tilde(v: np.ndarray) -> np.ndarray:
    return np.array([[0, -v[2], v[1]], [v[2], 0, -v[0]], [-v[1], v[0], 0]])


def _gxbeam(c: np.ndarray) -> tuple[list[np.ndarray], list[np.ndarray], list[np.ndarray]]:
    """∂C/∂c_i, ∂Q/∂c_i, ∂Q⁻¹/∂c_i of GXBeam.jl (byuflowlab/GXBeam.jl, src/math.jl: ``wiener_milenkovic``,
    ``get_C_θ``, ``get_Q``, ``get_Q_θ``, ``get_Qinv_θ``), for |c| ≤ 4 where its scaling is 1.

    Their formulas, written compactly here (GXBeam spells C and C_θi out entry by entry):
    c0 = 2 − cᵀc/8, tmp = 1/(4 − c0)², tmp_θ = 2/(4 − c0)³ c0_θ with c0_θ = −c/4;
    C = tmp [(c0² − cᵀc) I + 2 c cᵀ − 2 c0 c̃] (the *transformation* matrix, Rᵀ in our terms),
    C_θi = tmp_θ[i] C / tmp + tmp [(2 c0 c0_θ[i] − 2 c_i) I + 2 (e_i cᵀ + c e_iᵀ) − 2 c0_θ[i] c̃ − 2 c0 ẽ_i];
    Q = tmp ((4 − cᵀc/4) I − 2 c̃ + c cᵀ/2),
    Q_θi = tmp_θ[i] Q / tmp + tmp (−c_i/2 I − 2 ẽ_i + (e_i cᵀ + c e_iᵀ)/2);
    Qinv_θi = −c_i/8 I + ẽ_i/2 + (e_i cᵀ + c e_iᵀ)/8.
    """
    eye = np.eye(3)
    c0 = 2 - c @ c / 8
    c0_theta = -c / 4
    tmp = 1 / (4 - c0) ** 2
    tmp_theta = 2 / (4 - c0) ** 3 * c0_theta
    big_c = tmp * ((c0 ** 2 - c @ c) * eye + 2 * np.outer(c, c) - 2 * c0 * _tilde(c))
    q = tmp * ((4 - c @ c / 4) * eye - 2 * _tilde(c) + np.outer(c, c) / 2)
    c_theta, q_theta, qinv_theta = [], [], []
    for i in range(3):
        e = eye[i]
        sym = np.outer(e, c) + np.outer(c, e)
        c_theta.append(tmp_theta[i] * big_c / tmp + tmp * ((2 * c0 * c0_theta[i] - 2 * c[i]) * eye + 2 * sym
                                                         - 2 * c0_theta[i] * _tilde(c) - 2 * c0 * _tilde(e)))
        q_theta.append(tmp_theta[i] * q / tmp + tmp * (-c[i] / 2 * eye - 2 * _tilde(e) + sym / 2))
        qinv_theta.append(-c[i] / 8 * eye + _tilde(e) / 2 + sym / 8)
    return c_theta, q_theta, qinv_theta


def test_gxbeam_wiener_milenkovic_derivatives() -> None:
    """GXBeam's C = Rᵀ and Q = Hᵀ (its angular velocity in the body frame, Q⁻¹ = (H⁻¹)ᵀ), so column i of
    our ∂(Rᵀ a)/∂p is C_θi a, of ∂(Hᵀ a)/∂p is Q_θi a and of ∂(H⁻¹ a)/∂p is Qinv_θiᵀ a."""
    module = module_of("wiener_milenkovic")
    rng = np.random.default_rng(5)
    for scale in (0.0, 0.4, 1.5, 2.2):
        c = rng.normal(size=3)
        c *= scale / max(np.linalg.norm(c), 1e-300)
        a = rng.normal(size=3)
        c_theta, q_theta, qinv_theta = _gxbeam(c)
        expected = {
            "rotation_transpose_derivative": np.column_stack([m @ a for m in c_theta]),
            "tangent_transpose_derivative": np.column_stack([m @ a for m in q_theta]),
            "tangent_inverse_derivative": np.column_stack([m.T @ a for m in qinv_theta]),
        }
        for f, matrix in expected.items():
            got = getattr(module, f)(c, a)
            tolerance = 32 * np.finfo(float).eps * np.max(np.abs(matrix))
            assert np.max(np.abs(got - matrix)) <= tolerance, (f, scale)
    assert np.allclose(module.rotation_matrix(c).T, _gxbeam_c(c), atol=1e-15)


def _gxbeam_c(c: np.ndarray) -> np.ndarray:
    c0 = 2 - c @ c / 8
    return ((c0 ** 2 - c @ c) * np.eye(3) + 2 * np.outer(c, c) - 2 * c0 * _tilde(c)) / (4 - c0) ** 2


def test_domain_and_inputs() -> None:
    """NaN outside the range, ValueError for a wrong shape, float32 kept."""
    module = module_of("cayley_gibbs_rodrigues")
    for f in (*FUNCTIONS, "rescale_jacobian"):
        args = (np.array([[1e200, 0, 0], [0.1, 0.2, 0.3]]),) + ((np.ones(3),) if f in FUNCTIONS else ())
        with warnings.catch_warnings():
            warnings.simplefilter("error")
            out = getattr(module, f)(*args)
        assert out.shape == (2, 3, 3) and np.all(np.isnan(out[0])) and np.all(np.isfinite(out[1])), f
        if f in FUNCTIONS:
            assert getattr(module, f)(np.ones(3, np.float32), np.ones(3, np.float32)).dtype == np.float32
            with pytest.raises(ValueError):
                getattr(module, f)(np.ones(3), np.ones(2))
