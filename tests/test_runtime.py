"""The runtimes of the generated modules (symrot/backends/runtime/), tested on their own.

Each test builds a module from a runtime's copied text and a small hand-written plan — the Gibbs
vector g = tan(φ/2) u, whose coefficients are short closed forms (R = I + 2/(1+x) (g×) +
2/(1+x) (g×)², e₀ = 1/√(1+x), ν = 2/√(1+x), φ = 2 atan |g|) — without symrot's derivation or
plan, and checks the runtime against references written here: the tensor assembled directly
from its coefficients, exact rational arithmetic, the quaternion product.
"""

from __future__ import annotations

import math
import types
import warnings
from fractions import Fraction

import numpy as np
import pytest

from symrot.backends.runtime import MARKER, runtime_text

P_MAX_SQUARED = 1.0e6
NUMPY_RUNTIME = ("numpy_runtime", "numpy_operations")
NUMPY_PLAN = '''
import functools

import numpy

P_MAX = 1000.0
P_MAX_SQUARED = 1.0e6


def _one(x, phi, s, d, sin_half, cos_half, span=None):
    return numpy.ones_like(x)


def _zero(x, phi, s, d, sin_half, cos_half, span=None):
    return numpy.zeros_like(x)


def _two_over(x, phi, s, d, sin_half, cos_half, span=None):
    return 2.0 / (1.0 + x)


def _e0(x, phi, s, d, sin_half, cos_half, span=None):
    return 1.0 / numpy.sqrt(1.0 + x)


def _nu(x, phi, s, d, sin_half, cos_half, span=None):
    return 2.0 / numpy.sqrt(1.0 + x)


_TABLE = {"R_0": _one, "R_1": _two_over, "R_2": _two_over, "H_0": _two_over, "H_1": _two_over,
          "H_2": _zero, "e_0": _e0, "nu": _nu, "det_H": _two_over}
_COEFFICIENTS = {"64": _TABLE, "32": _TABLE}
_ACROSS = ()
_ANGLE = {suffix: (lambda s, d: 2.0 * numpy.arctan(s)) for suffix in ("64", "32")}
_ANGLE_LOW = {}
_ANGLE_LOW_BOUND = {}
_SCALE = {suffix: (lambda e0, e_norm: 1.0 / e0) for suffix in ("64", "32")}
_USES_PHI = {suffix: dict.fromkeys(_TABLE, False) for suffix in ("64", "32")}
_SWITCH = {"64": {}, "32": {}}
_X_LIMIT = {"64": 2.0 ** 600, "32": numpy.float32(2.0 ** 100)}
_DERIVATIVE_X_LIMIT = _X_LIMIT
E0_MIN = 0.0
_ROTATION_TOLERANCE = {"64": 2.0 ** -26, "32": numpy.float32(2.0 ** -11)}
_COMPLEMENT = None
_COMPLEMENT_LOW = 0.0


def _inside(x, suffix):
    return x < P_MAX_SQUARED
'''


def _module(source: str, name: str) -> types.ModuleType:
    module = types.ModuleType(name)
    exec(compile(source, f"<{name}>", "exec"), module.__dict__)
    return module


@pytest.fixture(scope="module")
def gibbs() -> types.ModuleType:
    """The NumPy runtime on the Gibbs plan."""
    return _module("\n\n".join([NUMPY_PLAN, *map(runtime_text, NUMPY_RUNTIME)]), "runtime_gibbs")


def _skew(v: np.ndarray) -> np.ndarray:
    out = np.zeros((*v.shape, 3))
    out[..., 0, 1], out[..., 0, 2], out[..., 1, 2] = -v[..., 2], v[..., 1], -v[..., 0]
    return out - np.swapaxes(out, -1, -2)


def _gibbs_rotation(g: np.ndarray) -> np.ndarray:
    """R = I + 2/(1+x) (g×) + 2/(1+x) (g×)², in float64 from the coefficients directly."""
    g = g.astype(np.float64)
    c = 2.0 / (1.0 + np.einsum("...i,...i->...", g, g))
    k = _skew(g)
    return np.eye(3) + c[..., None, None] * k + c[..., None, None] * (k @ k)


def _vectors(n: int, dtype: type, seed: int = 3) -> np.ndarray:
    rng = np.random.default_rng(seed)
    return (rng.normal(size=(n, 3)) * rng.choice([1e-9, 0.3, 2.0, 40.0], size=(n, 1))).astype(dtype)


def test_every_runtime_has_one_marker() -> None:
    for name in (*NUMPY_RUNTIME, "array_runtime", "jax_runtime", "torch_runtime"):
        text = runtime_text(name)
        assert text and MARKER not in text
        assert "{{" not in text and "{%" not in text, f"{name}: template syntax in a runtime"


@pytest.mark.parametrize("dtype", [np.float64, np.float32])
@pytest.mark.parametrize("n", [1, 5, 16, 40, 64, 65, 5000])
def test_tensor_paths_agree_with_the_coefficients(gibbs: types.ModuleType, n: int, dtype: type) -> None:
    """_tensor's scalar (few), gathered (small) and blocked paths: R from its coefficients within
    4 ulp of the float64 assembly (entries ≤ 1 in size), the same bits whichever path a row takes."""
    g = _vectors(n, dtype)
    r = gibbs.rotation_matrix(g)
    assert r.dtype == dtype and r.shape == (n, 3, 3)
    eps = np.finfo(dtype).eps
    assert np.max(np.abs(r - _gibbs_rotation(g))) <= 4 * eps
    single = np.stack([gibbs.rotation_matrix(g[i:i + 1])[0] for i in range(min(n, 70))])
    assert np.array_equal(single, r[:len(single)]), "a row's R depends on the batch it is in"


def test_outside_the_range_is_nan(gibbs: types.ModuleType) -> None:
    edge = math.sqrt(P_MAX_SQUARED)
    g = np.array([[edge * 0.999, 0, 0], [edge * 1.001, 0, 0], [np.nan, 0, 0], [np.inf, 0, 0]])
    for batch in (g, np.tile(g, (30, 1))):
        r = gibbs.rotation_matrix(batch)
        assert np.isfinite(r[0::4]).all()
        assert np.isnan(r[1::4]).all() and np.isnan(r[2::4]).all() and np.isnan(r[3::4]).all()


def test_apply_is_the_tensor_times_the_vector(gibbs: types.ModuleType) -> None:
    g, v = _vectors(100, np.float64), _vectors(100, np.float64, seed=4)
    h = gibbs.tangent(g)
    assert np.allclose(gibbs.omega(g, v), np.einsum("...ij,...j->...i", h, v), rtol=1e-14, atol=1e-300)


def test_compose_is_the_product_of_the_rotations(gibbs: types.ModuleType) -> None:
    """R(compose(g1, g2)) = R(g2) R(g1): g1 applied first (eqs 18-19, 67)."""
    g1, g2 = _vectors(200, np.float64) / 50, _vectors(200, np.float64, seed=5) / 50
    g3 = gibbs.compose(g1, g2)
    finite = np.isfinite(g3).all(-1)
    assert finite.mean() > 0.9
    product = _gibbs_rotation(g2) @ _gibbs_rotation(g1)
    assert np.allclose(_gibbs_rotation(g3[finite]), product[finite], atol=1e-12)


def test_from_rotation_matrix_inverts_and_refuses(gibbs: types.ModuleType) -> None:
    g = _vectors(50, np.float64) / 10
    back = gibbs.from_rotation_matrix(_gibbs_rotation(g))
    assert np.allclose(back, g, rtol=1e-12, atol=1e-15)
    reflection = np.diag([1.0, 1.0, -1.0])
    assert np.isnan(gibbs.from_rotation_matrix(reflection)).all()
    assert np.isnan(gibbs.from_rotation_matrix(2.0 * np.eye(3))).all()


def test_angle_and_quaternion(gibbs: types.ModuleType) -> None:
    g = _vectors(30, np.float64)
    phi = 2.0 * np.arctan(np.linalg.norm(g, axis=-1))
    assert np.allclose(gibbs.angle(g), phi, rtol=1e-15)
    e = gibbs.to_quaternion(g)
    assert np.allclose(e[:, 0], np.cos(phi / 2), rtol=1e-15)
    assert np.allclose(np.linalg.norm(e, axis=-1), 1.0, rtol=1e-15)


@pytest.mark.parametrize(("value", "message"), [
    (np.zeros(3, dtype=complex), "real float"), (np.zeros(3, dtype=bool), "real float"),
    (np.array(["a", "b", "c"]), "real float"), (np.zeros(4), "shape"),
    (np.ma.masked_array(np.zeros(3)), "masked")])
def test_input_is_refused_with_its_reason(gibbs: types.ModuleType, value: np.ndarray, message: str) -> None:
    with pytest.raises(ValueError, match=message):
        gibbs.rotation_matrix(value)


def test_input_keeps_its_precision(gibbs: types.ModuleType) -> None:
    assert gibbs.rotation_matrix(np.zeros(3, dtype=">f4")).dtype == np.float32
    assert gibbs.rotation_matrix(np.zeros(3, dtype=">f8")).dtype == np.float64
    assert gibbs.rotation_matrix(np.zeros(3, dtype=np.int32)).dtype == np.float64
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # no RuntimeWarning reaches the caller
        gibbs.rotation_matrix(np.array([[1e300, 1e300, 0.0], [np.nan, 0, 0]]))


def test_norm_without_underflow_or_overflow(gibbs: types.ModuleType) -> None:
    v = np.array([[3e-300, 4e-300, 0.0], [3e300, 4e300, 0.0], [np.inf, 0, 0], [np.nan, 1, 0], [0, 0, 0]])
    with np.errstate(all="ignore"):
        n = gibbs._norm(v)
    assert n[0] == pytest.approx(5e-300, rel=1e-15) and n[1] == pytest.approx(5e300, rel=1e-15)
    assert n[2] == np.inf and np.isnan(n[3]) and n[4] == 0.0


def test_two_square_is_exact(gibbs: types.ModuleType) -> None:
    a = _vectors(300, np.float64).ravel()
    square, error = gibbs._two_square(a)
    for value, high, low in zip(a.tolist(), square.tolist(), error.tolist(), strict=True):
        assert Fraction(high) + Fraction(low) == Fraction(value) ** 2


def test_complement_to_a_few_ulp() -> None:
    """d = k² − |p|² next to the pole, against exact rationals (float64: ≤ 2 ulp of d)."""
    source = NUMPY_PLAN.replace("_COMPLEMENT = None", "_COMPLEMENT = 4.0")
    module = _module("\n\n".join([source, *map(runtime_text, NUMPY_RUNTIME)]), "runtime_complement")
    rng = np.random.default_rng(11)
    u = rng.normal(size=(400, 3))
    u /= np.linalg.norm(u, axis=1)[:, None]
    p = u * (2.0 * (1.0 - np.logspace(-15, -1, 400)))[:, None]
    d = module._complement(p)
    for row, value in zip(p.tolist(), d.tolist(), strict=True):
        exact = 4 - sum(Fraction(c) ** 2 for c in row)
        assert abs(Fraction(value) - exact) <= 2 * math.ulp(float(exact)), (row, value, float(exact))


def test_span_takes_the_exact_path_for_doubtful_blocks(gibbs: types.ModuleType) -> None:
    assert gibbs._span(np.array([0.5, 2.0]), "64") == (0.5, 2.0)
    for x in ([], [np.nan, 1.0], [1.0, P_MAX_SQUARED], [1e-200, 1.0], [1.0] * 63 + [np.nan],
              [1.0] * 100 + [np.nan]):
        assert gibbs._span(np.array(x, dtype=np.float64), "64") is None, x


TORCH_PLAN = '''
P_MAX = 1000.0
P_MAX_SQUARED = 1.0e6


def _one(x, phi, s, d, sin_half, cos_half):
    return _xp.ones_like(x)


def _zero(x, phi, s, d, sin_half, cos_half):
    return _xp.zeros_like(x)


def _two_over(x, phi, s, d, sin_half, cos_half):
    return 2.0 / (1.0 + x)


def _e0(x, phi, s, d, sin_half, cos_half):
    return 1.0 / _sqrt(1.0 + x)


def _nu(x, phi, s, d, sin_half, cos_half):
    return 2.0 / _sqrt(1.0 + x)


_TABLE = {"R_0": _one, "R_1": _two_over, "R_2": _two_over, "H_0": _two_over, "H_1": _two_over,
          "H_2": _zero, "e_0": _e0, "nu": _nu, "det_H": _two_over}
_COEFFICIENTS = {"64": _TABLE, "32": _TABLE}
_ACROSS = ()
_ANGLE = {suffix: (lambda s, d: 2.0 * _xp.atan(s)) for suffix in ("64", "32")}
_ANGLE_LOW = {}
_ANGLE_LOW_BOUND = {}
_SCALE = {suffix: (lambda e0, e_norm: 1.0 / e0) for suffix in ("64", "32")}
_USES_PHI = {suffix: dict.fromkeys(_TABLE, False) for suffix in ("64", "32")}
_X_LIMIT = {"64": 2.0 ** 600, "32": 2.0 ** 100}
E0_MIN = 0.0
_ROTATION_TOLERANCE = {"64": 2.0 ** -26, "32": 2.0 ** -11}
_COMPLEMENT = None
_COMPLEMENT_LOW = 0.0


def _inside(x, suffix):
    return x < P_MAX_SQUARED
'''


@pytest.fixture(scope="module", params=["torch", "jax"])
def array_gibbs(request: pytest.FixtureRequest) -> types.ModuleType:
    """The array runtime with a framework's primitives on the Gibbs plan."""
    if request.param == "torch":
        pytest.importorskip("torch")
        imports = "import math\n\nimport torch as _xp\n"
    else:
        pytest.importorskip("jax")
        imports = "import math\n\nimport jax\nimport jax.numpy as _xp\nfrom jax import lax\n"
    source = "\n\n".join([imports, runtime_text(f"{request.param}_runtime"), TORCH_PLAN,
                          runtime_text("array_runtime")])
    module = _module(source, f"runtime_{request.param}")
    module.framework = request.param  # type: ignore[attr-defined]
    return module


def _array(module: types.ModuleType, value: np.ndarray) -> object:
    if module.framework == "torch":
        import torch
        return torch.as_tensor(value)
    import jax.numpy as jnp
    return jnp.asarray(value)


def test_array_runtime_rotation_and_compose(array_gibbs: types.ModuleType) -> None:
    g1 = _vectors(64, np.float32) / 20
    g2 = _vectors(64, np.float32, seed=8) / 20
    r = np.asarray(array_gibbs.rotation_matrix(_array(array_gibbs, g1)))
    assert r.dtype == np.float32
    assert np.max(np.abs(r - _gibbs_rotation(g1))) <= 8 * np.finfo(np.float32).eps
    g3 = np.asarray(array_gibbs.compose(_array(array_gibbs, g1), _array(array_gibbs, g2)))
    product = _gibbs_rotation(g2) @ _gibbs_rotation(g1)
    assert np.max(np.abs(_gibbs_rotation(g3) - product)) <= 1e-5
    outside = np.array([[2000.0, 0.0, 0.0]], dtype=np.float32)
    assert np.isnan(np.asarray(array_gibbs.rotation_matrix(_array(array_gibbs, outside)))).all()


def test_array_runtime_derivative_by_forward_mode(array_gibbs: types.ModuleType) -> None:
    """d(R a)/dp from the runtime's jvp columns against central differences of the formula."""
    g = _vectors(8, np.float32) / 10
    a = _vectors(8, np.float32, seed=9)
    jac = np.asarray(array_gibbs.rotation_derivative(_array(array_gibbs, g), _array(array_gibbs, a)))
    step = 1e-6
    for k in range(3):
        e = np.zeros(3)
        e[k] = step
        difference = _gibbs_rotation(g + e) - _gibbs_rotation(g - e)
        column = np.einsum("...ij,...j->...i", difference, a) / (2 * step)
        assert np.allclose(jac[..., k], column, atol=2e-4), k


def test_horner_and_clenshaw_against_their_sums(gibbs: types.ModuleType) -> None:
    """The runtime's polynomial helpers against the sums they stand for (zero terms included)."""
    coefficients = (1.0, 0.0, -0.25, 0.0, 0.125, 3.0)
    t = np.linspace(-1.0, 1.0, 41)
    for terms in range(1, len(coefficients) + 1):
        expected = sum(c * t ** k for k, c in enumerate(coefficients[:terms]))
        assert np.allclose(gibbs._horner(coefficients, terms, t), expected, rtol=0, atol=1e-15)
    chebyshev = (0.5, -1.0, 0.25, 0.0, 2.0)
    assert np.allclose(gibbs._clenshaw(chebyshev, t), np.polynomial.chebyshev.chebval(t, chebyshev),
                       rtol=0, atol=1e-14)


def test_series_tables_share_only_common_starts() -> None:
    from symrot.backends.series_tables import SeriesTables

    tables = SeriesTables()
    first = tables.reference("R_2", ["1.0", "0.5"])
    assert tables.reference("R_2", ["1.0", "0.5", "0.25"]) == first  # lengthened
    assert tables.reference("H_0", ["1.0"]) == first  # a start of it
    other = tables.reference("R_2", ["1.0", "0.4"])
    assert other != first
    rows = {table["name"]: table["rows"] for table in tables.context()}
    assert rows[first] == ["1.0, 0.5, 0.25,"] and rows[other] == ["1.0, 0.4,"]
