"""C derivatives of issue 19 (symrot/backends/c_derivatives.py), called through ctypes.

The generated headers of the seven named parameterizations (closed inverse, Newton angle, the fold complement
of the sine family) are compiled in one translation unit with the strict flags of
tests/c_harness.py (gcc, -std=c99 -Wall -Wextra -Wpedantic -Wdouble-promotion -Wconversion -Wshadow
-Werror; clang as well when installed) and compared with:

* the independent 150-digit reference of tests/reference.py on a φ sweep (p = 0, 1e-300 … φ_max −
  10⁻⁶): every derivative within 8 ulp of the reference matrix's largest entry, double and float;
* the NumPy modules (tested against the same reference in tests/test_derivatives.py) on random
  batches, for α and the Jacobians of compose and rescale, with the same NaN and status.
"""

from __future__ import annotations

import ctypes
import shutil
import subprocess
from pathlib import Path

import mpmath
import numpy as np
import pytest

from . import c_harness
from .reference import Reference
from .test_derivatives import FUNCTIONS, _as_array, _function, _ulp, module_of, radial_condition, sweep

ROOT = Path(__file__).resolve().parent.parent
GENERATED = ROOT / "generated" / "c"
NAMES = ("rotation_vector", "wiener_milenkovic", "euler_rodrigues", "det_h_one", "cayley_gibbs_rodrigues",
         "linear", "sine_m4")
CTYPE = {"double": "double", "float": "float"}
DTYPE = {"double": np.float64, "float": np.float32}
SUFFIX = {"double": "", "float": "_f"}
# function → (input widths, output widths, returns a status)
SIGNATURES = {**{f: ((3, 3), (9,), False) for f in FUNCTIONS},
              "angular_acceleration": ((3, 3, 3), (3,), False),
              "compose_jacobians": ((3, 3), (9, 9), True), "rescale_jacobian": ((3,), (9,), True)}

pytestmark = pytest.mark.skipif(shutil.which("gcc") is None, reason="gcc not installed")


def wrappers() -> str:
    """t_NAME_FUNC[_f](n, in0, in1, in2, out0, out1, status): one exported loop per function."""
    lines = ["#include <stddef.h>", *(f'#include "symrot_{n}.h"' for n in NAMES)]
    for name in NAMES:
        for precision, t in CTYPE.items():
            for function, (inputs, outputs, has_status) in SIGNATURES.items():
                arguments = [f"in{j} + {w}*i" for j, w in enumerate(inputs)]
                arguments += [f"out{j} + {w}*i" for j, w in enumerate(outputs)]
                call = f"symrot_{name}_{function}{SUFFIX[precision]}({', '.join(arguments)})"
                body = f"status[i] = {call};" if has_status else f"{call}; status[i] = 0;"
                signature = (f"void t_{name}_{function}{SUFFIX[precision]}(size_t n, const {t} *in0, "
                             f"const {t} *in1, const {t} *in2, {t} *out0, {t} *out1, int *status)")
                lines.append(signature + ";")
                lines.append(signature + " { size_t i; (void)in1; (void)in2; (void)out1; "
                             f"for (i = 0; i < n; ++i) {{ {body} }} }}")
    return "\n".join(lines) + "\n"


def _build(compiler: str, work: Path) -> Path:
    source = work / "derivatives.c"
    source.write_text(wrappers(), encoding="utf-8")
    out = work / f"derivatives_{compiler}.so"
    command = [compiler, *c_harness.STRICT_C, "-O2", "-fPIC", "-shared", f"-I{GENERATED}", str(source),
               "-o", str(out), "-lm"]
    result = subprocess.run(command, capture_output=True, text=True, timeout=600, check=False)
    assert result.returncode == 0, f"$ {' '.join(command)}\n{result.stderr[-6000:]}"
    return out


@pytest.fixture(scope="module")
def library(tmp_path_factory: pytest.TempPathFactory) -> ctypes.CDLL:
    return ctypes.CDLL(str(_build("gcc", tmp_path_factory.mktemp("derivatives_c"))))


@pytest.mark.skipif(shutil.which("clang") is None, reason="clang not installed")
def test_headers_compile_strictly_with_clang(tmp_path: Path) -> None:
    assert _build("clang", tmp_path).exists()


def call(library: ctypes.CDLL, name: str, function: str, precision: str,
         *inputs: np.ndarray) -> tuple[list[np.ndarray], np.ndarray]:
    """(outputs, each (n, width), status (n,)) of the C function on n rows of ``inputs``."""
    widths, out_widths, _ = SIGNATURES[function]
    dtype = DTYPE[precision]
    arrays = [np.ascontiguousarray(a, dtype=dtype).reshape(-1, w)
              for a, w in zip(inputs, widths, strict=True)]
    n = len(arrays[0])
    arrays += [arrays[0]] * (3 - len(arrays))
    outs = [np.full((n, w), -7.0, dtype=dtype) for w in out_widths]
    outs += [outs[0]] * (2 - len(outs))
    status = np.full(n, -7, dtype=np.intc)
    pointer = ctypes.POINTER(ctypes.c_double if precision == "double" else ctypes.c_float)
    fn = getattr(library, f"t_{name}_{function}{SUFFIX[precision]}")
    fn.argtypes = [ctypes.c_size_t, pointer, pointer, pointer, pointer, pointer, ctypes.POINTER(ctypes.c_int)]
    fn.restype = None
    fn(n, *(a.ctypes.data_as(pointer) for a in arrays), *(o.ctypes.data_as(pointer) for o in outs),
       status.ctypes.data_as(ctypes.POINTER(ctypes.c_int)))
    return outs[:len(out_widths)], status


@pytest.mark.parametrize("name", NAMES)
def test_c_derivatives_within_8_ulp_of_the_reference(library: ctypes.CDLL, name: str) -> None:
    """Within 8 ulp of the reference matrix's largest entry, or 8 κ next to a singular edge."""
    function, _ = _function(name)
    reference = Reference(function)
    limits = module_of(name)._DERIVATIVE_X_LIMIT  # the same plan, so the same documented domain
    rng = np.random.default_rng(23)
    p_max = float(function.p_max())
    worst: dict[tuple[str, str], float] = {}
    angles = sweep(float(function.phi_max))
    for angle in [*angles[::2], angles[-1]]:
        axis = rng.normal(size=3)
        axis /= np.linalg.norm(axis)
        a = rng.normal(size=3).astype(np.float32).astype(np.float64)
        with mpmath.workdps(40):
            size = float(function.value(mpmath.mpf(angle)))
        for precision, dtype in DTYPE.items():
            p = (size * axis).astype(dtype).astype(np.float64)
            if float(np.linalg.norm(p)) >= p_max * (1 - 4e-7) or (angle > 0 and not np.any(p)):
                continue
            beyond = float(p @ p) >= float(limits["64" if dtype is np.float64 else "32"])
            for f, tensor in FUNCTIONS.items():
                (got,), _ = call(library, name, f, precision, p, a)
                if beyond:  # beyond the documented domain of unbounded p (x_limit): NaN by design
                    assert np.all(np.isnan(got)), (f, angle, precision)
                    continue
                expected = _as_array(reference.derivative(list(p), list(a), tensor))
                assert np.all(np.isfinite(got)), (f, angle, precision)
                ulp = _ulp(got.reshape(3, 3), expected, dtype)
                if ulp > 8.0:  # next to a singular edge: within 8 κ (tests/test_derivatives.py)
                    ulp /= max(1.0, radial_condition(reference, p, a, tensor, expected))
                worst[(f, precision)] = max(worst.get((f, precision), 0.0), ulp)
    assert not {k: v for k, v in worst.items() if v > 8.0}, worst


@pytest.mark.parametrize("name", NAMES)
@pytest.mark.parametrize("precision", ["double", "float"])
def test_c_agrees_with_numpy(library: ctypes.CDLL, name: str, precision: str) -> None:
    """Derivatives, α and the Jacobians of compose and rescale against the NumPy module on a random
    batch with |φ| ≤ min(φ_max, 2π)/2, p = 0 and a p far outside the range (NaN and status where
    NumPy is NaN). Nearer the edge both are ill-conditioned (C and NumPy compute φ with different
    libraries), and each is checked against the reference with its condition number instead."""
    module = module_of(name)
    dtype = DTYPE[precision]
    rng = np.random.default_rng(31)
    function, _ = _function(name)
    top = min(float(function.phi_max), 2 * np.pi) * 0.5
    with mpmath.workdps(30):
        sizes = [float(function.value(mpmath.mpf(t))) for t in rng.uniform(0, top, 40)]
    axes = rng.normal(size=(40, 3))
    p = (axes / np.linalg.norm(axes, axis=1)[:, None] * np.array(sizes)[:, None]).astype(dtype)
    p[0] = 0
    p[1] = np.array([1e300, 0, 0]).astype(dtype) if dtype is np.float64 else np.array([1e30, 0, 0], dtype)
    q, v, w = (rng.normal(size=(40, 3)).astype(dtype) for _ in range(3))
    tolerance = 32 * float(np.finfo(dtype).eps)  # two implementations, each within 8 ulp of the
    # reference where κ ≤ 1, with different libm calls and branch switches (C: the plan's threshold)
    cases = {f: ((p, v), [getattr(module, f)(p, v).reshape(-1, 9)]) for f in FUNCTIONS}
    cases["angular_acceleration"] = ((p, v, w), [module.angular_acceleration(p, v, w)])
    jacobians = module.compose_jacobians(p, q * 0.1)
    cases["compose_jacobians"] = ((p, q * 0.1), [j.reshape(-1, 9) for j in jacobians])
    cases["rescale_jacobian"] = ((p,), [module.rescale_jacobian(p).reshape(-1, 9)])
    for f, (inputs, expected) in cases.items():
        outs, status = call(library, name, f, precision, *inputs)
        for got, want in zip(outs, expected, strict=True):
            nan = np.isnan(want).any(axis=1)
            assert np.array_equal(np.isnan(got).any(axis=1), nan), f
            scale = np.max(np.abs(np.where(nan[:, None], 0, want)), axis=1, keepdims=True)
            if f == "angular_acceleration":  # α = H p̈ + Ḣ ṗ may cancel: errors scale with H p̈
                scale = np.maximum(scale, np.max(np.abs(inputs[2]), axis=1, keepdims=True))
            error = np.abs(np.where(nan[:, None], 0, got.astype(np.float64) - want))
            assert np.all(error <= tolerance * np.maximum(scale, 1e-300)), f
            if SIGNATURES[f][2]:
                assert np.array_equal(status != 0, nan), f
