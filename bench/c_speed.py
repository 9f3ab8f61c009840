"""Speed of the generated C headers against a textbook C implementation and installable peers.

Measured in one run, side by side, on the same random parameter vectors:

* ns per call (C loop over a pool of 4096 vectors, every function inlined where the compiler
  chooses, the same flags for everyone): generated C (double and float), the textbook C of
  ``bench/c/textbook.c``, SymForce's generated ``Rot3.from_tangent(v).to_rotation_matrix()`` (C++,
  Eigen) and Eigen's ``AngleAxisd::toRotationMatrix`` for the rotation vector;
* batch throughput over 10⁶ rotations called from NumPy: the generated ``_batch`` kernel through
  ctypes, the textbook loop, and scipy's ``Rotation.from_rotvec`` / ``from_mrp`` + ``as_matrix``.

SymForce pins its own tool versions, so it is looked for in the Python named by
``$SYMROT_SYMFORCE_PYTHON`` (default: this one); set up with
``make setup-bench`` (a venv in /tmp/symforce_venv).

Run: ``python bench/c_speed.py`` (writes the "C backend" section of docs/performance.md).
"""

from __future__ import annotations

import argparse
import ctypes
import os
import platform
import subprocess
import sys
import tempfile
import time
from collections.abc import Callable
from pathlib import Path

import mpmath
import numpy as np
import sympy as sp

from symrot.api import derive
from symrot.functions import mpmath_namespace
from symrot.parsing import PHI

ROOT = Path(__file__).resolve().parent.parent
HEADERS = ROOT / "generated" / "c"
TEXTBOOK = ROOT / "bench" / "c" / "textbook.c"
DOC = ROOT / "docs" / "performance.md"
SECTION = "## C backend"
FLAGS = ("-O2", "-march=native")
POOL = 4096
BATCH = 1_000_000
PARAMETERIZATIONS = (
    "rotation_vector", "cayley_gibbs_rodrigues", "wiener_milenkovic", "linear", "euler_rodrigues",
    "sine_m4", "det_h_one",
)
ANGLE_LIMIT = {"linear": 1.5, "cayley_gibbs_rodrigues": 3.0}
"""Largest |φ| drawn for the random inputs (elsewhere 3.1 < π, inside every validity range)."""
FUNCTIONS = {
    "angle": "scalar", "rotation_matrix": "matrix", "tangent": "matrix", "tangent_inverse": "matrix",
    "tangent_det": "scalar", "root_matrix": "matrix", "root_tangent": "matrix", "pdot": "vector",
    "omega": "vector",
}
WIDTH = {"scalar": 1, "vector": 3, "matrix": 9}

LOOP = r"""
double %(symbol)s(size_t reps, size_t n, const %(T)s *pool, const %(T)s *vpool, double *sink) {
    %(T)s out[9] = {0}; double acc = 0.0; size_t r, i; struct timespec t0, t1;
    (void)vpool;
    clock_gettime(CLOCK_MONOTONIC, &t0);
    for (r = 0; r < reps; ++r) {
        for (i = 0; i < n; ++i) {
            size_t k; double sum = 0.0;
            %(call)s;
            /* every output is used, summed as the peers' R.sum() is: one add per call on acc */
            for (k = 0; k < %(width)d; ++k) sum += (double)out[k];
            acc += sum;
        }
    }
    clock_gettime(CLOCK_MONOTONIC, &t1);
    *sink += acc;
    return ((t1.tv_sec - t0.tv_sec) * 1e9 + (t1.tv_nsec - t0.tv_nsec)) / (double)(reps * n);
}
"""


def _call(target: str, kind: str) -> str:
    if kind == "scalar":
        return f"out[0] = {target}(pool + 3*i)"
    if kind == "vector":
        return f"{target}(pool + 3*i, vpool + 3*i, out)"
    return f"{target}(pool + 3*i, out)"


def c_source(names: list[str]) -> tuple[str, list[tuple[str, str, str, str]]]:
    """The C benchmark translation unit and its timers (symbol, parameterization, label, precision)."""
    lines = ["#define _POSIX_C_SOURCE 199309L", "#include <time.h>", "#include <stddef.h>",
             f'#include "{TEXTBOOK}"']
    lines += [f'#include "symrot_{name}.h"' for name in names]
    timers = []
    for name in names:
        for function, kind in FUNCTIONS.items():
            for precision, suffix, ctype in (("double", "", "double"), ("float", "_f", "float")):
                symbol = f"time_generated_{name}_{function}{suffix}"
                call = _call(f"symrot_{name}_{function}{suffix}", kind)
                lines.append(LOOP % {"symbol": symbol, "T": ctype, "call": call,
                                     "width": WIDTH[kind]})
                timers.append((symbol, name, f"generated {function}", precision))
            if kind == "matrix":
                for ctype, suffix in (("double", ""), ("float", "_f")):
                    lines.append(f"void batch_{name}_{function}{suffix}(size_t n, const {ctype} *p, "
                                 f"{ctype} *out) {{ symrot_{name}_{function}{suffix}_batch(n, p, out); }}")
        symbol = f"time_textbook_{name}_rotation_matrix"
        lines.append(LOOP % {"symbol": symbol, "T": "double", "width": 9,
                             "call": _call(f"textbook_{name}_rotation_matrix", "matrix")})
        timers.append((symbol, name, "textbook rotation_matrix", "double"))
        lines.append(f"void batch_textbook_{name}(size_t n, const double *p, double *out) "
                     f"{{ size_t i; for (i = 0; i < n; ++i) "
                     f"textbook_{name}_rotation_matrix(p + 3*i, out + 9*i); }}")
    return "\n".join(lines) + "\n", timers


PEER_SOURCE = r"""
#include <time.h>
#include <cmath>
#include <cstddef>
#include <limits>
#include <Eigen/Geometry>
%(symforce_include)s

#define PEER_TIMER(symbol, body) \
extern "C" double symbol(size_t reps, size_t n, const double *pool, const double *vpool, double *sink) { \
    double acc = 0.0; struct timespec t0, t1; (void)vpool; \
    clock_gettime(CLOCK_MONOTONIC, &t0); \
    for (size_t r = 0; r < reps; ++r) for (size_t i = 0; i < n; ++i) { \
        const double *p = pool + 3 * i; body; acc += R.sum(); } \
    clock_gettime(CLOCK_MONOTONIC, &t1); *sink += acc; \
    return ((t1.tv_sec - t0.tv_sec) * 1e9 + (t1.tv_nsec - t0.tv_nsec)) / double(reps * n); }

PEER_TIMER(time_eigen_rotation_vector, \
    Eigen::Vector3d v(p[0], p[1], p[2]); const double angle = v.norm(); \
    Eigen::Matrix3d R = angle > 0.0 ? Eigen::AngleAxisd(angle, v / angle).toRotationMatrix() \
                                    : Eigen::Matrix3d::Identity())
%(symforce_timer)s
"""

SYMFORCE_TIMER = r"""
PEER_TIMER(time_symforce_rotation_vector, \
    Eigen::Vector3d v(p[0], p[1], p[2]); \
    Eigen::Matrix3d R = sym::RotvecToMatrix<double>(v, 10 * std::numeric_limits<double>::epsilon()))
"""

SYMFORCE_GENERATOR = r"""
import sys
import symforce
symforce.set_epsilon_to_symbol()
import symforce.symbolic as sf
from symforce import codegen

def rotvec_to_matrix(v: sf.V3, epsilon: sf.Scalar) -> sf.M33:
    return sf.Rot3.from_tangent(v, epsilon=epsilon).to_rotation_matrix()

cg = codegen.Codegen.function(rotvec_to_matrix, config=codegen.CppConfig())
cg.generate_function(output_dir=sys.argv[1], skip_directory_nesting=True)
print(symforce.__version__)
"""


def compile_shared(compiler: str, source: Path, out: Path, extra: tuple[str, ...]) -> None:
    command = [compiler, *FLAGS, "-fPIC", "-shared", *extra, str(source), "-o", str(out), "-lm"]
    subprocess.run(command, check=True)


def generate_symforce(work: Path) -> tuple[Path | None, str]:
    """Generate SymForce's Rot3 rotation-vector code; (header, version) or (None, reason)."""
    python = os.environ.get("SYMROT_SYMFORCE_PYTHON", sys.executable)
    script = work / "symforce_gen.py"
    script.write_text(SYMFORCE_GENERATOR, encoding="utf-8")
    result = subprocess.run([python, str(script), str(work)], capture_output=True, text=True,
                            check=False, timeout=600)
    header = work / "rotvec_to_matrix.h"
    if result.returncode != 0 or not header.exists():
        return None, (result.stderr.strip().splitlines() or ["symforce not importable"])[-1]
    return header, result.stdout.strip()


def random_pool(name: str, n: int, rng: np.random.Generator) -> np.ndarray:
    """n vectors p = p(φ) u with |φ| log-uniform in [1e-6, limit] and uniform axes."""
    p_of_phi = sp.lambdify(PHI, derive(name).derivation.p, modules=[mpmath_namespace(), "mpmath"])
    limit = ANGLE_LIMIT.get(name, 3.1)
    angles = np.exp(rng.uniform(np.log(1e-6), np.log(limit), n))
    magnitudes = np.array([float(p_of_phi(mpmath.mpf(float(a)))) for a in angles[:256]])
    magnitudes = np.resize(magnitudes, n)
    axes = rng.normal(size=(n, 3))
    axes /= np.linalg.norm(axes, axis=1, keepdims=True)
    return np.ascontiguousarray(axes * magnitudes[:, None])


def time_timer(dll: ctypes.CDLL, symbol: str, pool: np.ndarray, vpool: np.ndarray, precision: str,
               reps: int) -> float:
    dtype, ctype = (np.float32, ctypes.c_float) if precision == "float" else (np.float64, ctypes.c_double)
    p = np.ascontiguousarray(pool, dtype=dtype)
    v = np.ascontiguousarray(vpool, dtype=dtype)
    fn = getattr(dll, symbol)
    pointer = ctypes.POINTER(ctype)
    fn.argtypes = [ctypes.c_size_t, ctypes.c_size_t, pointer, pointer, ctypes.POINTER(ctypes.c_double)]
    fn.restype = ctypes.c_double
    sink = ctypes.c_double(0.0)
    fn(max(1, reps // 10), len(p), p.ctypes.data_as(pointer), v.ctypes.data_as(pointer), ctypes.byref(sink))
    return min(fn(reps, len(p), p.ctypes.data_as(pointer), v.ctypes.data_as(pointer), ctypes.byref(sink))
               for _ in range(5))


def best_of(callable_: Callable[[], object], repeats: int = 5) -> float:
    times = []
    for _ in range(repeats):
        start = time.perf_counter()
        callable_()
        times.append(time.perf_counter() - start)
    return min(times)


def batch_timer(dll: ctypes.CDLL, symbol: str, p: np.ndarray) -> Callable[[], object]:
    fn = getattr(dll, symbol)
    pointer = ctypes.POINTER(ctypes.c_double)
    fn.argtypes = [ctypes.c_size_t, pointer, pointer]
    fn.restype = None

    def run() -> np.ndarray:
        out = np.empty((len(p), 3, 3))
        fn(len(p), p.ctypes.data_as(pointer), out.ctypes.data_as(pointer))
        return out

    return run


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--reps", type=int, default=200, help="passes over the pool per timing")
    parser.add_argument("--batch", type=int, default=BATCH, help="rotations per batch timing")
    parser.add_argument("--no-write", action="store_true", help="print only, leave docs/ alone")
    args = parser.parse_args(argv)
    from scipy.spatial.transform import Rotation

    names = [n for n in PARAMETERIZATIONS if (HEADERS / f"symrot_{n}.h").exists()]
    if not names:
        print(f"no headers under {HEADERS}: run make generate", file=sys.stderr)
        return 1
    rng = np.random.default_rng(20030101)
    rows: list[tuple[str, str, str, float]] = []
    batch_rows: list[tuple[str, str, float]] = []
    with tempfile.TemporaryDirectory(prefix="symrot_bench_") as tmp:
        work = Path(tmp)
        source, timers = c_source(names)
        (work / "bench.c").write_text(source, encoding="utf-8")
        compile_shared("gcc", work / "bench.c", work / "bench.so", ("-std=gnu11", f"-I{HEADERS}"))
        generated = ctypes.CDLL(str(work / "bench.so"))
        symforce_header, symforce_note = generate_symforce(work)
        peer = PEER_SOURCE % {
            "symforce_include": f'#include "{symforce_header}"' if symforce_header else "",
            "symforce_timer": SYMFORCE_TIMER if symforce_header else "",
        }
        (work / "peers.cpp").write_text(peer, encoding="utf-8")
        compile_shared("g++", work / "peers.cpp", work / "peers.so", ("-std=c++14", "-I/usr/include/eigen3"))
        peers = ctypes.CDLL(str(work / "peers.so"))

        pools = {name: random_pool(name, POOL, rng) for name in names}
        vpool = rng.normal(size=(POOL, 3))
        for symbol, name, label, precision in timers:
            rows.append((name, label, precision, time_timer(generated, symbol, pools[name], vpool,
                                                            precision, args.reps)))
        if "rotation_vector" in names:
            for peer_name in ("eigen", "symforce"):
                symbol = f"time_{peer_name}_rotation_vector"
                if hasattr(peers, symbol):
                    rows.append(("rotation_vector", f"{peer_name} rotation_matrix", "double",
                                 time_timer(peers, symbol, pools["rotation_vector"], vpool, "double",
                                            args.reps)))

        for name in names:
            p = np.ascontiguousarray(np.resize(pools[name], (args.batch, 3)))
            batch_rows.append((name, "generated _batch (ctypes)",
                               best_of(batch_timer(generated, f"batch_{name}_rotation_matrix", p))))
            batch_rows.append((name, "textbook loop (ctypes)",
                               best_of(batch_timer(generated, f"batch_textbook_{name}", p))))
            if name == "rotation_vector":
                batch_rows.append((name, "scipy from_rotvec().as_matrix()",
                                   best_of(lambda p=p: Rotation.from_rotvec(p).as_matrix())))
            if name == "wiener_milenkovic":
                mrp = p / 4.0  # scipy's MRP is tan(φ/4) u = p/4
                batch_rows.append((name, "scipy from_mrp().as_matrix()",
                                   best_of(lambda mrp=mrp: Rotation.from_mrp(mrp).as_matrix())))
    text = report(rows, batch_rows, args, symforce_note)
    print(text)
    if not args.no_write:
        write_section(text)
    return 0


def report(rows: list[tuple[str, str, str, float]], batch_rows: list[tuple[str, str, float]],
           args: argparse.Namespace, symforce_note: str) -> str:
    command = "python bench/c_speed.py" + (f" --reps {args.reps}" if args.reps != 200 else "") + \
        (f" --batch {args.batch}" if args.batch != BATCH else "")
    if "SYMROT_SYMFORCE_PYTHON" in os.environ:
        command = "SYMROT_SYMFORCE_PYTHON=/tmp/symforce_venv/bin/python " + command
    cpu = platform.processor() or platform.machine()
    lines = [
        SECTION, "",
        f"Produced by `{command}` (gcc {' '.join(FLAGS)}; {os.cpu_count()} cores, {cpu}; "
        f"SymForce: {symforce_note}). Times are the best of 5. Inputs: |φ| log-uniform in [1e-6, 3.1] "
        "(1.5 for linear, 3.0 for Cayley-Gibbs-Rodrigues), random axes, so most are small rotations: a "
        "single call below its plan's switch (rotation vector R: |φ| < 0.64, 89 % of these inputs) "
        "evaluates polynomials and no sin/cos, which the one-call times reflect; the batch kernels "
        "compute both candidates for every vector.", "",
        "### One call (ns per call, C loop over 4096 random vectors)", "",
        "| parameterization | function | double ns | float ns | textbook ns | best peer | peer ns | "
        "generated / best other |",
        "| --- | --- | ---: | ---: | ---: | --- | ---: | ---: |",
    ]
    table: dict[tuple[str, str, str], float] = {(n, lbl, pr): t for n, lbl, pr, t in rows}
    for name in dict.fromkeys(n for n, *_ in rows):
        for function in FUNCTIONS:
            double = table.get((name, f"generated {function}", "double"))
            if double is None:
                continue
            single = table.get((name, f"generated {function}", "float"), float("nan"))
            textbook = table.get((name, f"textbook {function}", "double")) if function == "rotation_matrix" \
                else None
            peers = {lbl.split()[0]: t for (n, lbl, _), t in table.items() if n == name
                     and lbl.endswith(function) and not lbl.startswith(("generated", "textbook"))}
            best_peer = min(peers.items(), key=lambda item: item[1]) if peers else None
            others = [t for t in (textbook, best_peer[1] if best_peer else None) if t is not None]
            ratio = f"{double / min(others):.2f}×" if others else "–"
            lines.append(
                f"| {name} | {function} | {double:.1f} | {single:.1f} | "
                f"{f'{textbook:.1f}' if textbook else '–'} | {best_peer[0] if best_peer else '–'} | "
                f"{f'{best_peer[1]:.1f}' if best_peer else '–'} | {ratio} |"
            )
    peer_rows = [(n, lbl, t) for (n, lbl, _), t in table.items()
                 if not lbl.startswith(("generated", "textbook"))]
    if peer_rows:
        lines += ["", "Peers, one call (double): " + "; ".join(
            f"{lbl} for {n}: {t:.1f} ns" for n, lbl, t in peer_rows) + "."]
    lines += ["", f"### Batch rotation_matrix over {args.batch:,} rotations, called from NumPy", "",
              "| parameterization | implementation | ms | M rotations/s | throughput vs scipy |",
              "| --- | --- | ---: | ---: | ---: |"]
    for name in dict.fromkeys(n for n, *_ in batch_rows):
        entries = [(label, t) for n, label, t in batch_rows if n == name]
        scipy_time = next((t for label, t in entries if label.startswith("scipy")), None)
        for label, seconds in entries:
            ratio = f"{scipy_time / seconds:.1f}×" if scipy_time else "–"
            lines.append(f"| {name} | {label} | {seconds * 1e3:.1f} | {args.batch / seconds / 1e6:.1f} | "
                         f"{ratio} |")
    lines += ["", "### Targets", ""]
    for name, label, peer_time in peer_rows:
        ours = table[name, "generated rotation_matrix", "double"]
        verdict = "met" if ours <= peer_time else "missed"
        lines.append(f"- one call ≤ 1.0× the best peer: {name} rotation_matrix {ours:.1f} ns vs "
                     f"{label.split()[0]} {peer_time:.1f} ns = {ours / peer_time:.2f}× ({verdict})")
    for name in dict.fromkeys(n for n, *_ in batch_rows):
        entries = dict((label, t) for n, label, t in batch_rows if n == name)
        scipy_time = next((t for label, t in entries.items() if label.startswith("scipy")), None)
        if scipy_time:
            ratio = scipy_time / entries["generated _batch (ctypes)"]
            verdict = "met" if ratio >= 3 else "missed"
            lines.append(f"- batch ≥ 3× scipy's throughput: {name} {ratio:.1f}× ({verdict})")
    lines += ["", "The machine is shared (2 cores, other jobs running): single figures move by up to ~30 % "
              "between runs; the ratios within one run are what the table is for."]
    return "\n".join(lines) + "\n"


def write_section(text: str) -> None:
    """Replace (or append) the "C backend" section of docs/performance.md, keeping the others."""
    DOC.parent.mkdir(exist_ok=True)
    old = DOC.read_text(encoding="utf-8") if DOC.exists() else "# Performance\n"
    if SECTION in old:
        start = old.index(SECTION)
        following = old.find("\n## ", start + len(SECTION))
        new = old[:start] + text + (old[following + 1:] if following >= 0 else "")
    else:
        new = old.rstrip("\n") + "\n\n" + text
    DOC.write_text(new, encoding="utf-8")


if __name__ == "__main__":
    raise SystemExit(main())
