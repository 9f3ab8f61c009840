"""Operations on rotations of any size in the generated NumPy modules (issue 6): property tests.

Functions under test: ``to_quaternion``, ``from_quaternion``, ``from_rotation_matrix``, ``compose``
and ``rescale``, for rotation_vector, wiener_milenkovic, cayley_gibbs_rodrigues, linear, det_h_one
the user expression ``cbrt(6*(phi-sin(phi)))`` (eq 35 again, built through ``module_source``) and two
user functions of tests/corpus.py (``phi + phi**5/120``, ``4*atanh(phi/4)``), plus euler_rodrigues for
the 180° edge.

Tolerances. Every operation is a short, fixed chain of correctly rounded operations on unit
quaternions (to_quaternion: coefficients of x = |p|² within 4 ε each (issue 4); a Hamilton product:
four products per component; from_quaternion: a norm, atan2, one coefficient, one product), so it
moves the rotation by a few ε — plus what rounding a parameter vector costs. Two functions of the
parameterization turn this into tolerances (p and p' from the generating function written here,
φ from the module's ``angle``):

* κ(p) = φ + |p| / p'(φ): the rotation error (radians per ε) of rounding p relatively by ε — the axis
  moves by ≤ φ ε, the angle by ε |p| / p'(φ). It is ≈ 2φ for small φ (tiny rotations stay
  relative) and large where p cannot resolve φ (linear near π/2, det_h_one near 2π).
* gain(p) = p'(φ) + |p| / (2 sin(φ/2)): |δp| per radian of rotation error (angle, then axis).

An operation's rotation error is θ = C ε Σ κ over its inputs, intermediate and output vectors; a
matrix entry is off by ≤ θ, a parameter vector by ≤ θ · gain. C = C_P = C_R = 8: the largest
ratio seen (8 hypothesis seeds × every property below) is 2.8 ε Σκ·gain for the round trips,
1.6 for R(compose), 0.2 for associativity, so C = 8 leaves a factor ≥ 2.8. Near φ = π, where p and
−p are the same rotation, the sign of a rescaled result may flip: comparisons accept −p only there
(|π − φ| < FLIP_ZONE).
"""

from __future__ import annotations

import importlib.util
import math
import warnings
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path
from types import ModuleType

import mpmath
import numpy as np
import pytest
import sympy as sp
from hypothesis import HealthCheck, Phase, given, settings
from hypothesis import strategies as st
from scipy.spatial.transform import Rotation

from symrot.api import derive
from symrot.backends.numpy_backend import module_source
from symrot.plan.builder import evaluation_plan

from .corpus import by_expression
from .reference import PHI, parse

ROOT = Path(__file__).resolve().parent.parent
GENERATED = ROOT / "generated" / "numpy"
OPERATIONS = ("to_quaternion", "from_quaternion", "from_rotation_matrix", "compose", "rescale")
USER_EXPRESSION = "cbrt(6*(phi-sin(phi)))"
C_P = 8.0
C_R = 8.0
EXAMPLES = 25
SETTINGS = settings(max_examples=EXAMPLES, deadline=None, derandomize=True, database=None,  # same in CI
                    phases=[Phase.explicit, Phase.reuse, Phase.generate],  # no minutes-long shrinking
                    suppress_health_check=[HealthCheck.function_scoped_fixture])
EPS = {np.dtype(np.float64): float(np.finfo(np.float64).eps),
       np.dtype(np.float32): float(np.finfo(np.float32).eps)}


@dataclass(frozen=True)
class Parameterization:
    """A generating function, written here independently of symrot, and its range."""

    source: str
    """Name for :func:`symrot.api.derive` (a registered name or a user expression)."""
    p: Callable[[np.ndarray], np.ndarray]
    dp: Callable[[np.ndarray], np.ndarray]
    """p'(φ), for the tolerances only."""
    phi_max: float
    """|φ| < phi_max is representable."""


def _det_h_one(phi: np.ndarray) -> np.ndarray:
    return np.cbrt(6 * (phi - np.sin(phi)))


def _det_h_one_prime(phi: np.ndarray) -> np.ndarray:
    p = _det_h_one(np.abs(phi))
    with np.errstate(all="ignore"):
        value = 2 * (1 - np.cos(phi)) / (p * p)
    return np.where(np.abs(phi) < 1e-4, 1.0, value)


def _corpus(expression: str) -> Parameterization:
    """A user function of tests/corpus.py: p and p′ lambdified from tests/reference.py's parse (not
    symrot's), φ_max the corpus's declared one."""
    expr = parse(expression)
    p, dp = (sp.lambdify(PHI, e, modules="numpy") for e in (expr, sp.diff(expr, PHI)))

    def quiet(function: Callable[[np.ndarray], np.ndarray]) -> Callable[[np.ndarray], np.ndarray]:
        def evaluate(phi: np.ndarray) -> np.ndarray:
            with np.errstate(divide="ignore"):  # p(φ_max) = inf at a pole: the end of the range
                return function(phi)
        return evaluate

    phi_max = float(by_expression(expression).declared_phi_max())
    return Parameterization(expression, quiet(p), quiet(dp), phi_max)


PARAMETERIZATIONS: dict[str, Parameterization] = {
    "rotation_vector": Parameterization("rotation_vector", lambda t: t, np.ones_like, 2 * math.pi),
    "wiener_milenkovic": Parameterization("wiener_milenkovic", lambda t: 4 * np.tan(t / 4),
                                          lambda t: 1 / np.cos(t / 4) ** 2, 2 * math.pi),
    "cayley_gibbs_rodrigues": Parameterization("cayley_gibbs_rodrigues", lambda t: 2 * np.tan(t / 2),
                                               lambda t: 1 / np.cos(t / 2) ** 2, math.pi),
    "linear": Parameterization("linear", np.sin, np.cos, math.pi / 2),
    "det_h_one": Parameterization("det_h_one", _det_h_one, _det_h_one_prime, 2 * math.pi),
    "user_eq35": Parameterization(USER_EXPRESSION, _det_h_one, _det_h_one_prime, 2 * math.pi),
    "corpus_quintic": _corpus("phi + phi**5/120"),
    "corpus_atanh": _corpus("4*atanh(phi/4)"),
}
"""user_eq35 is det_h_one entered as an expression: the module comes from module_source; so do the
two user functions of the corpus, beyond the named families: φ + φ⁵/120 (no closed inverse: a
Newton angle; ν → 0 at 2π) and 4 atanh(φ/4) (a pole at φ = 4: p unbounded)."""

Case = tuple[str, ModuleType, Parameterization]
Rotations = tuple[np.ndarray, np.ndarray]

EXTRA = {"euler_rodrigues": Parameterization("euler_rodrigues", lambda t: 2 * np.sin(t / 2),
                                             lambda t: np.cos(t / 2), math.pi)}


def build_module(name: str, directory: Path) -> ModuleType:
    """The generated module for ``name``: generated/numpy/NAME.py when it already has the
    operations of issue 6, else (and always for the user expression) built by module_source."""
    path = GENERATED / f"{name}.py"
    user = name in PARAMETERIZATIONS and PARAMETERIZATIONS[name].source != name
    if user or not path.exists() or "def compose(" not in path.read_text(encoding="utf-8"):
        source = {**PARAMETERIZATIONS, **EXTRA}[name].source
        path = directory / f"{name}.py"
        path.write_text(module_source(evaluation_plan(derive(source).derivation, name)), encoding="utf-8")
    spec = importlib.util.spec_from_file_location(f"symrot_ops_{name}", path)
    assert spec and spec.loader
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


_MODULES: dict[str, ModuleType] = {}


def get_module(name: str, directory: Path) -> ModuleType:
    """:func:`build_module`, once per test session (also used by test_operations_c.py)."""
    if name not in _MODULES:
        _MODULES[name] = build_module(name, directory)
    return _MODULES[name]


@pytest.fixture(scope="session")
def module_dir(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return tmp_path_factory.mktemp("operations_modules")


@pytest.fixture(scope="module", params=list(PARAMETERIZATIONS))
def case(request: pytest.FixtureRequest, module_dir: Path) -> Case:
    return request.param, get_module(request.param, module_dir), PARAMETERIZATIONS[request.param]


@contextmanager
def strict() -> Iterator[None]:
    """Any floating-point warning (overflow, invalid, division by zero) is an error (underflow is
    not a warning in NumPy's default error state, and is not one here: tiny inputs underflow)."""
    with warnings.catch_warnings(), np.errstate(divide="warn", over="warn", invalid="warn", under="ignore"):
        warnings.simplefilter("error")
        yield


# -- inputs ----------------------------------------------------------------------------------------
unit_axis = st.tuples(*[st.floats(-1, 1) for _ in range(3)]).filter(
    lambda v: math.fsum(c * c for c in v) > 1e-6)
fraction = st.one_of(st.floats(-1, 1), st.sampled_from([0.0, 1.0, -1.0, 0.5, 1e-9, 1 - 1e-9]))
"""Fraction of the largest angle used: edges are drawn often."""


@st.composite
def rotations(draw: st.DrawFn, size: int = 6) -> Rotations:
    """(axes (n, 3) unit, fractions (n,) in [−1, 1]·(1 − 1e-7)): φ = fraction · phi_max."""
    axes = np.array(draw(st.lists(unit_axis, min_size=1, max_size=size)), dtype=np.float64)
    axes /= np.linalg.norm(axes, axis=-1, keepdims=True)
    angles = np.array(draw(st.lists(fraction, min_size=len(axes), max_size=len(axes))))
    return axes, angles * (1 - 1e-7)


def parameter(param: Parameterization, axes: np.ndarray, fractions: np.ndarray,
              dtype: type = np.float64, phi_max: float | None = None) -> np.ndarray:
    """p = p(φ) u for φ = fraction · phi_max, rounded to ``dtype`` (the input is that rounded p)."""
    phi = fractions * (param.phi_max if phi_max is None else phi_max)
    p = (param.p(phi)[:, None] * axes).astype(dtype)
    # p(φ) may round to or past the end of the range (p' → 0 there for linear and det_h_one):
    # such inputs are pulled back to |p| = p_end (1 − 1000 ε)
    p_end = float(param.p(np.array(param.phi_max)))
    if not (math.isfinite(p_end) and p_end < 1e10):  # unbounded: the domain ends at the plan's x_limit
        label = "float32" if dtype == np.float32 else "float64"
        p_end = math.sqrt(evaluation_plan(derive(param.source).derivation, param.source)
                          .precisions[label].x_limit)
    if math.isfinite(p_end):
        limit = p_end * (1 - 1000 * float(np.finfo(dtype).eps))
        norm = np.linalg.norm(p.astype(np.float64), axis=-1, keepdims=True)
        with np.errstate(divide="ignore", invalid="ignore"):
            pulled = (p.astype(np.float64) * (limit / norm)).astype(dtype)
        p = np.where(norm > limit, pulled, p)
    return p


# -- tolerances ------------------------------------------------------------------------------------
FLIP_ZONE = 1e-5
"""|π − φ| below which p and −p may both be the rescaled answer (float32 rounding of φ ≈ 1e-7)."""


def angles_of(module: ModuleType, p: np.ndarray) -> np.ndarray:
    """|φ| of parameter vectors (float64), for tolerances."""
    with strict():
        return np.abs(module.angle(np.asarray(p, dtype=np.float64)))


def kappa(module: ModuleType, param: Parameterization, p: np.ndarray) -> np.ndarray:
    """Rotation error (radians, per ε) of a parameter vector that was rounded relatively by ε:
    φ + |p| / p'(φ) (the axis moves by ≲ ε·φ, the angle by ε |p| / p'(φ))."""
    phi = angles_of(module, p)
    return phi + np.linalg.norm(np.asarray(p, dtype=np.float64), axis=-1) / param.dp(phi)


def gain(module: ModuleType, param: Parameterization, p: np.ndarray) -> np.ndarray:
    """|δp| per radian of rotation error: p'(φ) (angle) + |p| / (2 sin(φ/2)) (axis); 2 at φ = 0."""
    phi = angles_of(module, p)
    norm = np.linalg.norm(np.asarray(p, dtype=np.float64), axis=-1)
    with np.errstate(divide="ignore", invalid="ignore"):
        axis = np.where(phi > 1e-8, norm / (2 * np.sin(phi / 2)), 1.0)
    return param.dp(phi) + axis


def floor(dtype: type) -> float:
    """Absolute floor of every tolerance: a few subnormal steps (float32 tiny results)."""
    return 8 * float(np.finfo(dtype).smallest_subnormal)


def p_distance(a: np.ndarray, b: np.ndarray, phi: np.ndarray) -> np.ndarray:
    """|a − b|, or min(|a − b|, |a + b|) where |φ| is within FLIP_ZONE of π."""
    a, b = np.asarray(a, dtype=np.float64), np.asarray(b, dtype=np.float64)
    plain = np.linalg.norm(a - b, axis=-1)
    flipped = np.linalg.norm(a + b, axis=-1)
    return np.where(np.abs(np.pi - phi) < FLIP_ZONE, np.minimum(plain, flipped), plain)


def assert_within(error: np.ndarray, tolerance: np.ndarray, what: str) -> None:
    error, tolerance = np.broadcast_arrays(error, tolerance)
    bad = ~(error <= tolerance)
    assert not bad.any(), f"{what}: error {error[bad]} > tolerance {tolerance[bad]}"


DTYPES = [np.float64, np.float32]


# -- properties ------------------------------------------------------------------------------------
@pytest.mark.parametrize("dtype", DTYPES)
@SETTINGS
@given(data=st.data())
def test_compose_is_associative(case: Case, dtype: type, data: st.DataObject) -> None:
    name, module, param = case
    axes, fractions = data.draw(rotations(size=4))
    p1 = parameter(param, axes, fractions, dtype)
    p2 = parameter(param, axes[::-1], fractions[::-1] * 0.7, dtype)
    p3 = parameter(param, np.roll(axes, 1, axis=0), -np.roll(fractions, 1), dtype)
    with strict():
        p12, p23 = module.compose(p1, p2), module.compose(p2, p3)
        left, right = module.compose(p12, p3), module.compose(p1, p23)
    eps = EPS[np.dtype(dtype)]
    finite = np.isfinite(left).all(-1) & np.isfinite(right).all(-1)
    if name not in ("linear", "cayley_gibbs_rodrigues"):  # ranges > π: compose never fails
        assert finite.all(), (p1, p2, p3, left, right)
    inputs = sum(kappa(module, param, p) for p in (p1, p2, p3))
    theta = C_P * eps * (2 * inputs + kappa(module, param, p12) + kappa(module, param, p23)
                         + kappa(module, param, left) + kappa(module, param, right))
    tolerance = theta[finite] * gain(module, param, left[finite]) + floor(dtype)
    phi = angles_of(module, left[finite])
    assert_within(p_distance(left[finite], right[finite], phi), tolerance, f"{name} associativity")


@pytest.mark.parametrize("dtype", DTYPES)
@SETTINGS
@given(data=st.data())
def test_compose_with_inverse_is_identity(case: Case, dtype: type, data: st.DataObject) -> None:
    name, module, param = case
    axes, fractions = data.draw(rotations())
    p = parameter(param, axes, fractions, dtype)
    with strict():
        q1, q2 = module.compose(p, -p), module.compose(-p, p)
    eps = EPS[np.dtype(dtype)]
    for q in (q1, q2):
        assert q.dtype == dtype
        assert_within(np.linalg.norm(q.astype(np.float64), axis=-1),
                      4 * eps * np.linalg.norm(p.astype(np.float64), axis=-1) + floor(dtype),
                      f"{name} compose(p, -p)")


@pytest.mark.parametrize("dtype", DTYPES)
@SETTINGS
@given(data=st.data())
def test_compose_matches_matrix_product(case: Case, dtype: type, data: st.DataObject) -> None:
    name, module, param = case
    axes, fractions = data.draw(rotations())
    p1 = parameter(param, axes, fractions, dtype)
    p2 = parameter(param, np.roll(axes, 1, axis=0), np.roll(fractions, 1) * 0.9, dtype)
    with strict():
        p3 = module.compose(p1, p2)
        r3 = module.rotation_matrix(p3)
        r1, r2 = module.rotation_matrix(p1.astype(np.float64)), module.rotation_matrix(p2.astype(np.float64))
        product = r2 @ r1
    assert p3.dtype == dtype and r3.dtype == dtype
    finite = np.isfinite(p3).all(-1)
    # the rescaled result: |φ3| <= π, so |p3| <= p(π) for ranges above π
    if param.phi_max > math.pi:
        assert finite.all()
        bound = float(param.p(np.array(math.pi))) * (1 + 4 * EPS[np.dtype(dtype)])
        assert (np.linalg.norm(p3.astype(np.float64), axis=-1) <= bound).all()
    eps = EPS[np.dtype(dtype)]
    theta = C_R * eps * (1 + kappa(module, param, p1) + kappa(module, param, p2) + kappa(module, param, p3))
    error = np.abs(r3[finite].astype(np.float64) - product[finite]).max(axis=(-2, -1))
    assert_within(error, theta[finite], f"{name} R(compose)")


@pytest.mark.parametrize("dtype", DTYPES)
@SETTINGS
@given(data=st.data())
def test_round_trips_give_the_rescaled_vector(case: Case, dtype: type, data: st.DataObject) -> None:
    name, module, param = case
    axes, fractions = data.draw(rotations())
    p = parameter(param, axes, fractions, dtype)
    with strict():
        rescaled = module.rescale(p)
        via_quaternion = module.from_quaternion(module.to_quaternion(p))
        via_matrix = module.from_rotation_matrix(module.rotation_matrix(p))
        angle = module.angle(p.astype(np.float64))
    eps = EPS[np.dtype(dtype)]
    assert rescaled.dtype == via_quaternion.dtype == via_matrix.dtype == dtype
    assert np.isfinite(rescaled).all()
    # rescale keeps p bit for bit when |φ| <= π and otherwise gives an angle <= π
    small = np.abs(angle) < math.pi - FLIP_ZONE
    assert np.array_equal(rescaled[small], p[small])
    assert (angles_of(module, rescaled) <= math.pi * (1 + 1e-6)).all()
    phi = angles_of(module, rescaled)
    theta = C_P * eps * (kappa(module, param, p) + kappa(module, param, rescaled))
    tolerance = theta * gain(module, param, rescaled) + floor(dtype)
    assert_within(p_distance(via_quaternion, rescaled, phi), tolerance, f"{name} from_q∘to_quaternion")
    assert_within(p_distance(via_matrix, rescaled, phi), tolerance, f"{name} from_rotation_matrix∘R")
    # the rescaled vector is the same rotation
    with strict():
        error = np.abs(module.rotation_matrix(rescaled.astype(np.float64))
                       - module.rotation_matrix(p.astype(np.float64))).max(axis=(-2, -1))
    assert_within(error, C_R / C_P * theta + floor(dtype), f"{name} R(rescale(p))")


@pytest.mark.parametrize("dtype", DTYPES)
def test_dtypes_and_shapes(case: Case, dtype: type) -> None:
    _name, module, param = case
    rng = np.random.default_rng(1)
    axes = rng.normal(size=(2, 5, 3))
    axes /= np.linalg.norm(axes, axis=-1, keepdims=True)
    p = parameter(param, axes.reshape(-1, 3), rng.uniform(-0.9, 0.9, 10), dtype).reshape(2, 5, 3)
    with strict():
        e = module.to_quaternion(p)
        outputs = {"to_quaternion": e, "from_quaternion": module.from_quaternion(e),
                   "from_rotation_matrix": module.from_rotation_matrix(module.rotation_matrix(p)),
                   "compose": module.compose(p, p[:, ::-1]), "rescale": module.rescale(p)}
    for function, value in outputs.items():
        assert value.dtype == dtype, (function, value.dtype)
        assert value.shape == (2, 5, 4 if function == "to_quaternion" else 3), function
    # a single vector works too and unit quaternions come out normalized
    assert module.compose(p[0, 0], p[1, 1]).shape == (3,)
    assert np.allclose(np.linalg.norm(e.astype(np.float64), axis=-1), 1, atol=4 * EPS[np.dtype(dtype)])


def test_edge_inputs_without_warnings(case: Case) -> None:
    """NaN inputs, zero and non-finite quaternions, the zero matrix: NaN or a value, no warning."""
    name, module, _param = case
    with strict():
        assert np.isnan(module.to_quaternion(np.array([np.nan, 0, 0]))).all()
        assert np.isnan(module.compose(np.array([np.nan, 0, 0]), np.zeros(3))).all()
        assert np.isnan(module.rescale(np.array([0, np.nan, 0]))).all()
        for e in ([0, 0, 0, 0], [np.nan, 0, 0, 0], [np.inf, 0, 0, 0], [1, np.inf, 0, 0]):
            assert np.isnan(module.from_quaternion(np.array(e, dtype=float))).all(), (name, e)
        assert np.isnan(module.from_rotation_matrix(np.full((3, 3), np.nan))).all()
        # unnormalized quaternions: only the direction matters, e and -e agree
        e = np.array([0.8, 0.1, -0.2, 0.3])
        expected = module.from_quaternion(e / np.linalg.norm(e))
        for scale in (1e-150, 1e150, -1.0, -7.5):
            got = module.from_quaternion(scale * e)
            assert np.allclose(got, expected, rtol=C_P * 2.3e-16, atol=0), (name, scale, got, expected)
        # identity and 360°
        assert np.array_equal(module.from_quaternion(np.array([-1.0, 0, 0, 0])), np.zeros(3))
        assert np.array_equal(module.from_rotation_matrix(np.eye(3)), np.zeros(3))
        identity = module.to_quaternion(np.zeros(3))
    assert np.array_equal(identity[1:], np.zeros(3))
    # exactly 1 except for linear: see test_linear_identity_quaternion_is_exact
    assert identity[0] == 1 or (name == "linear" and identity[0] == np.nextafter(1.0, 2.0)), identity


@pytest.mark.parametrize("dtype", DTYPES)
def test_tiny_rotations_keep_relative_accuracy(case: Case, dtype: type) -> None:
    name, module, _param = case
    tiny = 1e-200 if dtype == np.float64 else 1e-30
    eps = EPS[np.dtype(dtype)]
    rng = np.random.default_rng(7)
    p1 = (rng.uniform(0.1, 1, size=(20, 3)) * tiny).astype(dtype)
    p2 = (rng.uniform(-1, 1, size=(20, 3)) * tiny).astype(dtype)
    with strict():
        p3 = module.compose(p1, p2)
        e = module.to_quaternion(p1)
        back = module.from_quaternion(e)
        from_r = module.from_rotation_matrix(module.rotation_matrix(p1))
    a, b = p1.astype(np.float64) / tiny, p2.astype(np.float64) / tiny  # exact in float64
    scale = np.linalg.norm(a, axis=-1) + np.linalg.norm(b, axis=-1)
    # p(φ) = φ + O(φ³) and the BCH terms are O(tiny²): the exact result is a + b to ~1e-400
    assert_within(np.linalg.norm(p3.astype(np.float64) / tiny - (a + b), axis=-1), 4 * eps * scale,
                  f"{name} tiny compose")
    assert_within(np.abs(e[:, 1:].astype(np.float64) / tiny - a / 2).max(-1),
                  4 * eps * np.abs(a).max(-1), f"{name} tiny to_quaternion")
    assert np.all(e[:, 0] == 1) or name == "linear"  # see test_linear_identity_quaternion_is_exact
    assert np.all(np.abs(e[:, 0] - 1) <= eps)
    for value, what in ((back, "from_quaternion"), (from_r, "from_rotation_matrix")):
        assert_within(np.abs(value.astype(np.float64) / tiny - a).max(-1), 4 * eps * np.abs(a).max(-1),
                      f"{name} tiny {what}")


TWO_PI_LOW = 2.4492935982947064e-16
"""2π − fl(2π)."""


# -- against scipy ---------------------------------------------------------------------------------
@pytest.fixture(scope="module")
def rv(module_dir: Path) -> ModuleType:
    return get_module("rotation_vector", module_dir)


@pytest.fixture(scope="module")
def wm(module_dir: Path) -> ModuleType:
    return get_module("wiener_milenkovic", module_dir)


quaternions = st.tuples(st.one_of(st.just(0.0), st.floats(-1, 1)),
                        *[st.floats(-1, 1) for _ in range(3)]).filter(
    lambda q: math.fsum(c * c for c in q) > 1e-4)


@SETTINGS
@given(axes_fractions=rotations(size=8))
def test_to_quaternion_matches_scipy(rv: ModuleType, wm: ModuleType, axes_fractions: Rotations) -> None:
    """Not canonicalized: e0 = cos(φ/2) < 0 beyond 180°, for both scipy and symrot."""
    axes, fractions = axes_fractions
    eps = EPS[np.dtype(np.float64)]
    p_rv = parameter(PARAMETERIZATIONS["rotation_vector"], axes, fractions)
    p_wm = parameter(PARAMETERIZATIONS["wiener_milenkovic"], axes, fractions * 0.999)
    with strict():
        got_rv, got_wm = rv.to_quaternion(p_rv), wm.to_quaternion(p_wm)
    expected_rv = Rotation.from_rotvec(p_rv).as_quat(scalar_first=True)
    expected_wm = Rotation.from_mrp(p_wm / 4).as_quat(scalar_first=True)
    assert_within(np.abs(got_rv - expected_rv).max(-1), 4 * eps, "to_quaternion vs from_rotvec")
    # MRP near 360°: scipy's (1 - m²)/(1 + m²) rounds absolutely, m = |p|/4 up to 4e3 here
    assert_within(np.abs(got_wm - expected_wm).max(-1), 4 * eps, "to_quaternion vs from_mrp")


@SETTINGS
@given(q=st.lists(quaternions, min_size=1, max_size=8))
def test_from_quaternion_and_matrix_match_scipy(rv: ModuleType, wm: ModuleType,
                                                 q: list[tuple[float, ...]]) -> None:
    e = np.array(q)
    rotation = Rotation.from_quat(e, scalar_first=True)
    matrix = rotation.as_matrix()
    with strict():
        got = {"rv": rv.from_quaternion(e), "wm": wm.from_quaternion(e),
               "rv R": rv.from_rotation_matrix(matrix), "wm R": wm.from_rotation_matrix(matrix)}
    expected = {"rv": rotation.as_rotvec(), "wm": 4 * rotation.as_mrp()}
    eps = EPS[np.dtype(np.float64)]
    phi = np.linalg.norm(expected["rv"], axis=-1)
    for label, value in got.items():
        reference = expected[label.split()[0]]
        # the 180°-ambiguity: scipy and symrot may pick opposite signs at φ = π. Within 4 ε relative
        # to max(1, |p|) (was 64 ε absolute): measured 2.9 on 20 000 seeded quaternions (8.7 ε absolute)
        scale = np.maximum(1.0, np.linalg.norm(reference, axis=-1))
        assert_within(p_distance(value, reference, phi), 4 * eps * scale, f"{label} vs scipy")


@SETTINGS
@given(axes_fractions=rotations(size=8), other=rotations(size=8))
def test_compose_matches_scipy(rv: ModuleType, wm: ModuleType, axes_fractions: Rotations,
                               other: Rotations) -> None:
    (a1, f1), (a2, f2) = axes_fractions, other
    n = min(len(f1), len(f2))
    p1 = parameter(PARAMETERIZATIONS["rotation_vector"], a1[:n], f1[:n])
    p2 = parameter(PARAMETERIZATIONS["rotation_vector"], a2[:n], f2[:n])
    composed = Rotation.from_rotvec(p2) * Rotation.from_rotvec(p1)  # p1 first
    with strict():
        got = rv.compose(p1, p2)
        got_wm = wm.compose(4 * Rotation.from_rotvec(p1).as_mrp(), 4 * Rotation.from_rotvec(p2).as_mrp())
    expected = composed.as_rotvec()
    phi = np.linalg.norm(expected, axis=-1)
    eps = EPS[np.dtype(np.float64)]
    assert_within(p_distance(got, expected, phi), 32 * eps * 4, "compose vs scipy (rotation vector)")
    assert_within(p_distance(got_wm, 4 * composed.as_mrp(), phi), 32 * eps * 4, "compose vs scipy (MRP)")


def test_exact_half_and_full_turns(rv: ModuleType, wm: ModuleType, module_dir: Path) -> None:
    """180° and 360° exactly: e = (0, u) and (−1, 0); p = 4u is exactly 180° for wiener_milenkovic."""
    u = np.array([[1.0, 0, 0], [0, 0.6, 0.8], [0, 0, -1.0]])
    half = np.concatenate([np.zeros((3, 1)), u], axis=-1)
    flip = np.array([np.diag([1.0, -1, -1]), np.diag([-1.0, 1, -1]), np.diag([-1.0, -1, 1])])
    eps = EPS[np.dtype(np.float64)]
    with strict():
        assert np.allclose(np.abs(wm.to_quaternion(4 * u)), np.abs(half), atol=eps, rtol=0)
        assert np.allclose(wm.to_quaternion(4 * u), Rotation.from_mrp(u).as_quat(scalar_first=True),
                           atol=eps, rtol=0)
        assert_within(p_distance(wm.from_quaternion(half), 4 * u, np.full(3, np.pi)), 4 * eps, "wm 180°")
        assert_within(p_distance(rv.from_quaternion(half), np.pi * u, np.full(3, np.pi)), 8 * eps, "rv 180°")
        for module, scale in ((rv, np.pi), (wm, 4.0)):
            got = module.from_rotation_matrix(flip)
            assert_within(p_distance(got, scale * np.eye(3), np.full(3, np.pi)), 8 * eps, "R = 180°")
            expected = Rotation.from_matrix(flip).as_rotvec()
            assert_within(p_distance(rv.from_rotation_matrix(flip), expected, np.full(3, np.pi)),
                          8 * eps, "R = 180° vs scipy")
            # two half turns: a full turn, the identity (p3 ≈ 0)
            turn = module.compose(scale * u, scale * u)
            assert (np.linalg.norm(turn, axis=-1) <= 8 * eps).all(), turn
        # just short of 360° (rotation vector, exact binary |p| on an axis): e0 = −cos(...) ≈ −1
        for k in (1, 2, 8, 1000, 10**6):
            p = np.array([2 * math.pi * (1 - k * eps), 0, 0])
            if not p[0] < 2 * math.pi:
                continue
            got = rv.to_quaternion(p)
            expected = Rotation.from_rotvec(p).as_quat(scalar_first=True)
            assert got[0] < 0 and got[1] > 0
            assert abs(got[1] - expected[1]) <= 4 * eps * expected[1], (k, got, expected)
            assert abs(got[0] - expected[0]) <= eps
            # rescaled: the small rotation the other way round
            small = rv.rescale(p)
            remainder = (2 * math.pi - p[0]) + TWO_PI_LOW  # 2π − p[0], exact to ~1e-32
            assert small[0] < 0 and abs(small[0] + remainder) <= 8 * eps * remainder, (k, small, remainder)
    half_angle = {"cayley_gibbs_rodrigues": True, "linear": True, "euler_rodrigues": True,
                  "det_h_one": False, "user_eq35": False}
    for name, nan in half_angle.items():
        module = get_module(name, module_dir)
        with strict():
            value = module.from_quaternion(half)
            matrix = module.from_rotation_matrix(flip)
        assert np.isnan(value).all() == nan and np.isnan(matrix).all() == nan, (name, value, matrix)
        if not nan:
            assert np.allclose(np.linalg.norm(value, axis=-1), np.cbrt(6 * np.pi), rtol=4 * eps)


# -- out of range ----------------------------------------------------------------------------------
def composed_angle(axes1: np.ndarray, phi1: np.ndarray, axes2: np.ndarray, phi2: np.ndarray) -> np.ndarray:
    """|φ3| ∈ [0, π] of the composition, from quaternions computed here (not by symrot)."""
    a0, a = np.cos(phi1 / 2), np.sin(phi1 / 2)[:, None] * axes1
    b0, b = np.cos(phi2 / 2), np.sin(phi2 / 2)[:, None] * axes2
    e0 = a0 * b0 - np.einsum("...i,...i->...", a, b)
    e = a0[:, None] * b + b0[:, None] * a + np.cross(b, a)
    return 2 * np.arctan2(np.linalg.norm(e, axis=-1), np.abs(e0))


@pytest.mark.parametrize("name", ["linear", "cayley_gibbs_rodrigues"])
@SETTINGS
@given(first=rotations(size=8), second=rotations(size=8), near=st.booleans())
def test_out_of_range_compose_is_nan(module_dir: Path, name: str, first: Rotations, second: Rotations,
                                     near: bool) -> None:
    """NaN exactly when the composed rotation is not representable, never a wrong finite vector.

    ``near``: the second rotation shares the first one's axis and brings the total close to the
    end of the range (π/2 for linear, π for cayley_gibbs_rodrigues), from both sides."""
    module, param = get_module(name, module_dir), PARAMETERIZATIONS[name]
    (a1, f1), (a2, f2) = first, second
    n = min(len(f1), len(f2))
    a1, f1, a2, f2 = a1[:n], f1[:n], a2[:n], f2[:n]
    phi1 = f1 * param.phi_max
    top = param.phi_max - 1e-6  # sin(π/2 − 1e-6) = 1 − 5e-13 < 1: every input is in range
    phi1 = np.clip(phi1, -top, top)
    if near:
        a2 = a1
        phi2 = np.where(phi1 < 0, -1, 1) * (param.phi_max - np.abs(phi1)) + f2 * 1e-6
    else:
        phi2 = f2 * param.phi_max
    phi2 = np.clip(phi2, -top, top)
    p1 = (param.p(phi1)[:, None] * a1)
    p2 = (param.p(phi2)[:, None] * a2)
    with strict():
        p3 = module.compose(p1, p2)
        product = module.rotation_matrix(p2) @ module.rotation_matrix(p1)
    assert np.isfinite(p1).all() and np.isfinite(p2).all()
    phi3 = composed_angle(a1, phi1, a2, phi2)
    nan = np.isnan(p3).any(-1)
    assert np.array_equal(nan, np.isnan(p3).all(-1))
    margin = 1e-9  # the rounded inputs are these rotations to ~1e-16; 1e-9 is far outside rounding
    # inside: for sin φ the range ends at a fold (p′(π/2) = 0): φ within √(8ε) ≈ 4e-8 of π/2 has
    # |p| within 4ε of 1, where the rounding of |p|² decides; the quaternion test beyond is sharp
    inside_margin = 1e-7 if name == "linear" else margin
    assert not nan[phi3 < param.phi_max - inside_margin].any(), (phi3[nan], p3[nan])
    if name == "linear":
        assert nan[phi3 > param.phi_max + margin].all(), (phi3, p3)
    finite = ~nan
    eps = EPS[np.dtype(np.float64)]
    error = np.abs(module.rotation_matrix(p3[finite]) - product[finite]).max(axis=(-2, -1))
    theta = C_R * eps * (1 + kappa(module, param, p1) + kappa(module, param, p2) + kappa(module, param, p3))
    assert_within(error, theta[finite], f"{name} finite compose")


def test_out_of_range_inputs_are_nan(module_dir: Path) -> None:
    linear = get_module("linear", module_dir)
    with strict():
        for p in ([1.0, 0, 0], [0.8, 0.6, 0.0], [2.0, 0, 0]):
            p = np.array(p)
            assert np.isnan(linear.to_quaternion(p)).all()
            assert np.isnan(linear.rescale(p)).all()
            assert np.isnan(linear.compose(p, np.zeros(3))).all()
            assert np.isnan(linear.compose(np.zeros(3), p)).all()
        # 0.5 + 0.5 rad about x: representable (sin 1 < 1); 0.8 + 0.8 rad: 1.6 > π/2 is not
        assert np.allclose(linear.compose(np.array([math.sin(0.5), 0, 0]), np.array([math.sin(0.5), 0, 0])),
                           [math.sin(1.0), 0, 0], rtol=4e-16, atol=0)
        big = np.array([math.sin(0.8), 0, 0])
        assert np.isnan(linear.compose(big, big)).all()
        cgr = get_module("cayley_gibbs_rodrigues", module_dir)
        # 90° + 90° = 180°: not representable by CGR (|p| → ∞)
        assert np.isnan(cgr.compose(np.array([0, 2.0, 0]), np.array([0, 2.0, 0]))).all()
        # 120° + 120° = 240° ≡ −120°: representable once rescaled
        p = np.array([0, 0, 2 * math.tan(math.pi / 3)])
        composed = cgr.compose(p, p)
    with mpmath.workdps(40):  # 2 tan(φ₃/2), φ₃ = 2 (2 atan(p/2)) − 2π, of the rounded p: not −p (7 ulp away)
        exact = float(2 * mpmath.tan(2 * mpmath.atan(mpmath.mpf(p[2]) / 2) - mpmath.pi))
    assert composed[:2].tolist() == [0, 0] and abs(composed[2] - exact) <= 4 * np.spacing(abs(exact)), \
        (composed, exact)  # measured 0.36 ulp; was rtol 16 · 2.3e-16 against −p


# -- edge inputs (defects found while writing these tests, fixed) -------------------------------
def test_infinite_p_gives_nan_without_warning(module_dir: Path) -> None:
    module = get_module("rotation_vector", module_dir)
    with strict():
        assert np.isnan(module.to_quaternion(np.array([np.inf, 0, 0]))).all()


def test_huge_unbounded_vector_is_documented_out_of_range(module_dir: Path) -> None:
    """|p|² ≥ x_limit (2^341 for Wiener–Milenkovic in float64, symrot/plan/domain.py) is outside the
    documented range of p_max = ∞ parameterizations: NaN, never the unrescaled p (φ = 4 atan(p/4)
    = 2π − 1.6e-154 here) nor a warning."""
    module = get_module("wiener_milenkovic", module_dir)
    for p in (np.array([1e155, 0, 0]), np.array([1e80, 0, 0])):
        with strict():
            assert np.isnan(module.rescale(p)).all() and np.isnan(module.to_quaternion(p)).all()
            assert np.isnan(module.rotation_matrix(p)).all()
    with strict():
        q = module.rescale(np.array([1e50, 0, 0]))  # inside: 2π − 1.6e-49, rescaled
    assert abs(q[0] + 16 / 1e50) <= 4 * np.spacing(16 / 1e50)  # 4 tan(φ/4 − π/2) = −16/p; measured 0 ulp


def test_subnormal_quaternion_is_normalized(module_dir: Path) -> None:
    module = get_module("rotation_vector", module_dir)
    with strict():
        p = module.from_quaternion(np.array([1e-320, 1e-320, 0, 0]))
    assert p == pytest.approx([math.pi / 2, 0, 0], rel=1e-15)


def test_linear_identity_quaternion_is_exact(module_dir: Path) -> None:
    module = get_module("linear", module_dir)
    assert module.to_quaternion(np.zeros(3))[0] == 1.0
