"""The vectorizable batch kernels of the C backend (symrot.backends.c_batch).

* the branch-free sin/cos kernel (symrot.plan.sincos_kernel), printed exactly as the batch kernels print it,
  is within 1.5 ulp of 50-digit mpmath in double and float, with and without FMA contraction, on
  arguments from 0 and 1e-300 up to far beyond the 3π/2 the headers need, and right next to
  multiples of π/2 where the reduction cancels;
* every coefficient loop of every generated header is vectorized by gcc and by clang at -O2
  (AVX2), which is what the kernels are written for;
* the block size is a compile-time option that does not change the results.
(Accuracy of the kernels' outputs against mpmath, sanitizer runs and agreement with the single
calls are in test_c_backend.py.)
"""

from __future__ import annotations

import ctypes
import itertools
import platform
import re
import subprocess
from pathlib import Path

import mpmath
import numpy as np
import pytest

from symrot.api import derive
from symrot.backends.c_backend import COVERED, FUNCTIONS, FunctionWriter, plan_for
from symrot.backends.c_batch import BatchWriter
from symrot.backends.c_printer import Precision
from symrot.backends.templating import environment

from . import c_harness
from .test_c_backend import GENERATED, limits

CANDIDATES = "/* every candidate value, unconditionally */"
COEFFICIENT_LOOP = "for (k = 0; k < SYMROT_BATCH_BLOCK; ++k)"
SINCOS_KERNEL = re.compile(r"\ba\d+_q = ")
"""The kernel's quadrant q (symrot.backends.c_sincos), in the loops that compute sin/cos inline."""
KERNEL_ULP = 1.5
"""Measured: 1.28 ulp in double, 1.41 in float (libm: about 0.5). The reduced argument r is
rounded once (0.5 ulp of r carried into sin r), and 1 + z·Q(z) adds the rounding of z = r²."""


def kernel_source(precision: Precision) -> str:
    """A C function evaluating the kernel on n arguments, from the statements the headers print."""
    # the kernel does not depend on the plan; any plan gives a writer for the precision
    writer = FunctionWriter(plan_for(derive("rotation_vector").derivation, "rotation_vector"), "t", precision)
    statements = BatchWriter(writer).sincos.kernel_statements("a[k]", 0, {"sin0", "cos0"})
    body = environment().get_template("c/statements.j2").module.block(statements, "        ")  # type: ignore[attr-defined]
    t = precision
    nearest = environment().get_template("c/nearest.h.j2").render()
    return (f"#include <float.h>\n#include <math.h>\n#include <stddef.h>\n{nearest}\n"
            f"void kernel_{t}(size_t n, const {t} *a, {t} *s, {t} *c) {{\n"
            f"    size_t k;\n    for (k = 0; k < n; ++k) {{\n{body}"
            f"        s[k] = sin0;\n        c[k] = cos0;\n    }}\n}}\n")


@pytest.fixture(scope="module")
def kernels(tmp_path_factory: pytest.TempPathFactory) -> dict[str, ctypes.CDLL]:
    work = tmp_path_factory.mktemp("sincos")
    source = work / "kernel.c"
    source.write_text(kernel_source("double") + kernel_source("float"), encoding="utf-8")
    libraries = {}
    for label, flags in (("fma", ("-march=native", "-ffp-contract=fast")), ("nofma", ("-ffp-contract=off",))):
        out = work / f"kernel_{label}.so"
        subprocess.run(["gcc", *c_harness.STRICT_C, "-O2", *flags, "-shared", "-fPIC", str(source), "-o",
                        str(out), "-lm"], check=True, capture_output=True, timeout=120)
        libraries[label] = ctypes.CDLL(str(out))
    return libraries


def arguments(dtype: type) -> np.ndarray:
    """0, tiny, log-spaced and uniform arguments, and the neighbours of k π/2 (k ≤ 64)."""
    tiny = 1e-300 if dtype == np.float64 else 1e-38
    rng = np.random.default_rng(3)
    values = [np.array([0.0, tiny]), np.geomspace(tiny, 1.0, 400), rng.uniform(0, 100, 4000)]
    for k in range(1, 65):
        centre = dtype(k * np.pi / 2)
        below = np.nextafter(centre, dtype(0))
        above = np.nextafter(centre, dtype(np.inf))
        values.append(np.array([centre, below, above, np.nextafter(below, dtype(0)),
                                np.nextafter(above, dtype(np.inf))], dtype=dtype))
    return np.concatenate([np.asarray(v, dtype=dtype) for v in values])


def ulp_error(got: float, exact: mpmath.mpf, dtype: type) -> float:
    """|got − exact| in units of the last place of exact in the format (subnormal-aware)."""
    info = np.finfo(dtype)
    exponent = max(int(mpmath.floor(mpmath.log(abs(exact), 2))) if exact != 0 else info.minexp, info.minexp)
    ulp = mpmath.ldexp(1, exponent - info.nmant)
    return float(abs(mpmath.mpf(float(got)) - exact) / ulp)


@pytest.mark.parametrize("label", ["fma", "nofma"])
@pytest.mark.parametrize("precision, dtype", [("double", np.float64), ("float", np.float32)])
def test_sincos_kernel_is_within_one_and_a_half_ulp(label: str, precision: str, dtype: type,
                                         kernels: dict[str, ctypes.CDLL]) -> None:
    a = arguments(dtype)
    sine, cosine = np.empty_like(a), np.empty_like(a)
    pointer = ctypes.POINTER(c_harness.CTYPES[precision])
    function = getattr(kernels[label], f"kernel_{precision}")
    function.restype = None
    function(ctypes.c_size_t(len(a)), a.ctypes.data_as(pointer), sine.ctypes.data_as(pointer),
             cosine.ctypes.data_as(pointer))
    worst = (0.0, 0.0)
    with mpmath.workdps(50):
        for value, s, c in zip(a, sine, cosine, strict=True):
            exact = mpmath.mpf(float(value))
            errors = (ulp_error(s, mpmath.sin(exact), dtype), ulp_error(c, mpmath.cos(exact), dtype))
            worst = (max(worst[0], errors[0]), max(worst[1], errors[1]))
    assert max(worst) <= KERNEL_ULP, (precision, label, worst)
    assert min(worst) > 0  # the sweep does reach rounding errors


def vectorized_lines(compiler: str, source: Path, work: Path,
                     target: tuple[str, ...] = ("-mavx2", "-mfma")) -> set[tuple[str, int]]:
    """(header, line) of every loop the compiler reports as vectorized at -O2 and ``target``."""
    flags = [*c_harness.STRICT_C, "-O2", *target, f"-I{GENERATED}", "-c", str(source),
             "-o", str(work / f"{compiler}.o")]
    report = ["-fopt-info-vec-optimized"] if compiler == "gcc" else ["-Rpass=loop-vectorize"]
    result = subprocess.run([compiler, *flags, *report], capture_output=True, text=True, timeout=600,
                            check=False)
    assert result.returncode == 0, result.stderr[-4000:]
    pattern = re.compile(r"symrot_(\w+)\.h:(\d+):\d+: (?:optimized: loop vectorized|remark: vectorized loop)")
    return {(m.group(1), int(m.group(2))) for m in map(pattern.search, result.stderr.splitlines()) if m}


@pytest.mark.parametrize("compiler", ["gcc", "clang"])
def test_every_coefficient_loop_is_vectorized(compiler: str, tmp_path: Path) -> None:
    """Both coefficient loops of every batch kernel (the candidates and the select), in one
    translation unit with all headers and every kernel called (as a user's would be)."""
    source = tmp_path / "all.c"
    source.write_text(c_harness.translation_unit(COVERED), encoding="utf-8")
    vectorized = vectorized_lines(compiler, source, tmp_path)
    expected, missing = 0, []
    for name in COVERED:
        lines = (GENERATED / f"symrot_{name}.h").read_text(encoding="utf-8").splitlines()
        for number, line in enumerate(lines, start=1):
            if COEFFICIENT_LOOP in line:
                expected += 1
                if (name, number) not in vectorized:
                    missing.append((name, number))
    matrix_functions = sum(f.kind == "matrix" for f in FUNCTIONS)
    kernels = len(COVERED) * matrix_functions * 2  # double and float
    # a select loop per kernel, and a candidate loop unless every coefficient is a constant (CGR's H^-1)
    candidates = sum((GENERATED / f"symrot_{name}.h").read_text(encoding="utf-8").count(CANDIDATES)
                     for name in COVERED)
    assert kernels - 4 <= candidates <= kernels
    assert expected == kernels + candidates
    assert not missing, f"{compiler}: coefficient loops not vectorized (header, line): {missing}"


@pytest.mark.skipif(platform.machine() not in ("x86_64", "AMD64"), reason="baseline x86-64 SSE2 codegen")
def test_sin_cos_loops_are_vectorized_at_baseline_x86_64(tmp_path: Path) -> None:
    """gcc -O2 without -m flags (SSE2, no FMA, no SSE4.1 roundsd): every candidate loop that holds
    the sin/cos kernel is vectorized. It was not while the kernel rounded with rint(), which gcc
    writes there as a compare-and-branch sequence; the header's SYMROT_NEAREST adds and subtracts
    1.5·2^52 instead (issue 21: the rotation vector's batch was 2.2× SciPy at baseline x86-64)."""
    source = tmp_path / "all.c"
    source.write_text(c_harness.translation_unit(COVERED), encoding="utf-8")
    vectorized = vectorized_lines("gcc", source, tmp_path, target=())
    kernel_loops, missing = 0, []
    for name in COVERED:
        lines = (GENERATED / f"symrot_{name}.h").read_text(encoding="utf-8").splitlines()
        for number, line in enumerate(lines, start=1):
            if COEFFICIENT_LOOP in line and lines[number - 2].strip() == CANDIDATES:
                body = "\n".join(itertools.takewhile(lambda text: COEFFICIENT_LOOP not in text,
                                                     lines[number:]))
                if SINCOS_KERNEL.search(body):
                    kernel_loops += 1
                    if (name, number) not in vectorized:
                        missing.append((name, number))
    assert kernel_loops >= 4 * sum(f.kind == "matrix" for f in FUNCTIONS)  # several headers, both precisions
    assert not missing, f"sin/cos loops not vectorized at baseline x86-64 (header, line): {missing}"


def assert_batch_bits_agree(names: list[str], builds: tuple[list[str], list[str]],
                            inputs: dict[str, np.ndarray], work: Path) -> None:
    """Every batch kernel of the headers ``names`` (both precisions) gives the same bits on
    ``inputs[name]`` when the translation unit is compiled with either list of gcc flags (every
    NaN counted as one value)."""
    source = work / "kernels.c"
    source.write_text(c_harness.translation_unit(names), encoding="utf-8")
    libraries = []
    for index, flags in enumerate(builds):
        out = work / f"kernels_{index}.so"
        subprocess.run(["gcc", *c_harness.STRICT_C, "-O2", *flags, f"-I{GENERATED}", "-shared", "-fPIC",
                        str(source), "-o", str(out), "-lm"], check=True, capture_output=True, timeout=300)
        libraries.append(c_harness.Library(ctypes.CDLL(str(out)), names))
    for name in names:
        for function in FUNCTIONS:
            if function.kind != "matrix":
                continue
            for precision in ("double", "float"):
                first, second = (library.call(name, function, precision, inputs[name], batch=True)
                                 for library in libraries)
                assert _bits(first) == _bits(second), (name, function.name, precision)


def _bits(values: np.ndarray) -> bytes:
    """The bytes of ``values`` with every NaN made one NaN: C leaves the sign and payload of a NaN
    an operation returns to the instructions the compiler chose (vector or scalar)."""
    canonical = values.copy()
    canonical[np.isnan(canonical)] = np.nan
    return canonical.tobytes()


def test_the_rounding_macro_gives_the_bits_of_rint(tmp_path: Path) -> None:
    """The batch kernels built with the header's SYMROT_NEAREST (1.5·2^52 added and subtracted)
    and with rint/rintf put in its place give the same bits, on angles across the whole range."""
    # the kernel is the same text in every header; these four give it arguments c·φ over ranges of
    # several quadrants (a closed angle, a Newton angle, the sine and the tangent family)
    names = ["rotation_vector", "det_h_one", "sine_m5", "tangent_m5"]
    for name in names:
        assert "SYMROT_NEAREST(" in (GENERATED / f"symrot_{name}.h").read_text(encoding="utf-8"), name
    rng = np.random.default_rng(21)
    directions = rng.normal(size=(2000, 3))
    directions /= np.linalg.norm(directions, axis=1, keepdims=True)
    inputs = {}
    for name in names:
        p_max = float(limits(name).p_max_float)
        top = p_max if np.isfinite(p_max) else 1e3
        magnitudes = np.concatenate([rng.uniform(0, top, 1500), top * (1 - np.geomspace(1e-1, 1e-9, 500))])
        inputs[name] = directions * magnitudes[:, None]
    assert_batch_bits_agree(names, ([], ["-DSYMROT_NEAREST(y)=rint(y)", "-DSYMROT_NEARESTF(y)=rintf(y)"]),
                            inputs, tmp_path)


def test_the_block_size_is_a_compile_time_option_that_does_not_change_results(tmp_path: Path) -> None:
    """-DSYMROT_BATCH_BLOCK=3 (scalar-sized blocks) and the default 32 give the same bits
    (without FMA contraction, which the compiler may apply differently to vector and scalar code)."""
    names = ["rotation_vector", "det_h_one", "tangent_m5", "sine_m3"]
    rng = np.random.default_rng(11)
    p = rng.normal(size=(77, 3)) * rng.uniform(0, 2, size=(77, 1))
    flags = ["-mavx2", "-ffp-contract=off"]
    assert_batch_bits_agree(names, (flags, [*flags, "-DSYMROT_BATCH_BLOCK=3"]), dict.fromkeys(names, p),
                            tmp_path)
