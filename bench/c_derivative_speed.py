"""Speed of the C single calls of the derivatives (issue 19) beside H, in ns per call.

Each function of generated/c/symrot_NAME.h is called in a C loop over a pool of 4096 random inputs
(|φ| log-uniform in [1e-6, 3.0], random axes; a, ṗ, p̈ standard normal), compiled with gcc -O2
-march=native. Time: thread CPU time (``time.thread_time_ns``) of the whole loop, best of 5, so
that other processes on a shared machine count less than in wall-clock time (they still share caches
and, with hyper-threading, the core).

Run: ``python bench/c_derivative_speed.py`` (prints a Markdown table for docs/performance.md).
"""

from __future__ import annotations

import argparse
import ctypes
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import mpmath
import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from tests.reference import GeneratingFunction  # noqa: E402

HEADERS = ROOT / "generated" / "c"
NAMED = {"rotation_vector": "phi", "wiener_milenkovic": "4*tan(phi/4)",
         "det_h_one": "cbrt(6*(phi - sin(phi)))"}
# function → C call in the loop (i: input index), outputs per call
CALLS = {
    "tangent": ("symrot_{n}_tangent{s}(p + 3*i, out)", 9),
    "omega": ("symrot_{n}_omega{s}(p + 3*i, a + 3*i, out)", 3),
    "tangent_derivative": ("symrot_{n}_tangent_derivative{s}(p + 3*i, a + 3*i, out)", 9),
    "tangent_inverse_derivative": ("symrot_{n}_tangent_inverse_derivative{s}(p + 3*i, a + 3*i, out)", 9),
    "rotation_derivative": ("symrot_{n}_rotation_derivative{s}(p + 3*i, a + 3*i, out)", 9),
    "angular_acceleration": ("symrot_{n}_angular_acceleration{s}(p + 3*i, a + 3*i, b + 3*i, out)", 3),
    "compose_jacobians": ("(void)symrot_{n}_compose_jacobians{s}(p + 3*i, a + 3*i, out, out + 9)", 18),
    "rescale_jacobian": ("(void)symrot_{n}_rescale_jacobian{s}(p + 3*i, out)", 9),
}
POOL = 4096
REPEATS = 50


def source() -> str:
    lines = ["#include <stddef.h>", *(f'#include "symrot_{n}.h"' for n in NAMED)]
    for name in NAMED:
        for precision, suffix in (("double", ""), ("float", "_f")):
            for function, (call, _) in CALLS.items():
                text = call.format(n=name, s=suffix)
                t = precision
                lines.append(f"double loop_{name}_{function}{suffix}(size_t reps, size_t n, const {t} *p, "
                             f"const {t} *a, const {t} *b, {t} *out) {{ size_t r, i; double sink = 0; "
                             f"(void)a; (void)b; for (r = 0; r < reps; ++r) {{ for (i = 0; i < n; ++i) "
                             f"{{ {text}; sink += (double)out[0]; }} }} return sink; }}")
    return "\n".join(lines) + "\n"


def pool(expression: str, dtype: type, rng: np.random.Generator) -> np.ndarray:
    function = GeneratingFunction(expression)
    angles = np.exp(rng.uniform(np.log(1e-6), np.log(3.0), POOL))
    with mpmath.workdps(30):
        sizes = np.array([float(function.value(mpmath.mpf(float(t)))) for t in angles])
    axes = rng.normal(size=(POOL, 3))
    return np.ascontiguousarray(axes / np.linalg.norm(axes, axis=1)[:, None] * sizes[:, None], dtype=dtype)


def main(argv: list[str] | None = None) -> int:
    argparse.ArgumentParser(description=__doc__.splitlines()[0],
                            epilog="Prints a Markdown table for docs/performance.md.").parse_args(argv)
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "speed.c"
        path.write_text(source(), encoding="utf-8")
        library = Path(tmp) / "speed.so"
        subprocess.run(["gcc", "-std=c99", "-O2", "-march=native", "-fPIC", "-shared", f"-I{HEADERS}",
                        str(path), "-o", str(library), "-lm"], check=True)
        dll = ctypes.CDLL(str(library))
        rng = np.random.default_rng(19)
        print("| parameterization | function | double ns | float ns |")
        print("| --- | --- | ---: | ---: |")
        for name, expression in NAMED.items():
            times: dict[str, list[float]] = {}
            precisions = (("", np.float64, ctypes.c_double), ("_f", np.float32, ctypes.c_float))
            for suffix, dtype, ctype in precisions:
                p = pool(expression, dtype, rng)
                a, b = (np.ascontiguousarray(rng.normal(size=(POOL, 3)), dtype=dtype) for _ in range(2))
                out = np.zeros(18, dtype=dtype)
                pointer = ctypes.POINTER(ctype)
                for function in CALLS:
                    fn = getattr(dll, f"loop_{name}_{function}{suffix}")
                    fn.argtypes = [ctypes.c_size_t, ctypes.c_size_t, pointer, pointer, pointer, pointer]
                    fn.restype = ctypes.c_double
                    args = [x.ctypes.data_as(pointer) for x in (p, a, b, out)]
                    best = float("inf")
                    for _ in range(5):
                        start = time.thread_time_ns()
                        fn(REPEATS, POOL, *args)
                        best = min(best, (time.thread_time_ns() - start) / (REPEATS * POOL))
                    times.setdefault(function, []).append(best)
            for function, (double_ns, float_ns) in times.items():
                print(f"| {name} | {function} | {double_ns:.1f} | {float_ns:.1f} |")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
