"""C derivatives of issue 19 (symrot/backends/c_derivatives.py), called through ctypes.

The generated headers of the seven named parameterizations (closed inverse, Newton angle, the fold complement
of the sine family) are compiled in one translation unit with the strict flags of
tests/c_harness.py (gcc, -std=c99 -Wall -Wextra -Wpedantic -Wdouble-promotion -Wconversion -Wshadow
-Werror; clang as well when installed) and compared with:

* the independent 150-digit reference of tests/reference.py on a φ sweep (p = 0, 1e-300 … φ_max −
  10⁻⁶): every derivative within 8 ulp of the reference matrix's largest entry, double and float;
* the NumPy modules (tested against the same reference in tests/test_derivatives.py) on random
  batches, for α and the Jacobians of compose and rescale, with the same NaN and status.

Two user functions of tests/corpus.py (CORPUS_HEADERS) are emitted through the public API, compiled with
gcc -O2 -ffp-contract=off and held to the same reference target, α included (the whole corpus:
``bench/accuracy_derivatives.py --corpus --c``, docs/accuracy_derivatives_corpus_c.md).
"""

from __future__ import annotations

import ctypes
import shutil
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import mpmath
import numpy as np
import pytest

from symrot.api import derive
from symrot.backends.c_backend import header_source
from symrot.plan.builder import evaluation_plan

from . import c_harness
from .corpus import by_expression
from .reference import GeneratingFunction, Reference
from .test_derivatives import (
    FUNCTIONS,
    _as_array,
    _function,
    _ulp,
    acceleration_condition,
    module_of,
    radial_condition,
    sweep,
)

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


def wrappers(names: Sequence[str] = NAMES) -> str:
    """t_NAME_FUNC[_f](n, in0, in1, in2, out0, out1, status): one exported loop per function of the
    headers symrot_NAME.h of ``names``."""
    lines = ["#include <stddef.h>", *(f'#include "symrot_{n}.h"' for n in names)]
    for name in names:
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


def build(config: c_harness.BuildConfig, work: Path, names: Sequence[str] = NAMES,
          include: Path = GENERATED) -> ctypes.CDLL:
    """The wrappers of ``names`` (headers in ``include``) compiled into ``work`` with ``config``
    (tests/c_harness.py) and loaded."""
    source = work / "derivatives.c"
    source.write_text(wrappers(names), encoding="utf-8")
    return ctypes.CDLL(str(c_harness.compile_one(config, source, include, work, timeout=600)))


def _build(compiler: str, work: Path) -> ctypes.CDLL:
    config = c_harness.BuildConfig(f"derivatives_{compiler}", compiler, (*c_harness.STRICT_C, "-O2"))
    return build(config, work)


@pytest.fixture(scope="module")
def library(tmp_path_factory: pytest.TempPathFactory) -> ctypes.CDLL:
    return _build("gcc", tmp_path_factory.mktemp("derivatives_c"))


@pytest.mark.skipif(shutil.which("clang") is None, reason="clang not installed")
def test_headers_compile_strictly_with_clang(tmp_path: Path) -> None:
    assert _build("clang", tmp_path)


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
    limits = module_of(name)._DERIVATIVE_X_LIMIT  # the same plan, so the same documented domain
    worst = worst_against_reference(library, name, function, limits, acceleration=False)
    assert not {k: v for k, v in worst.items() if v > 8.0}, worst


def worst_against_reference(library: ctypes.CDLL, name: str, function: GeneratingFunction,
                            limits: dict[str, Any], acceleration: bool) -> dict[tuple[str, str], float]:
    """Worst ulp / max(1, κ) of each (function, precision) of header ``name`` at p = 0, 1e-8, 0.6 φ_max
    and φ_max − 10⁻⁶ (α too when ``acceleration``, κ as in tests/test_derivatives.py); asserts no NaN
    inside the documented domain (|p|² below ``limits``, as ``_DERIVATIVE_X_LIMIT``) and NaN beyond."""
    reference = Reference(function)
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
            if acceleration and not beyond:
                (got,), _ = call(library, name, "angular_acceleration", precision, p, a, a[::-1].copy())
                alpha = np.array([float(v) for v in reference.along(list(p), list(a), list(a[::-1]))[1]])
                assert np.all(np.isfinite(got)), ("angular_acceleration", angle, precision)
                ulp = _ulp(got.reshape(3), alpha, dtype)
                if ulp > 8.0:
                    ulp /= max(1.0, acceleration_condition(reference, p, a, a[::-1].copy(), alpha))
                key = ("angular_acceleration", precision)
                worst[key] = max(worst.get(key, 0.0), ulp)
    return worst


CORPUS_HEADERS = {"corpus_cubic": "phi + phi**3", "corpus_asinh": "asinh(phi)"}
"""Two functions of the user corpus (tests/corpus.py) outside the paper's families: a polynomial and an
inverse hyperbolic p, both unbounded, with the ν edge at 2π and Newton's angle in C (no closed inverse
is planned for them). bench/accuracy_derivatives.py --corpus --c measures the whole corpus."""


@pytest.fixture(scope="module")
def corpus_library(tmp_path_factory: pytest.TempPathFactory) -> tuple[ctypes.CDLL, dict[str, dict[str, Any]]]:
    """The headers of CORPUS_HEADERS emitted through the public API and compiled with gcc -O2
    -ffp-contract=off; (library, {header: the plan's derivative x limits})."""
    work = tmp_path_factory.mktemp("derivatives_c_corpus")
    limits = {}
    for header, expression in CORPUS_HEADERS.items():
        plan = evaluation_plan(derive(expression).derivation, header)
        (work / f"symrot_{header}.h").write_text(header_source(plan, header), encoding="utf-8")
        limits[header] = {label.removeprefix("float"): precision.derivative_x_limit
                          for label, precision in plan.precisions.items()}
    return build(c_harness.build_config("gcc-O2-nofma"), work, tuple(CORPUS_HEADERS), work), limits


@pytest.mark.parametrize("header", CORPUS_HEADERS)
def test_c_derivatives_of_corpus_functions(corpus_library: tuple[ctypes.CDLL, dict[str, dict[str, Any]]],
                                           header: str) -> None:
    """The five derivatives and α of a user function within 8 ulp of the reference (or 8 κ), no NaN
    inside the range, double and float."""
    library, limits = corpus_library
    function = by_expression(CORPUS_HEADERS[header]).generating_function()
    worst = worst_against_reference(library, header, function, limits[header], acceleration=True)
    assert len(worst) == 12, worst
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
