"""C operations of issue 6 against the NumPy modules: compiled with gcc, called through ctypes.

The generated headers of rotation_vector, wiener_milenkovic, cayley_gibbs_rodrigues, linear,
det_h_one, euler_rodrigues and (through ``symrot derive ... --emit c``) the user expression
cbrt(6*(phi-sin(phi))) are compiled in one translation unit (gcc -std=c99 -Wall -Wextra -Wpedantic
-Werror -O2, shared object) with one loop wrapper per function and precision. On random inputs
(all angles of the range, both signs, p = 0, |p| = 1e-300 (1e-38 in float), unnormalized and
negative-e0 quaternions, exact half turns) the C results must equal the NumPy module's to
``ULPS`` units of the precision — relative to |p| plus, for vectors whose rotation is
ill-conditioned in p, the rotation error of a few ε mapped to p (``gain`` of
test_operations_numpy; both codes round differently, e.g. the order of the Hamilton product
terms) — and the returned status must be nonzero exactly where NumPy returns NaN. Near φ = π the
sign of a rescaled vector may differ (p and −p are the same rotation there).

ULPS = 4: the largest measured ratio error / (ε × the factor of :func:`allowed`) is 1.8 (R of
det_h_one near 2π), ≤ 0.9 for every operation of issue 6, in double and float.
"""

from __future__ import annotations

import ctypes
import shutil
import subprocess
from pathlib import Path
from types import ModuleType

import numpy as np
import pytest

from symrot.cli import main as symrot_main

from . import c_harness
from .test_operations_numpy import (
    EXTRA,
    FLIP_ZONE,
    PARAMETERIZATIONS,
    Parameterization,
    angles_of,
    gain,
    get_module,
    kappa,
    parameter,
)

ROOT = Path(__file__).resolve().parent.parent
GENERATED = ROOT / "generated" / "c"
NAMES = ("rotation_vector", "wiener_milenkovic", "cayley_gibbs_rodrigues", "linear", "det_h_one",
         "euler_rodrigues", "user_eq35")
FLAGS = (*c_harness.STRICT_C, "-O2")
CTYPE = {"double": "double", "float": "float"}
DTYPE = {"double": np.float64, "float": np.float32}
SUFFIX = {"double": "", "float": "_f"}
ULPS = 4.0
TINY = {"double": 1e-300, "float": 1e-38}

pytestmark = pytest.mark.skipif(shutil.which("gcc") is None, reason="gcc not installed")

# (function, input widths, output width, returns status)
OPERATIONS = {"to_quaternion": ((3,), 4, False), "from_quaternion": ((4,), 3, True),
              "from_rotation_matrix": ((9,), 3, True), "compose": ((3, 3), 3, True),
              "rescale": ((3,), 3, True), "rotation_matrix": ((3,), 9, False)}


def wrappers(name: str) -> str:
    """One exported loop per function and precision: t_NAME_FUNC[_f](n, in1, in2, out, status)."""
    lines = []
    for precision in ("double", "float"):
        t = CTYPE[precision]
        for function, (widths, width, has_status) in OPERATIONS.items():
            target = f"symrot_{name}_{function}{SUFFIX[precision]}"
            symbol = f"t_{name}_{function}{SUFFIX[precision]}"
            arguments = ", ".join(f"in{j} + {w}*i" for j, w in enumerate(widths))
            call = f"{target}({arguments}, out + {width}*i)"
            body = f"status[i] = {call};" if has_status else f"{call}; status[i] = 0;"
            signature = f"void {symbol}(size_t n, const {t} *in0, const {t} *in1, {t} *out, int *status)"
            lines.append(signature + ";")
            lines.append(signature + " { size_t i; (void)in1; for (i = 0; i < n; ++i) { " + body + " } }")
    return "\n".join(lines)


@pytest.fixture(scope="module")
def library(tmp_path_factory: pytest.TempPathFactory) -> ctypes.CDLL:
    work = tmp_path_factory.mktemp("operations_c")
    assert symrot_main(["derive", PARAMETERIZATIONS["user_eq35"].source, "--name", "user_eq35",
                        "--emit", "c", "--out", str(work)]) == 0
    for name in NAMES[:-1]:
        shutil.copy(GENERATED / f"symrot_{name}.h", work)
    source = work / "operations.c"
    source.write_text("#include <stddef.h>\n" + "".join(f'#include "symrot_{n}.h"\n' for n in NAMES)
                      + "\n".join(wrappers(n) for n in NAMES) + "\n", encoding="utf-8")
    out = work / "operations.so"
    command = ["gcc", *FLAGS, "-fPIC", "-shared", f"-I{work}", str(source), "-o", str(out), "-lm"]
    result = subprocess.run(command, capture_output=True, text=True, timeout=600, check=False)
    assert result.returncode == 0, f"$ {' '.join(command)}\n{result.stderr[-6000:]}"
    return ctypes.CDLL(str(out))


def call(library: ctypes.CDLL, name: str, function: str, precision: str,
         *inputs: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(outputs (n, width), status (n,)) of the C function on n rows of ``inputs``."""
    widths, width, _ = OPERATIONS[function]
    dtype = DTYPE[precision]
    arrays = [np.ascontiguousarray(a, dtype=dtype).reshape(-1, w)
              for a, w in zip(inputs, widths, strict=True)]
    n = len(arrays[0])
    second = arrays[1] if len(arrays) > 1 else arrays[0]
    out = np.full((n, width), -7.0, dtype=dtype)
    status = np.full(n, -7, dtype=np.intc)
    pointer = ctypes.POINTER(ctypes.c_double if precision == "double" else ctypes.c_float)
    fn = getattr(library, f"t_{name}_{function}{SUFFIX[precision]}")
    fn.argtypes = [ctypes.c_size_t, pointer, pointer, pointer, ctypes.POINTER(ctypes.c_int)]
    fn.restype = None
    fn(n, arrays[0].ctypes.data_as(pointer), second.ctypes.data_as(pointer), out.ctypes.data_as(pointer),
       status.ctypes.data_as(ctypes.POINTER(ctypes.c_int)))
    return out, status


@pytest.fixture(scope="module", params=NAMES)
def case(request: pytest.FixtureRequest, tmp_path_factory: pytest.TempPathFactory) -> tuple[str, ModuleType]:
    directory = tmp_path_factory.getbasetemp() / "operations_c_modules"
    directory.mkdir(exist_ok=True)
    return request.param, get_module(request.param, directory)


def inputs(name: str, precision: str, count: int = 300, seed: int = 11) -> np.ndarray:
    """p over the whole range (fractions uniform in [-1, 1], edges, p = 0, |p| = TINY)."""
    param = PARAMETERIZATIONS.get(name) or _extra(name)
    rng = np.random.default_rng(seed)
    axes = rng.normal(size=(count, 3))
    axes /= np.linalg.norm(axes, axis=-1, keepdims=True)
    edges = [1 - 1e-7, -(1 - 1e-7), 0.5, 1e-3, 0, 0, 0, 0]
    fractions = np.concatenate([rng.uniform(-1, 1, count - len(edges)), edges])
    p = parameter(param, axes, fractions, DTYPE[precision])
    p[-3] = (axes[-3] * TINY[precision]).astype(DTYPE[precision])
    p[-2] = np.array([TINY[precision], 0, 0], dtype=DTYPE[precision])
    return p


def _extra(name: str) -> Parameterization:
    return EXTRA[name]


def allowed(module: ModuleType, name: str, function: str, args: tuple[np.ndarray, ...],
            reference: np.ndarray, eps: float) -> np.ndarray:
    """Per-row tolerance, ULPS ε × (see the module docstring):

    * to_quaternion, rotation_matrix: 1 + κ(p) (absolute: unit quaternion, |R_ij| ≤ 1);
    * vectors: |p| + gain(p) · θ with θ the rotation error in ε: κ of the inputs and the output
      (compose, rescale) or 1 + κ(p) (from_quaternion, from_rotation_matrix).

    κ(p) = φ + |p| / p'(φ) ~ 2φ for small φ, so tiny rotations keep relative tolerances."""
    param = PARAMETERIZATIONS.get(name) or _extra(name)
    finite = np.isfinite(reference).all(-1)
    ref = np.where(finite[:, None], reference, 0.0).astype(np.float64)
    if function in ("to_quaternion", "rotation_matrix"):
        return ULPS * eps * (1 + kappa(module, param, args[0].astype(np.float64)))
    out = kappa(module, param, ref)
    theta = {"compose": lambda: sum(kappa(module, param, a.astype(np.float64)) for a in args) + out,
             "rescale": lambda: kappa(module, param, args[0].astype(np.float64)) + out}.get(
        function, lambda: 1 + out)()
    return ULPS * eps * (np.linalg.norm(ref, axis=-1) + gain(module, param, ref) * theta)


def compare(got: np.ndarray, status: np.ndarray, expected: np.ndarray, tolerance: np.ndarray,
            what: str, phi: np.ndarray | None = None) -> None:
    """Status nonzero exactly on NumPy's NaN rows, NaN there in C too, elsewhere within tolerance.

    ``phi``: rotation angles of parameter vectors; within FLIP_ZONE of π, −expected is accepted
    too (p and −p are then the same rotation and either code may pick either sign)."""
    nan = np.isnan(expected).any(-1)
    assert np.array_equal(nan, np.isnan(expected).all(-1)), what
    assert np.array_equal(status != 0, nan), \
        f"{what}: status {status[status != 0]} vs NaN rows {np.nonzero(nan)}"
    assert np.isnan(got[nan]).all(), f"{what}: C outputs where NumPy is NaN: {got[nan]}"
    error = np.abs(got[~nan].astype(np.float64) - expected[~nan].astype(np.float64)).max(-1)
    if phi is not None:
        flipped = np.abs(got[~nan].astype(np.float64) + expected[~nan].astype(np.float64)).max(-1)
        error = np.where(np.abs(np.pi - phi[~nan]) < FLIP_ZONE, np.minimum(error, flipped), error)
    bad = ~(error <= tolerance[~nan])
    assert not bad.any(), \
        f"{what}: C {got[~nan][bad]} vs NumPy {expected[~nan][bad]}: {error[bad]} > {tolerance[~nan][bad]}"




def quaternion_inputs(precision: str, count: int = 200, seed: int = 12) -> np.ndarray:
    """Random directions in R⁴, unnormalized (scales 1e-3..1e3), e0 of both signs, e0 = 0 exactly."""
    rng = np.random.default_rng(seed)
    e = rng.normal(size=(count, 4)) * np.exp(rng.uniform(-7, 7, size=(count, 1)))
    e[:20, 0] = 0.0
    e[20:25] = [[1, 0, 0, 0], [-1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 0, -1], [0.5, 0.5, 0.5, 0.5]]
    return e.astype(DTYPE[precision])


def measure(library: ctypes.CDLL, name: str, module: ModuleType, precision: str) -> dict[str, tuple]:
    """{function: (C output, status, NumPy output)} on the inputs of this file."""
    dtype = DTYPE[precision]
    p = inputs(name, precision)
    q = np.roll(p, 7, axis=0)
    e = quaternion_inputs(precision)
    matrices = module.rotation_matrix(p)
    results = {}
    for function, args in (("to_quaternion", (p,)), ("from_quaternion", (e,)),
                           ("from_rotation_matrix", (matrices,)), ("compose", (p, q)),
                           ("compose", (p, -p)), ("rescale", (p,)), ("rotation_matrix", (p,))):
        got, status = call(library, name, function, precision, *args)
        expected = getattr(module, function)(*[a.astype(dtype) for a in args])
        key = function if function not in results else function + "_inverse"
        results[key] = (got, status, expected.reshape(len(got), -1), args)
    return results


@pytest.mark.parametrize("precision", ["double", "float"])
def test_c_operations_match_numpy(library: ctypes.CDLL, case: tuple[str, ModuleType], precision: str) -> None:
    name, module = case
    eps = float(np.finfo(DTYPE[precision]).eps)
    for function, (got, status, expected, args) in measure(library, name, module, precision).items():
        what = f"{name} {function} ({precision})"
        assert got.dtype == DTYPE[precision]
        tol = allowed(module, name, function.removesuffix("_inverse"), args, expected, eps)
        if function == "to_quaternion":
            # e0 absolutely, the vector part with its own (relative for tiny p) tolerance
            compare(got[:, :1], status, expected[:, :1], tol, what + " e0")
            size = np.linalg.norm(expected[:, 1:].astype(np.float64), axis=-1)
            vector = ULPS * eps * size + (tol - ULPS * eps)
            compare(got[:, 1:], status, expected[:, 1:], vector, what + " e")
        elif function == "rotation_matrix":
            compare(got, status, expected, tol, what)
        else:
            finite = np.isfinite(expected).all(-1)
            phi = np.zeros(len(expected))
            phi[finite] = angles_of(module, expected[finite])
            compare(got, status, expected, tol, what, phi)
        if function == "compose_inverse":  # compose(p, -p): the identity
            assert np.all(np.linalg.norm(got.astype(np.float64), axis=-1)
                          <= 4 * eps * np.linalg.norm(args[0].astype(np.float64), axis=-1)), what


@pytest.mark.parametrize("precision", ["double", "float"])
def test_zero_and_tiny(library: ctypes.CDLL, case: tuple[str, ModuleType], precision: str) -> None:
    """p = 0 gives exactly the identity; |p| = 1e-300 (1e-38 in float) keeps relative accuracy."""
    name, _module = case
    dtype, eps, tiny = DTYPE[precision], float(np.finfo(DTYPE[precision]).eps), TINY[precision]
    zero = np.zeros((1, 3), dtype=dtype)
    for function in ("compose", "rescale"):
        got, status = call(library, name, function, precision, *(zero,) * len(OPERATIONS[function][0]))
        assert status[0] == 0 and np.array_equal(got[0], np.zeros(3)), (name, function, got)
    e, _ = call(library, name, "to_quaternion", precision, zero)
    assert np.array_equal(e[0, 1:], np.zeros(3)) and abs(e[0, 0] - 1) <= eps, (name, e)
    p1 = (np.array([[0.3, -0.5, 0.8]]) * tiny).astype(dtype)
    p2 = (np.array([[0.7, 0.2, -0.1]]) * tiny).astype(dtype)
    p3, status = call(library, name, "compose", precision, p1, p2)
    exact = p1.astype(np.float64) / tiny + p2.astype(np.float64) / tiny
    assert status[0] == 0
    error = np.abs(p3[0].astype(np.float64) / tiny - exact[0]).max()
    assert error <= 4 * eps * np.abs(exact).max(), (name, p3)
    back, status = call(library, name, "from_quaternion", precision, call(library, name, "to_quaternion",
                                                                          precision, p1)[0])
    assert status[0] == 0
    error = np.abs(back[0].astype(np.float64) / tiny - p1[0] / tiny).max()
    assert error <= 4 * eps * np.abs(p1[0] / tiny).max(), (name, back)


# -- issue 17: statuses agree with the domain; non-rotations refused ------------------------------
def _rz(angle: float, dtype: type) -> np.ndarray:
    c, s = np.cos(dtype(angle)), np.sin(dtype(angle))  # in the format: Rz(π) has sin(π) ≠ 0
    return np.array([c, -s, 0, s, c, 0, 0, 0, 1], dtype=dtype)


@pytest.mark.parametrize("precision", ["double", "float"])
@pytest.mark.parametrize("name", ["cayley_gibbs_rodrigues", "wiener_milenkovic"])
def test_status_agrees_with_the_domain_near_half_turns(library: ctypes.CDLL, name: str, precision: str,
                                                       tmp_path: Path) -> None:
    """e = (e0, 1, 0, 0) with e0 → 0, Rz(π) in the format, compose and rescale of near half turns:
    status 0 exactly when the returned p is accepted by the header's own rotation_matrix (finite R),
    status 1 with NaN otherwise, and NaN rows where the NumPy module is NaN."""
    dtype = DTYPE[precision]
    module = get_module(name, tmp_path)
    e0 = [1e-300, 1e-100, 1e-30, 1e-17, 1e-10, 1e-5, 0.1, 0.0]
    with np.errstate(under="ignore"):
        e = np.array([(v, 1.0, 0.0, 0.0) for v in e0]).astype(dtype)
    results = {"from_quaternion": call(library, name, "from_quaternion", precision, e),
               "from_rotation_matrix": call(library, name, "from_rotation_matrix", precision,
                                            np.stack([_rz(np.pi, dtype), _rz(np.pi - 1e-7, dtype)]))}
    near = np.array([[np.pi - 1e-7, 0, 0], [0, 0, np.pi - 1e-3]])
    turns = np.stack([module.from_quaternion(np.array([np.cos(a / 2), 0, 0, np.sin(a / 2)]))
                      for a in near[:, 0] + near[:, 2]]).astype(dtype)
    results["compose"] = call(library, name, "compose", precision, turns, turns[::-1])
    results["rescale"] = call(library, name, "rescale", precision, turns)
    for function, (got, status) in results.items():
        what = f"{name} {function} ({precision})"
        matrices, _ = call(library, name, "rotation_matrix", precision, np.where(np.isnan(got), 0, got))
        accepted = np.isfinite(matrices).all(-1)
        assert np.array_equal(status == 0, accepted & np.isfinite(got).all(-1)), (what, got, status)
        assert np.isnan(got[status != 0]).all(), what
    got, status = results["from_quaternion"]
    assert np.array_equal(status != 0, np.isnan(module.from_quaternion(e)).any(-1)), (name, precision, got)
    if name == "cayley_gibbs_rodrigues":  # 2/e0 leaves the domain: e0 = 1e-100 (1e-17 in float)
        assert status[1] == 1 and status[3] == (1 if precision == "float" else 0) and status[5] == 0
    else:  # 4 tan(φ/4) → 4: every half turn is inside
        assert not status.any()


NOT_ROTATIONS = {"zeros": np.zeros(9), "ones": np.ones(9), "diag(1,1,-1)": np.diag([1.0, 1.0, -1.0]).ravel(),
                 "-I": -np.eye(3).ravel(), "2 Rz(1)": 2 * _rz(1.0, np.float64),
                 "rank 1": np.outer([0.6, 0.8, 0.0], [0.0, 0.6, 0.8]).ravel(),
                 "e0 e0^T": np.outer([1.0, 0, 0], [1.0, 0, 0]).ravel(),
                 "NaN entry": _rz(0.3, np.float64) + np.where(np.arange(9) == 7, np.nan, 0.0),
                 "inf entry": _rz(0.3, np.float64) + np.where(np.arange(9) == 5, np.inf, 0.0),
                 "1e30 I": 1e30 * np.eye(3).ravel()}


@pytest.mark.parametrize("precision", ["double", "float"])
def test_from_rotation_matrix_refuses_non_rotations(library: ctypes.CDLL, case: tuple[str, ModuleType],
                                                    precision: str) -> None:
    """Status 1 and NaN unless max |RᵀR − I| ≤ tol and det R > 0 (tol = 2^-26, 2^-11 in float);
    rotations perturbed by up to tol/8 per entry are accepted, scaled by 1 + 4 tol refused."""
    from symrot.plan.quaternion import ROTATION_TOLERANCE_POWER

    name, module = case
    dtype = DTYPE[precision]
    tol = 2.0 ** ROTATION_TOLERANCE_POWER["float64" if precision == "double" else "float32"]
    refused = np.stack([*NOT_ROTATIONS.values(), (1 + 4 * tol) * _rz(1.0, np.float64),
                        _rz(1.0, np.float64) + 4 * tol * (np.arange(9) == 1)])
    with np.errstate(over="ignore"):
        refused = refused.astype(dtype)
    got, status = call(library, name, "from_rotation_matrix", precision, refused)
    assert (status == 1).all() and np.isnan(got).all(), (name, precision, status)
    with np.errstate(invalid="ignore", over="ignore"):
        assert np.isnan(module.from_rotation_matrix(refused.reshape(-1, 3, 3))).all(), name
    rng = np.random.default_rng(5)
    angles = rng.uniform(-1.5, 1.5, 30)
    perturbed = np.stack([_rz(a, np.float64) for a in angles]) + rng.uniform(-tol / 8, tol / 8, (30, 9))
    perturbed = perturbed.astype(dtype)
    got, status = call(library, name, "from_rotation_matrix", precision, perturbed)
    expected = module.from_rotation_matrix(perturbed.reshape(-1, 3, 3))
    assert not status.any() and np.isfinite(expected).all(), (name, precision, status)
    # C and NumPy within 4 ε (1 + |p|max) (was 16): measured 1.6 (det_h_one double)
    scale = 4 * float(np.finfo(dtype).eps) * (1 + np.abs(expected.astype(np.float64)).max())
    assert np.abs(got.astype(np.float64) - expected).max() <= scale, (name, precision)
