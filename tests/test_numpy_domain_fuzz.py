"""The generated NumPy modules over every magnitude: no warning, finite or NaN, NaN exactly outside.

Issue 17, generated-code half, for the 7 modules under ``generated/numpy/`` in float64 and float32:

* every public function on vectors whose components come from ``MAGNITUDES`` (0, the smallest
  subnormal, 1e-300 … 1.7e308, inf, NaN, both signs), under ``warnings.simplefilter("error")``
  with every NumPy floating-point warning enabled: no RuntimeWarning escapes (``_quiet``), outputs
  are finite or NaN, never ±inf, and the functions of p are NaN exactly where the exact |p|² is
  outside the range: |p|² ≥ p_max² with p_max from tests/reference.py (tests/edges.py), or the
  documented x_limit for unbounded p; ``EDGE_FACTORS`` add magnitudes a few ulps either side of
  that edge, and vectors whose rounded |p|² may fall on either side (|x − edge| ≤ γ₃ x) are left
  undecided;
* the operations return either NaN or a vector inside that same test (``angle`` of it is finite):
  ``from_quaternion`` of Cayley–Gibbs–Rodrigues and Wiener–Milenkovic near e₀ → 0 included;
* ``from_rotation_matrix`` refuses what is not a rotation (max |RᵀR − I| > tol or det R ≤ 0, tol =
  2⁻²⁶ in float64, 2⁻¹¹ in float32: ``symrot.plan.quaternion.ROTATION_TOLERANCE_POWER``) and
  accepts rotations perturbed within tol.
"""

from __future__ import annotations

import importlib.util
import itertools
import warnings
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from fractions import Fraction
from pathlib import Path
from types import ModuleType
from typing import Any

import numpy as np
import pytest

from symrot.plan.quaternion import ROTATION_TOLERANCE_POWER

from .edges import FAMILIES, documented_x_limit, edge
from .reference import GeneratingFunction, Reference

GENERATED = Path(__file__).resolve().parent.parent / "generated" / "numpy"
NAMES = sorted(path.stem for path in GENERATED.glob("*.py"))
MAGNITUDES = (0.0, 5e-324, 1e-300, 1e-30, 1.0, 1e10, 1e80, 1e300, 1.7e308, np.inf, np.nan)
EDGE_FACTORS = (0.5, 1 - 2.0**-20, 1 - 2.0**-48, 1 + 2.0**-48, 1 + 2.0**-20)
"""Magnitudes m·edge added to MAGNITUDES, edge = p_max or √x_limit; NEAR_FACTORS /√3 too (the rows
(a, −a, a)). ±2⁻⁴⁸ is a few float64 ulps: NaN must start there, not 2 % further out."""
NEAR_FACTORS = (1 - 2.0**-20, 1 + 2.0**-20)
OF_P = ("angle", "rotation_matrix", "tangent", "tangent_inverse", "tangent_det", "root_matrix",
        "root_tangent", "to_quaternion")
DTYPES = (np.float64, np.float32)
SUFFIX = {np.float64: "64", np.float32: "32"}
LABEL = {np.float64: "float64", np.float32: "float32"}


def load(name: str) -> ModuleType:
    spec = importlib.util.spec_from_file_location(f"symrot_fuzz_{name}", GENERATED / f"{name}.py")
    assert spec and spec.loader
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


@pytest.fixture(scope="module", params=NAMES)
def module(request: pytest.FixtureRequest) -> ModuleType:
    return load(request.param)


@contextmanager
def strict() -> Iterator[None]:
    """Every floating-point condition NumPy can report (underflow too) raised as an error."""
    with warnings.catch_warnings(), np.errstate(all="warn"):
        warnings.simplefilter("error")
        yield


def cast(values: object, dtype: type) -> np.ndarray:
    """values in dtype (1e300 → inf in float32, as a caller's own cast would give)."""
    with np.errstate(all="ignore"):
        return np.asarray(values, dtype=np.float64).astype(dtype)


def edge_of(module: ModuleType, dtype: type) -> float:
    """|p| at the edge of the range: p_max from tests/reference.py, or √x_limit (documented)."""
    name = module.__name__.removeprefix("symrot_fuzz_")
    found = edge(FAMILIES[name])
    if found.bounded:
        return float(found.p_max)
    return float(np.sqrt(documented_x_limit(GENERATED / f"{name}.py", dtype)))


def vectors(module: ModuleType, dtype: type) -> np.ndarray:
    """(m1, m2, 0), (m1, -m1, m1) and (-m1, 0, m2) for every pair of magnitudes (MAGNITUDES and
    the EDGE_FACTORS and NEAR_FACTORS of the module's edge)."""
    size = edge_of(module, dtype)
    near = (*(f * size for f in EDGE_FACTORS), *(f * size / np.sqrt(3) for f in NEAR_FACTORS))
    magnitudes = (*MAGNITUDES, *near)
    rows = []
    for a, b in itertools.product(magnitudes, repeat=2):
        rows += [(a, b, 0.0), (a, -a, a), (-a, 0.0, b)]
    return cast(rows, dtype)


def _fraction(value: Any) -> Fraction:
    """An mpmath number as the exact fraction it is."""
    mantissa, exponent = value.man_exp
    return Fraction(mantissa) * Fraction(2) ** exponent


def exact_inside(module: ModuleType, p: np.ndarray, dtype: type) -> tuple[np.ndarray, np.ndarray]:
    """(inside, decided): the exact |p|² below the edge squared (p_max² of tests/reference.py, or the
    documented x_limit), and whether the rounding of |p|² (|x̂ − x| ≤ γ₃ x) cannot move it across."""
    name = module.__name__.removeprefix("symrot_fuzz_")
    found = edge(FAMILIES[name])
    bound = _fraction(found.p_max_squared) if found.bounded else \
        Fraction(documented_x_limit(GENERATED / f"{name}.py", dtype))
    u = Fraction(float(np.finfo(dtype).eps)) / 2
    gamma = 3 * u / (1 - 3 * u)
    inside, decided = [], []
    for row in p.astype(np.float64):
        if not np.isfinite(row).all():
            inside.append(False)
            decided.append(True)
            continue
        exact = sum(Fraction(float(c)) ** 2 for c in row)
        inside.append(exact < bound)
        decided.append(abs(exact - bound) > gamma * exact)
    return np.asarray(inside), np.asarray(decided)


def nan_rows(values: np.ndarray, rows: int) -> np.ndarray:
    flat = values.reshape(rows, -1)
    nan = np.isnan(flat)
    assert np.array_equal(nan.any(-1), nan.all(-1)), "rows partly NaN"
    return nan.all(-1)


def check_finite_or_nan(values: np.ndarray, what: str) -> None:
    assert not np.isinf(values).any(), f"{what}: infinite output"


def check_inside_or_nan(module: ModuleType, result: np.ndarray, dtype: type, what: str) -> np.ndarray:
    """Each row of an operation's result is all NaN or a vector its own module accepts."""
    check_finite_or_nan(result, what)
    nan = nan_rows(result, len(result))
    with strict():
        angle = module.angle(result)
    disagree = result[np.isnan(angle) != nan]
    assert np.array_equal(np.isnan(angle), nan), f"{what}: NaN and domain disagree at {disagree}"
    return nan


@pytest.mark.parametrize("dtype", DTYPES)
def test_functions_of_p_over_all_magnitudes(module: ModuleType, dtype: type) -> None:
    p = vectors(module, dtype)
    inside, decided = exact_inside(module, p, dtype)
    assert inside[decided].any() and not inside[decided].all() and decided.mean() > 0.9
    for name in OF_P:
        with strict():
            batch = getattr(module, name)(p)
        what = f"{module.__name__} {name} {dtype.__name__}"
        assert batch.dtype == dtype, what
        check_finite_or_nan(batch, what)
        nan = nan_rows(batch, len(p))
        assert np.array_equal(nan[decided], ~inside[decided]), \
            f"{what}: NaN {p[nan & inside & decided]}, finite {p[~nan & ~inside & decided]}"
        for row, expected in zip(p[::7], batch[::7], strict=True):  # one vector at a time, too
            with strict():
                single = getattr(module, name)(row)
            # the batch recomputes x of its valid rows after masking: equal up to rounding
            scale = 16 * float(np.finfo(dtype).eps) * max(1.0, float(np.nan_to_num(np.abs(expected)).max()))
            np.testing.assert_allclose(single, expected, rtol=0, atol=scale, err_msg=what)
    second = cast([[0.3, -0.5, 0.8]] * len(p), dtype) * cast(1e10, dtype)
    for name in ("pdot", "omega"):
        with strict():
            result = getattr(module, name)(p, second)
        what = f"{module.__name__} {name} {dtype.__name__}"
        check_finite_or_nan(result, what)
        assert np.array_equal(nan_rows(result, len(p))[decided], ~inside[decided]), what
        with strict():  # a non-finite or huge second argument: no warning (the values may be inf)
            getattr(module, name)(p, np.roll(p, 1, axis=0))


@pytest.mark.parametrize("dtype", DTYPES)
def test_operations_over_all_magnitudes(module: ModuleType, dtype: type) -> None:
    p = vectors(module, dtype)
    inside, decided = exact_inside(module, p, dtype)
    what = f"{module.__name__} {dtype.__name__}"
    for label, call in (("rescale", lambda: module.rescale(p)),
                        ("compose", lambda: module.compose(p, np.roll(p, 5, axis=0))),
                        ("compose p1 first", lambda: module.compose(np.roll(p, 5, axis=0), p))):
        with strict():
            result = call()
        nan = check_inside_or_nan(module, result, dtype, f"{what} {label}")
        assert (~nan & inside).any() and nan[~inside & decided].all(), f"{what} {label}"
    quaternions = cast([(a, b, -c, 0.0) for a, b, c in itertools.product(MAGNITUDES, repeat=3)], dtype)
    with strict():
        result = module.from_quaternion(quaternions)
    nan = check_inside_or_nan(module, result, dtype, f"{what} from_quaternion")
    assert nan[~np.isfinite(quaternions).all(-1) | ~quaternions.any(-1)].all(), what
    matrices = np.zeros((len(quaternions), 3, 3), dtype=dtype)  # [[a, b, 0], [-b, a, 0], [0, 0, c]]
    matrices[:, 0, 0] = matrices[:, 1, 1] = quaternions[:, 0]
    matrices[:, 0, 1], matrices[:, 1, 0] = quaternions[:, 1], -quaternions[:, 1]
    matrices[:, 2, 2] = -quaternions[:, 2]
    with strict():
        result = module.from_rotation_matrix(matrices)
    nan = check_inside_or_nan(module, result, dtype, f"{what} from_rotation_matrix")
    assert 0 < (~nan).sum() < len(nan), what  # the rotations among them (e.g. I) are accepted


@pytest.mark.parametrize("dtype", DTYPES)
@pytest.mark.parametrize("name", ["cayley_gibbs_rodrigues", "wiener_milenkovic"])
def test_half_turn_quaternions_follow_the_domain(name: str, dtype: type) -> None:
    """e = (e0, 1, 0, 0), e0 → 0: CGR p = 2/e0 leaves the domain (NaN once |p|² ≥ x_limit), WM
    p → 4 stays inside; either way the result is NaN or accepted by angle."""
    module = load(name)
    e0 = [1e-300, 1e-100, 1e-30, 1e-17, 1e-10, 1e-5, 0.1, 0.0]
    e = cast([(v, 1.0, 0.0, 0.0) for v in e0], dtype)
    with strict():
        p = module.from_quaternion(e)
    nan = check_inside_or_nan(module, p, dtype, f"{name} {dtype.__name__}")
    reference = Reference(GeneratingFunction(FAMILIES[name]))
    eps = float(np.finfo(dtype).eps)
    if name == "wiener_milenkovic":
        assert not nan.any()
    else:  # tan(φ/2) = |e|/e0: p = 2/e0, outside from (2/e0)² ≥ the documented x_limit on
        limit = Fraction(documented_x_limit(GENERATED / f"{name}.py", dtype))
        expected_nan = [v == 0 or Fraction(2) ** 2 / Fraction(float(v)) ** 2 >= limit for v in e[:, 0]]
        assert np.array_equal(nan, expected_nan), (p, expected_nan)
        assert nan.any() and not nan.all()
    for row, vector in zip(e[~nan], p[~nan], strict=True):  # within 4 ulp of tests/reference.py
        exact = [float(v) for v in reference.from_quaternion([float(c) for c in row])]
        assert np.max(np.abs(vector.astype(np.float64) - exact)) <= 4 * eps * max(abs(v) for v in exact), row


def rz(angle: float) -> np.ndarray:
    c, s = np.cos(angle), np.sin(angle)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


NOT_ROTATIONS: dict[str, Callable[[], np.ndarray]] = {
    "zeros": lambda: np.zeros((3, 3)),
    "ones": lambda: np.ones((3, 3)),
    "diag(1,1,-1)": lambda: np.diag([1.0, 1.0, -1.0]),
    "-I": lambda: -np.eye(3),
    "2 Rz(1)": lambda: 2 * rz(1.0),
    "rank 1": lambda: np.outer([0.6, 0.8, 0.0], [0.0, 0.6, 0.8]),
    "rank 1 trace 1": lambda: np.outer([1.0, 0.0, 0.0], [1.0, 0.0, 0.0]),
    "NaN entry": lambda: rz(0.3) + np.where(np.arange(9).reshape(3, 3) == 7, np.nan, 0.0),
    "inf entry": lambda: rz(0.3) + np.where(np.arange(9).reshape(3, 3) == 5, np.inf, 0.0),
    "1e300 I": lambda: 1e300 * np.eye(3),
}


def tolerance(dtype: type) -> float:
    return 2.0 ** ROTATION_TOLERANCE_POWER[LABEL[dtype]]


@pytest.mark.parametrize("dtype", DTYPES)
def test_from_rotation_matrix_refuses_non_rotations(module: ModuleType, dtype: type) -> None:
    tol = tolerance(dtype)
    matrices = {**{k: v() for k, v in NOT_ROTATIONS.items()},
                "(1 + 4 tol) Rz(1)": (1 + 4 * tol) * rz(1.0),
                "Rz(1) + 4 tol e01": rz(1.0) + 4 * tol * np.outer([1, 0, 0], [0, 1, 0])}
    for label, matrix in matrices.items():
        with strict():
            p = module.from_rotation_matrix(cast(matrix, dtype))
        assert np.isnan(p).all(), f"{module.__name__} {dtype.__name__} {label}: {p}"
    # a batch mixing them with rotations keeps the rotations
    batch = np.stack([cast(m, dtype) for m in matrices.values()] + [cast(rz(1.0), dtype)])
    with strict():
        p = module.from_rotation_matrix(batch)
    assert np.isnan(p[:-1]).all() and np.isfinite(p[-1]).all()


@pytest.mark.parametrize("dtype", DTYPES)
def test_from_rotation_matrix_accepts_perturbed_rotations(module: ModuleType, dtype: type) -> None:
    """Rotations rounded to the format, and perturbed by up to tol/8 per entry, are accepted; the
    result is within O(perturbation) of the exact rotation's parameters."""
    tol = tolerance(dtype)
    rng = np.random.default_rng(17)
    angles = rng.uniform(-0.9, 0.9, size=40) * float(module.angle(np.array([module.P_MAX * 0.999, 0, 0]))
                                                     if np.isfinite(module.P_MAX) else np.pi)
    exact = np.stack([rz(a) for a in angles])
    perturbed = exact + rng.uniform(-tol / 8, tol / 8, size=exact.shape) * (np.arange(40) % 2)[:, None, None]
    with strict():
        got = module.from_rotation_matrix(cast(perturbed, dtype))
        reference = module.from_rotation_matrix(exact)
    refused = perturbed[~np.isfinite(got).all(-1)]
    assert np.isfinite(got).all(), f"{module.__name__} {dtype.__name__}: refused {refused}"
    scale = 1 + np.abs(reference).max(-1)
    with strict():
        kappa = 1 + np.abs(module.tangent_inverse(reference)).max((-2, -1))
    error = np.abs(got.astype(np.float64) - reference).max(-1)
    assert (error <= 8 * tol * kappa * scale).all(), (error, tol)
