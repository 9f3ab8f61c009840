"""C headers under AddressSanitizer/UndefinedBehaviorSanitizer on the fuzz inputs of the NumPy
domain fuzz (issue 17): every single call, batch kernel and operation of a header, both precisions.

Inputs: vectors whose components are drawn from ``MAGNITUDES`` (0, the smallest subnormal,
1e-300 … 1.7e308, inf, NaN, both signs; in float those round to float's subnormals, 0 and inf),
quaternions of the same components, and matrices: rotations, rotations perturbed at every
magnitude, and the non-rotations of issue 17 (zeros, ones, diag(1, 1, −1), −I, 2 Rz(1), rank 1,
NaN/inf entries). The driver is compiled with ``-O0 -g -fsanitize=address,undefined
-fno-sanitize-recover=all`` (clang, or gcc), so the first report aborts it; its outputs must be
finite or NaN (never ±inf) and every status 0 or 1. The second argument of pdot/omega is a finite
rate (:func:`rates`).
"""

from __future__ import annotations

import subprocess
from pathlib import Path

import numpy as np

from symrot.backends.c_functions import FUNCTIONS

MAGNITUDES = (0.0, 5e-324, 1e-300, 1e-30, 1e-8, 1.0, 3.0, 1e10, 1e80, 1e300, 1.7e308, np.inf, np.nan)
SANITIZE = ("-std=c99", "-O0", "-g", "-fsanitize=address,undefined", "-fno-sanitize-recover=all",
            "-fno-omit-frame-pointer")
OPERATIONS = (("to_quaternion", "p", 4, False), ("from_quaternion", "e", 3, True),
              ("from_rotation_matrix", "R", 3, True), ("compose", "pp", 3, True), ("rescale", "p", 3, True))
"""(operation, input kind, output width, returns a status)."""


def vectors(count: int, seed: int) -> np.ndarray:
    """Every magnitude on each axis, then ``count`` random component triples, random signs."""
    rng = np.random.default_rng(seed)
    axes = [np.roll([m, 0.0, 0.0], k) for m in MAGNITUDES for k in range(3)]
    drawn = rng.choice(np.array(MAGNITUDES), size=(count, 3))
    out = np.concatenate([np.array(axes), drawn])
    return out * rng.choice([-1.0, 1.0], size=out.shape)


def quaternions(count: int, seed: int) -> np.ndarray:
    rng = np.random.default_rng(seed + 1)
    unit = rng.normal(size=(count, 4))
    unit /= np.linalg.norm(unit, axis=1, keepdims=True)
    drawn = rng.choice(np.array(MAGNITUDES), size=(count, 4)) * rng.choice([-1.0, 1.0], size=(count, 4))
    small = np.array([[1e-100, 1.0, 0.0, 0.0], [1e-17, 1.0, 0.0, 0.0], [0.0, 0.0, 0.0, 1.0],
                      [1.0, 0.0, 0.0, 0.0], [-1.0, 0.0, 0.0, 0.0]])
    return np.concatenate([small, unit, drawn])


def _rz(angle: float) -> np.ndarray:
    c, s = np.cos(angle), np.sin(angle)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def matrices(count: int, seed: int) -> np.ndarray:
    rng = np.random.default_rng(seed + 2)
    special = [np.zeros((3, 3)), np.ones((3, 3)), np.diag([1.0, 1.0, -1.0]), -np.eye(3), 2 * _rz(1.0),
               np.outer([1.0, 2.0, 3.0], [0.5, -1.0, 2.0]), _rz(np.pi), np.eye(3)]
    out = [m.reshape(9) for m in special]
    for k in range(count):
        axis = rng.normal(size=3)
        axis /= np.linalg.norm(axis)
        angle = rng.uniform(0, np.pi)
        k_ = np.array([[0, -axis[2], axis[1]], [axis[2], 0, -axis[0]], [-axis[1], axis[0], 0]])
        rotation = np.eye(3) + np.sin(angle) * k_ + (1 - np.cos(angle)) * (k_ @ k_)
        perturbed = rotation.reshape(9).copy()
        perturbed[k % 9] += MAGNITUDES[k % len(MAGNITUDES)] * (1 if k % 2 else -1)
        out += [rotation.reshape(9), perturbed]
    return np.array(out)


def driver_source(headers: list[str]) -> str:
    """A C program: reads the inputs of :func:`write_inputs`, calls every function of every header
    on them (double, then float), writes all outputs as doubles (statuses too) to stdout."""
    lines = ["#include <stdio.h>", "#include <stdlib.h>", "#include <string.h>"]
    lines += [f'#include "symrot_{h}.h"' for h in headers]
    body = []
    for ctype, suffix in (("double", ""), ("float", "_f")):
        pre = "d" if ctype == "double" else "f"
        for h in headers:
            for function in FUNCTIONS:
                target = f"symrot_{h}_{function.name}{suffix}"
                w = function.width
                if function.kind == "scalar":
                    call = f"buf[0] = (double){target}({pre}p + 3*i);"
                    body.append(_loop(ctype, 1, call, w_out=1))
                    continue
                if function.kind == "vector":
                    call = f"{target}({pre}p + 3*i, {pre}w + 3*i, out);"
                else:
                    call = f"{target}({pre}p + 3*i, out);"
                body.append(_loop(ctype, w, call))
                if function.kind == "matrix":
                    body.append(_batch(ctype, w, f"{target}_batch"))
            for name, kind, width, status in OPERATIONS:
                target = f"symrot_{h}_{name}{suffix}"
                count = {"p": "n", "pp": "n", "e": "ne", "R": "nr"}[kind]
                args = {"p": f"{pre}p + 3*i", "pp": f"{pre}p + 3*i, {pre}p + 3*((i + 1) % n)",
                        "e": f"{pre}e + 4*i", "R": f"{pre}R + 9*i"}[kind]
                call = (f"buf[{width}] = (double){target}({args}, out);" if status
                        else f"{target}({args}, out);")
                body.append(_loop(ctype, width, call, w_out=width + status, count=count))
    lines.append(_MAIN.replace("/*BODY*/", "\n".join(body)))
    return "\n".join(lines) + "\n"


def _loop(ctype: str, width: int, call: str, w_out: int | None = None, count: str = "n") -> str:
    """For i < count: an exact-size output buffer (ASan sees any write past it), the call, and the
    outputs (converted to double) written to stdout."""
    w_out = width if w_out is None else w_out
    return (f"for (i = 0; i < {count}; ++i) {{ {ctype} *out = ({ctype} *)malloc({width} * sizeof *out); "
            f"double buf[16]; size_t j; for (j = 0; j < {width}; ++j) out[j] = 0; {call} "
            f"for (j = 0; j < {width}; ++j) buf[j] = (double)out[j]; "
            f"fwrite(buf, sizeof *buf, {w_out}, stdout); free(out); }}")


def _batch(ctype: str, width: int, target: str) -> str:
    pre = "d" if ctype == "double" else "f"
    return (f"{{ {ctype} *out = ({ctype} *)malloc({width} * n * sizeof *out); {target}(n, {pre}p, out); "
            f"for (i = 0; i < {width} * n; ++i) {{ double b = (double)out[i]; "
            "fwrite(&b, sizeof b, 1, stdout); } free(out); }")


_MAIN = r"""
static void *read_all(FILE *in, size_t count, size_t size) {
    void *data = malloc(count * size);
    if (fread(data, size, count, in) != count) exit(4);
    return data;
}
int main(int argc, char **argv) {
    FILE *in; size_t n, ne, nr, i;
    double *dp, *dw, *de, *dR; float *fp, *fw, *fe, *fR;
    if (argc != 2 || !(in = fopen(argv[1], "rb"))) return 2;
    if (fread(&n, sizeof n, 1, in) != 1 || fread(&ne, sizeof ne, 1, in) != 1
        || fread(&nr, sizeof nr, 1, in) != 1) return 3;
    dp = (double *)read_all(in, 3 * n, sizeof *dp); dw = (double *)read_all(in, 3 * n, sizeof *dw);
    de = (double *)read_all(in, 4 * ne, sizeof *de);
    dR = (double *)read_all(in, 9 * nr, sizeof *dR);
    fp = (float *)read_all(in, 3 * n, sizeof *fp); fw = (float *)read_all(in, 3 * n, sizeof *fw);
    fe = (float *)read_all(in, 4 * ne, sizeof *fe);
    fR = (float *)read_all(in, 9 * nr, sizeof *fR);
    fclose(in);
/*BODY*/
    free(dp); free(dw); free(de); free(dR); free(fp); free(fw); free(fe); free(fR);
    return 0;
}
"""


def rates(count: int, seed: int) -> np.ndarray:
    """Second arguments of pdot/omega: finite rates of moderate size (|component| ≤ 10³; the
    product with an unbounded rate may overflow legitimately)."""
    rng = np.random.default_rng(seed + 3)
    return rng.uniform(-1, 1, size=(count, 3)) * 10.0 ** rng.integers(-3, 4, size=(count, 1))


def write_inputs(path: Path, p: np.ndarray, e: np.ndarray, r: np.ndarray) -> None:
    w = rates(len(p), 0)
    with np.errstate(over="ignore"), path.open("wb") as handle:
        handle.write(np.array([len(p), len(e), len(r)], dtype=np.uintp).tobytes())
        for dtype in (np.float64, np.float32):
            for array in (p, w, e, r):
                handle.write(np.ascontiguousarray(array, dtype=dtype).tobytes())


def build(compiler: str, headers: list[str], include_dir: Path, work: Path) -> Path:
    source = work / "fuzz_driver.c"
    source.write_text(driver_source(headers), encoding="utf-8")
    binary = work / f"fuzz_driver_{compiler}"
    command = [compiler, *SANITIZE, f"-I{include_dir}", str(source), "-o", str(binary), "-lm"]
    result = subprocess.run(command, capture_output=True, text=True, timeout=600, check=False)
    if result.returncode != 0:
        raise AssertionError(f"{' '.join(command)}\n{result.stderr[-4000:]}")
    return binary


def run(binary: Path, p: np.ndarray, e: np.ndarray, r: np.ndarray, work: Path) -> np.ndarray:
    """Every output of the driver (sanitizer-clean run required), as one float64 array."""
    inputs = work / "fuzz.in"
    write_inputs(inputs, p, e, r)
    env = {"ASAN_OPTIONS": "detect_leaks=1:abort_on_error=0", "UBSAN_OPTIONS": "print_stacktrace=1",
           "PATH": "/usr/bin:/bin"}
    result = subprocess.run([str(binary), str(inputs)], capture_output=True, timeout=1800, check=False,
                            env=env)
    if result.returncode != 0 or result.stderr:
        raise AssertionError(f"{binary.name} exited {result.returncode}:\n"
                             f"{result.stderr.decode(errors='replace')[-6000:]}")
    return np.frombuffer(result.stdout, dtype=np.float64)


def statuses_and_values(headers: list[str], n: int, ne: int, nr: int, outputs: np.ndarray) -> tuple[
        np.ndarray, np.ndarray, list[str]]:
    """(every status the operations returned, every other output, the operations whose status
    disagrees with their output: 0 with a NaN, 1 with a number), split by the driver's layout."""
    statuses, values, disagree, offset = [], [], [], 0
    for precision in ("double", "float"):
        for h in headers:
            for function in FUNCTIONS:
                size = (1 if function.kind == "scalar" else function.width) * n
                values.append(outputs[offset:offset + size])
                offset += size
                if function.kind == "matrix":
                    values.append(outputs[offset:offset + function.width * n])
                    offset += function.width * n
            for name, kind, width, status in OPERATIONS:
                count = {"p": n, "pp": n, "e": ne, "R": nr}[kind]
                block = outputs[offset:offset + count * (width + status)].reshape(count, width + status)
                offset += block.size
                values.append(block[:, :width].ravel())
                if status:
                    statuses.append(block[:, width])
                    nan = np.isnan(block[:, :width]).any(axis=1)
                    wrong = np.flatnonzero((block[:, width] == 0) == nan)
                    if wrong.size:
                        disagree.append(f"{precision} {h} {name}: {wrong.size} of {count} (input {wrong[0]})")
    assert offset == outputs.size, (offset, outputs.size)
    return np.concatenate(statuses), np.concatenate(values), disagree


__all__ = ["MAGNITUDES", "build", "matrices", "quaternions", "run", "statuses_and_values", "vectors"]
