"""Compile generated C headers with a matrix of compilers and flags, and call them from Python.

One translation unit includes every header under test and defines, for each C function and
precision, an exported wrapper with one uniform signature::

    void t_NAME_FUNC[_f][_batch](size_t n, const T *p, const T *v, T *out);

that loops over ``n`` parameter vectors (``v`` is the second vector of ``pdot``/``omega``, ignored
by the others). Built as a shared object, it is called through :mod:`ctypes` with NumPy arrays.
Sanitizer builds (``-fsanitize=address,undefined``) cannot be loaded into a Python that was not
started under the sanitizer runtime, so they are built as an executable instead: its ``main`` reads
the inputs from a file and writes every wrapper's output to stdout, in the order of
:func:`wrapper_names`, and aborts on the first sanitizer report.
"""

from __future__ import annotations

import ctypes
import hashlib
import shutil
import subprocess
from collections.abc import Sequence
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass
from pathlib import Path

import mpmath
import numpy as np
import sympy as sp

from symrot.backends.c_backend import FUNCTIONS, CFunction
from symrot.core.derivation import Derivation
from symrot.core.functions import mpmath_namespace
from symrot.core.parsing import PHI

EMBEDDED_WARNINGS = ("-Wdouble-promotion", "-Wconversion", "-Wshadow")
"""What embedded users add (a silent float → double promotion is a software-emulated double
operation on a single-precision FPU such as Cortex-M4F): the headers compile cleanly with them."""
STRICT_C = ("-std=c99", "-Wall", "-Wextra", "-Wpedantic", *EMBEDDED_WARNINGS, "-Werror")
STRICT_CXX = ("-x", "c++", "-std=c++11", "-Wall", "-Wextra", "-Wpedantic", *EMBEDDED_WARNINGS, "-Werror")
SANITIZE = ("-O0", "-g", "-fsanitize=address,undefined", "-fno-sanitize-recover=all")
CTYPES = {"double": ctypes.c_double, "float": ctypes.c_float}
DTYPES = {"double": np.float64, "float": np.float32}
SUFFIX = {"double": "", "float": "_f"}


@dataclass(frozen=True)
class BuildConfig:
    """One way of compiling the test translation unit."""

    label: str
    compiler: str
    flags: tuple[str, ...]
    executable: bool = False
    """True for sanitizer builds (run as a subprocess), False for a ctypes-loaded shared object."""


def build_configs() -> list[BuildConfig]:
    """gcc and clang × {-O2 with FMA contraction, -O2 -ffp-contract=off, -O0 + ASan/UBSan}, and C++.

    ``-march=native -ffp-contract=fast`` lets the compiler fuse a*b + c wherever it likes (on a
    machine with FMA); ``-ffp-contract=off`` forbids it. Both must meet the same accuracy target.
    """
    configs = []
    for compiler in ("gcc", "clang"):
        configs.append(BuildConfig(f"{compiler}-O2-fma", compiler,
                                   (*STRICT_C, "-O2", "-march=native", "-ffp-contract=fast")))
        configs.append(BuildConfig(f"{compiler}-O2-nofma", compiler,
                                   (*STRICT_C, "-O2", "-ffp-contract=off")))
        configs.append(BuildConfig(f"{compiler}-asan-ubsan", compiler, (*STRICT_C, *SANITIZE), True))
    configs.append(BuildConfig("g++-O2", "g++", (*STRICT_CXX, "-O2")))
    return configs


def build_config(label: str) -> BuildConfig:
    """The configuration of :func:`build_configs` called ``label`` (e.g. ``gcc-O2-nofma``)."""
    return next(c for c in build_configs() if c.label == label)


def missing_compilers() -> list[str]:
    return [name for name in ("gcc", "g++", "clang") if shutil.which(name) is None]


def wrapper_names(headers: Sequence[str], batches: bool = True) -> list[tuple[str, str, CFunction, bool]]:
    """(wrapper symbol, precision, function, is_batch) in the driver's output order (without the
    batch kernels' wrappers when not ``batches``)."""
    names = []
    for header in headers:
        for precision in ("double", "float"):
            for function in FUNCTIONS:
                base = f"{header}_{function.name}{SUFFIX[precision]}"
                names.append((f"t_{base}", precision, function, False))
                if batches and function.kind == "matrix":
                    names.append((f"t_{base}_batch", precision, function, True))
    return names


def _call(header: str, function: CFunction, precision: str, batch: bool) -> str:
    target = f"symrot_{header}_{function.name}{SUFFIX[precision]}"
    if batch:
        return f"{target}_batch(n, p, out);"
    step = f"out + {function.width}*i"
    if function.kind == "scalar":
        call = f"out[i] = {target}(p + 3*i);"
    elif function.kind == "vector":
        call = f"{target}(p + 3*i, v + 3*i, {step});"
    else:
        call = f"{target}(p + 3*i, {step});"
    return f"size_t i; for (i = 0; i < n; ++i) {{ {call} }}"


def translation_unit(headers: Sequence[str], batches: bool = True) -> str:
    """The test source: the headers, the wrappers and (under SYMROT_TEST_MAIN) the driver; without
    the batch kernels' wrappers when not ``batches`` (they are most of the compile time)."""
    lines = ["#include <stddef.h>"]
    lines += [f'#include "symrot_{header}.h"' for header in headers]
    lines += ["#ifdef __cplusplus", 'extern "C" {', "#endif"]
    entries = {"double": [], "float": []}
    for symbol, precision, function, batch in wrapper_names(headers, batches):
        header = symbol[2:].split(f"_{function.name}")[0]
        ctype = precision
        lines.append(f"void {symbol}(size_t n, const {ctype} *p, const {ctype} *v, {ctype} *out);")
        lines.append(f"void {symbol}(size_t n, const {ctype} *p, const {ctype} *v, {ctype} *out) "
                     f"{{ (void)v; {_call(header, function, precision, batch)} }}")
        entries[precision].append(f"{{{symbol}, {function.width}}}")
    lines += ["#ifdef __cplusplus", "}", "#endif"]
    lines += [
        "#ifdef SYMROT_TEST_MAIN",
        "#include <stdio.h>",
        "#include <stdlib.h>",
        "typedef void (*double_fn)(size_t, const double *, const double *, double *);",
        "typedef void (*float_fn)(size_t, const float *, const float *, float *);",
        "struct double_entry { double_fn fn; size_t width; };",
        "struct float_entry { float_fn fn; size_t width; };",
        "static const struct double_entry double_table[] = {" + ", ".join(entries["double"]) + "};",
        "static const struct float_entry float_table[] = {" + ", ".join(entries["float"]) + "};",
        _DRIVER_MAIN,
        "#endif",
    ]
    return "\n".join(lines) + "\n"


_DRIVER_MAIN = r"""
/* argv[1]: input file = size_t n, double p[3n], double v[3n], float p[3n], float v[3n].
   stdout: for each table entry in order, its n*width outputs (doubles first, then floats). */
int main(int argc, char **argv) {
    FILE *in; size_t n, k, i;
    double *p, *v, *out; float *pf, *vf, *outf;
    if (argc != 2 || !(in = fopen(argv[1], "rb"))) return 2;
    if (fread(&n, sizeof n, 1, in) != 1) return 3;
    p = (double *)malloc(3 * n * sizeof *p); v = (double *)malloc(3 * n * sizeof *v);
    pf = (float *)malloc(3 * n * sizeof *pf); vf = (float *)malloc(3 * n * sizeof *vf);
    out = (double *)malloc(9 * n * sizeof *out); outf = (float *)malloc(9 * n * sizeof *outf);
    if (fread(p, sizeof *p, 3 * n, in) != 3 * n || fread(v, sizeof *v, 3 * n, in) != 3 * n
        || fread(pf, sizeof *pf, 3 * n, in) != 3 * n || fread(vf, sizeof *vf, 3 * n, in) != 3 * n)
        return 4;
    fclose(in);
    for (k = 0; k < sizeof double_table / sizeof double_table[0]; ++k) {
        /* exact-size buffers so that AddressSanitizer sees any write past the last output */
        double *exact = (double *)malloc(double_table[k].width * n * sizeof *exact);
        double_table[k].fn(n, p, v, exact);
        for (i = 0; i < double_table[k].width * n; ++i) out[i] = exact[i];
        fwrite(out, sizeof *out, double_table[k].width * n, stdout);
        free(exact);
    }
    for (k = 0; k < sizeof float_table / sizeof float_table[0]; ++k) {
        float *exact = (float *)malloc(float_table[k].width * n * sizeof *exact);
        float_table[k].fn(n, pf, vf, exact);
        for (i = 0; i < float_table[k].width * n; ++i) outf[i] = exact[i];
        fwrite(outf, sizeof *outf, float_table[k].width * n, stdout);
        free(exact);
    }
    free(p); free(v); free(pf); free(vf); free(out); free(outf);
    return 0;
}
"""


@dataclass
class Build:
    config: BuildConfig
    path: Path
    headers: tuple[str, ...]

    def load(self) -> Library:
        return Library(ctypes.CDLL(str(self.path)), self.headers)


def compile_one(config: BuildConfig, source: Path, include_dir: Path, out_dir: Path,
                timeout: float = 300) -> Path:
    """Compile ``source`` with ``config`` (at most ``timeout`` seconds); raise with the compiler's
    message on failure."""
    suffix = ".bin" if config.executable else ".so"
    out = out_dir / f"{config.label}{suffix}"
    command = [config.compiler, *config.flags, f"-I{include_dir}", str(source)]
    if config.executable:
        command += ["-DSYMROT_TEST_MAIN", "-o", str(out), "-lm"]
    else:
        command += ["-fPIC", "-shared", "-o", str(out), "-lm"]
    result = subprocess.run(command, capture_output=True, text=True, timeout=timeout, check=False)
    if result.returncode != 0:
        raise AssertionError(f"{config.label} failed:\n$ {' '.join(command)}\n{result.stderr[-6000:]}")
    return out


def compile_all(configs: Sequence[BuildConfig], headers: Sequence[str], include_dir: Path,
                out_dir: Path, jobs: int = 2) -> dict[str, Build]:
    """Build the test translation unit with every config, ``jobs`` compilers at a time."""
    source_text = translation_unit(headers)
    digest = hashlib.sha256(source_text.encode()).hexdigest()[:12]
    source = out_dir / f"symrot_test_{digest}.c"
    source.write_text(source_text, encoding="utf-8")
    with ThreadPoolExecutor(max_workers=jobs) as pool:
        futures = {c.label: pool.submit(compile_one, c, source, include_dir, out_dir) for c in configs}
        paths = {label: future.result() for label, future in futures.items()}
    by_label = {c.label: c for c in configs}
    return {label: Build(by_label[label], path, tuple(headers)) for label, path in paths.items()}


class Library:
    """A loaded shared object: ``call(header, function, precision, p, v, batch)`` → outputs."""

    def __init__(self, dll: ctypes.CDLL, headers: Sequence[str]) -> None:
        self.dll = dll
        self.headers = tuple(headers)

    def call(self, header: str, function: CFunction, precision: str, p: np.ndarray,
             v: np.ndarray | None = None, batch: bool = False) -> np.ndarray:
        dtype = DTYPES[precision]
        p = np.ascontiguousarray(p, dtype=dtype).reshape(-1, 3)
        v = p if v is None else np.ascontiguousarray(v, dtype=dtype).reshape(-1, 3)
        n = len(p)
        out = np.empty((n, function.width), dtype=dtype)
        symbol = f"t_{header}_{function.name}{SUFFIX[precision]}" + ("_batch" if batch else "")
        fn = getattr(self.dll, symbol)
        pointer = ctypes.POINTER(CTYPES[precision])
        fn.argtypes = [ctypes.c_size_t, pointer, pointer, pointer]
        fn.restype = None
        fn(n, p.ctypes.data_as(pointer), v.ctypes.data_as(pointer), out.ctypes.data_as(pointer))
        return out.reshape(function.shape(n))


def run_driver(build: Build, double_inputs: tuple[np.ndarray, np.ndarray],
               float_inputs: tuple[np.ndarray, np.ndarray], work: Path) -> dict[str, np.ndarray]:
    """Run a sanitizer executable on (p, v) pairs of equal length; {wrapper symbol: outputs}."""
    n = len(double_inputs[0])
    assert len(float_inputs[0]) == n
    inputs = work / f"{build.config.label}.in"
    with inputs.open("wb") as handle:
        handle.write(np.array([n], dtype=np.uintp).tobytes())
        for array, dtype in ((double_inputs[0], np.float64), (double_inputs[1], np.float64),
                             (float_inputs[0], np.float32), (float_inputs[1], np.float32)):
            handle.write(np.ascontiguousarray(array, dtype=dtype).reshape(n, 3).tobytes())
    env = {"ASAN_OPTIONS": "detect_leaks=1:abort_on_error=0", "UBSAN_OPTIONS": "print_stacktrace=1",
           "PATH": "/usr/bin:/bin"}
    result = subprocess.run([str(build.path), str(inputs)], capture_output=True, timeout=300,
                            check=False, env=env)
    if result.returncode != 0 or result.stderr:
        raise AssertionError(f"{build.config.label} exited {result.returncode}:\n"
                             f"{result.stderr.decode(errors='replace')[-6000:]}")
    data = memoryview(result.stdout)
    outputs: dict[str, np.ndarray] = {}
    offset = 0
    names = wrapper_names(build.headers)
    for precision in ("double", "float"):
        dtype = np.dtype(DTYPES[precision])
        for symbol, prec, function, _ in names:
            if prec != precision:
                continue
            count = n * function.width
            chunk = np.frombuffer(data[offset: offset + count * dtype.itemsize], dtype=dtype)
            outputs[symbol] = chunk.reshape(function.shape(n))
            offset += count * dtype.itemsize
    if offset != len(data):
        raise AssertionError(f"driver wrote {len(data)} bytes, expected {offset}")
    return outputs


# -- mpmath reference ----------------------------------------------------------------------------
SERIES_BELOW = mpmath.mpf("1e-12")
"""Below this |p| the reference sums the exact series in x (error < |p|^12), above it the closed form."""
SERIES_TERMS = 6
MATRIX_OF = {"pdot": "tangent_inverse", "omega": "tangent"}
TENSOR_OF = {"rotation_matrix": "R", "tangent": "H", "tangent_inverse": "H_inverse",
             "root_matrix": "G", "root_tangent": "K"}


def _mp(number: sp.Expr) -> mpmath.mpf:
    """An exact series coefficient at the working precision (rational, or not: the series engine
    returned an irrational-looking K_2 coefficient for tangent_m5, equal to 1e-16 relative)."""
    if number.is_Rational:
        return mpmath.mpf(int(number.p)) / int(number.q)
    return mpmath.mpf(sp.N(number, mpmath.mp.dps + 10)._to_mpmath(mpmath.mp.prec + 30))


_CROSS_SIGN = ((0, -1, 1), (1, 0, -1), (-1, 1, 0))
"""(p×)_ij = _CROSS_SIGN[i][j] p_k with k = 3 − i − j the third index (i ≠ j)."""


class Reference:
    """High-precision values of every C function at an exact (binary) input p, from the core.

    φ = φ(|p|) is found by bracketed root finding on p(φ) = |p| in [0, φ_max] (or the reverted
    series for tiny |p|); coefficients come from the raw closed forms at ≥ 60 digits, increased
    with the cancellation the closed forms suffer at small φ, or from the exact series in x.
    """

    def __init__(self, derivation: Derivation, phi_max: float) -> None:
        self.derivation = derivation
        self.phi_max = mpmath.mpf(phi_max)
        namespace = [mpmath_namespace(), "mpmath"]
        self.p_of_phi = sp.lambdify(PHI, derivation.p, modules=namespace)
        self.closed = {name: sp.lambdify(PHI, expr, modules=namespace)
                       for name, expr in derivation.coefficient_expressions().items()}
        self.series = {name: derivation.series_in_x(name, SERIES_TERMS) for name in self.closed}
        self.phi_series = derivation.phi_of_p(2 * SERIES_TERMS)
        self._cache: dict[str, dict[str, mpmath.mpf]] = {}
        self._angles: dict[str, mpmath.mpf] = {}

    def _digits(self, s: mpmath.mpf) -> int:
        return 60 + (0 if s >= 1 else int(3 * -mpmath.log10(s)))

    def angle(self, s: mpmath.mpf) -> mpmath.mpf:
        """φ(s), memoized per s (every function of a grid point asks for it)."""
        key = mpmath.nstr(s, 40)
        if key not in self._angles:
            self._angles[key] = self._solve_angle(s)
        return self._angles[key]

    def _solve_angle(self, s: mpmath.mpf) -> mpmath.mpf:
        if s < SERIES_BELOW:
            return mpmath.fsum(_mp(c) * s**k for k, c in enumerate(self.phi_series) if c != 0)
        with mpmath.workdps(self._digits(s)):
            def residual(t: mpmath.mpf) -> mpmath.mpf:
                return self.p_of_phi(t) - s

            try:
                return mpmath.findroot(residual, (mpmath.mpf(0), self.phi_max), solver="illinois")
            except (ValueError, ZeroDivisionError):
                with mpmath.workdps(20):
                    rough = mpmath.findroot(residual, (mpmath.mpf(0), self.phi_max), solver="bisect")
                return mpmath.findroot(residual, rough, solver="secant")

    def coefficients(self, s: mpmath.mpf, names: Sequence[str]) -> dict[str, mpmath.mpf]:
        key = mpmath.nstr(s, 40)
        if key not in self._cache:
            self._cache[key] = self._all_coefficients(s)
        return {n: self._cache[key][n] for n in names}

    def _all_coefficients(self, s: mpmath.mpf) -> dict[str, mpmath.mpf]:
        x = s * s
        if s < SERIES_BELOW:
            return {n: mpmath.fsum(_mp(c) * x**k for k, c in enumerate(self.series[n])) for n in self.closed}
        with mpmath.workdps(self._digits(s)):
            phi = self.angle(s)
            return {n: +self.closed[n](phi) for n in self.closed}

    def evaluate(self, function: CFunction, p: Sequence[float], v: Sequence[float],
                 stretch: mpmath.mpf | int = 1) -> list[mpmath.mpf]:
        """The exact value of ``function`` at the binary inputs p·stretch, v, as a flat list."""
        with mpmath.workdps(60):
            pv = [mpmath.mpf(float(c)) * stretch for c in p]
            s = mpmath.sqrt(mpmath.fsum(c * c for c in pv))
            if function.name == "angle":
                return [self.angle(s)]
            if function.name == "tangent_det":
                return [self.coefficients(s, ["det_H"])["det_H"]]
            tensor = {"pdot": "H_inverse", "omega": "H"}.get(function.name) or TENSOR_OF[function.name]
            a, b, c = (self.coefficients(s, [f"{tensor}_{k}" for k in range(3)])[f"{tensor}_{k}"]
                       for k in range(3))
            # T = a I + b (p×) + c (p×)², (p×)² = p pᵀ − |p|² I, entry by entry (mpmath's matrix
            # products converted each scalar through repr and were a third of the fixture's time)
            x = s * s
            T = [[(a - c * x if i == j else 0) + c * pv[i] * pv[j]
                  + b * _CROSS_SIGN[i][j] * pv[3 - i - j if i != j else 0] for j in range(3)]
                 for i in range(3)]
            if function.kind == "matrix":
                return [T[i][j] for i in range(3) for j in range(3)]
            w = [mpmath.mpf(float(c)) for c in v]
            return [mpmath.fsum(T[i][j] * w[j] for j in range(3)) for i in range(3)]


def ulp_errors(function: CFunction, got: np.ndarray, exact: list[mpmath.mpf], precision: str) -> float:
    """Error in units of ε of the precision: per entry / max(1, ‖ref‖max) for matrices, relative
    for vectors (to the vector's max entry) and scalars. NaN or inf counts as infinite."""
    eps = mpmath.mpf(float(np.finfo(DTYPES[precision]).eps))
    values = np.asarray(got, dtype=np.float64).ravel()
    if not np.all(np.isfinite(values)):
        return float("inf")
    scale = max(abs(e) for e in exact)
    if function.kind == "matrix":
        scale = max(scale, mpmath.mpf(1))
    if scale == 0:
        return 0.0 if np.all(values == 0) else float("inf")
    return float(max(abs(mpmath.mpf(float(g)) - e) for g, e in zip(values, exact, strict=True))
                 / scale / eps)


def condition(reference: Reference, function: CFunction, p: Sequence[float], v: Sequence[float],
              precision: str, exact: list[mpmath.mpf]) -> float:
    """How many ε of output change one ε of relative change of |p| causes (same norm as
    :func:`ulp_errors`). Every evaluation through x = |p|² inherits that much from rounding x, so
    the target is 4 ε · max(1, condition): exactly 4 ε where the problem is well-conditioned,
    and 4 ε times the condition number next to a singularity of the parameterization. For
    pdot = H⁻¹ ω and omega = H pdot it also includes the componentwise condition number of the
    product, max_i Σ_j |T_ij v_j| / max_i |(T v)_i| (terms far larger than the result)."""
    eps = mpmath.mpf(float(np.finfo(DTYPES[precision]).eps))
    if not any(float(c) for c in p):
        return 1.0
    moved = reference.evaluate(function, p, v, 1 - eps)  # inward: stays inside the validity range
    scale = max(abs(e) for e in exact)
    if function.kind == "matrix":
        scale = max(scale, mpmath.mpf(1))
    if scale == 0:
        return 1.0
    stretch = max(abs(a - b) for a, b in zip(moved, exact, strict=True)) / scale / eps
    if function.kind != "vector":
        return float(stretch)
    # T v summed from terms that may be much larger than the result: its componentwise condition
    matrix_function = next(f for f in FUNCTIONS if f.name == MATRIX_OF[function.name])
    entries = reference.evaluate(matrix_function, p, v)
    terms = max(sum(abs(entries[3 * i + j]) * abs(mpmath.mpf(float(v[j]))) for j in range(3))
                for i in range(3))
    return float(max(stretch, terms / scale))
