"""Issue 58: the ``_batch`` kernels raise no floating-point flag on valid input.

Flight software traps FE_INVALID (and FE_DIVBYZERO, FE_OVERFLOW) to catch a NaN where it appears.
The kernels compute every candidate value on every lane of a block, so a lane that discards a
value (past n, below a polynomial's threshold) must still compute it on a harmless argument. For
every header, every ``_batch`` kernel in both precisions runs on valid inputs that span the range
(|p| from 2^-1000, subnormal in float, to just inside the validity edge, zeros, every n from 1 to
three blocks and more), with the flags cleared before each call and tested after it.
"""

from __future__ import annotations

import re
import shutil
import subprocess
from pathlib import Path

import pytest

from symrot.backends.c_backend import COVERED

GENERATED = Path(__file__).resolve().parent.parent / "generated" / "c"
KERNEL = re.compile(r"^static inline void (symrot_\w+_batch)\(size_t n, const (double|float) \*p", re.M)
DRIVER = r"""
#include <fenv.h>
#include <math.h>
#include <stdio.h>
#include "symrot_{name}.h"
#define COUNT 4000
static double P[3 * COUNT];
static float PF[3 * COUNT];
static double OUT[9 * COUNT];
static float OUTF[9 * COUNT];
int main(void) {{
    unsigned long long state = 88172645463325252ULL;
    size_t k, n;
    for (k = 0; k < COUNT; ++k) {{
        double u[3], norm, scale, r;
        int i;
        for (i = 0; i < 3; ++i) {{
            state ^= state << 13; state ^= state >> 7; state ^= state << 17;
            u[i] = (double)(state >> 11) / 9007199254740992.0 * 2.0 - 1.0;
        }}
        norm = sqrt(u[0] * u[0] + u[1] * u[1] + u[2] * u[2]) + 1e-300;
        state ^= state << 13; state ^= state >> 7; state ^= state << 17;
        r = (double)(state >> 11) / 9007199254740992.0;
        scale = k % 2 ? {edge} * (0.999 * r) : {edge} * ldexp(1.0, -(int)(r * {depth}));
        if (k % 97 == 0) scale = 0.0;
        for (i = 0; i < 3; ++i) {{ P[3 * k + i] = scale * u[i] / norm; PF[3 * k + i] = (float)P[3 * k + i]; }}
    }}
{calls}
    return 0;
}}
"""
CALL = r"""
    for (n = 1; n <= COUNT; n = n < 100 ? n + 1 : n * 3) {{
        feclearexcept(FE_ALL_EXCEPT);
        {kernel}(n, {inputs}, {outputs});
        if (fetestexcept(FE_INVALID | FE_DIVBYZERO | FE_OVERFLOW)) {{
            printf("{kernel} n=%lu:%s%s%s\n", (unsigned long)n,
                   fetestexcept(FE_INVALID) ? " invalid" : "",
                   fetestexcept(FE_DIVBYZERO) ? " divide-by-zero" : "",
                   fetestexcept(FE_OVERFLOW) ? " overflow" : "");
            break;
        }}
    }}"""


def _edges(text: str) -> tuple[float, float]:
    """|p| just inside the validity edge of the double and of the float functions."""
    bounded = re.search(r"Valid for \|p\| < ([0-9.e+]+)", text)
    if bounded:
        edge = float(bounded[1]) * (1 - 1e-6)
        return edge, edge
    powers = [int(power) for power in re.findall(r"Valid for every p with \|p\|\^2 < 2\^(\d+)", text)]
    return 2.0 ** (min(powers[:1] or [100]) / 2) * 0.999, 2.0 ** (min(powers) / 2) * 0.999


@pytest.mark.parametrize("name", COVERED)
def test_batch_kernels_raise_no_flag_on_valid_input(name: str, tmp_path: Path) -> None:
    compiler = shutil.which("gcc") or shutil.which("cc")
    assert compiler, "a C compiler is needed (make setup installs gcc)"
    text = (GENERATED / f"symrot_{name}.h").read_text(encoding="utf-8")
    double_edge, float_edge = _edges(text)
    kernels = KERNEL.findall(text)
    assert len(kernels) == 10, kernels
    calls = []
    for kernel, ctype in kernels:
        inputs, outputs = ("P", "OUT") if ctype == "double" else ("PF", "OUTF")
        calls.append(CALL.format(kernel=kernel, inputs=inputs, outputs=outputs))
    for precision, edge, depth in (("double", double_edge, 1000), ("float", float_edge, 140)):
        chosen = "\n".join(c for c, (_, ctype) in zip(calls, kernels, strict=True) if ctype == precision)
        source = tmp_path / f"{name}_{precision}.c"
        text = DRIVER.format(name=name, edge=repr(edge), depth=depth, calls=chosen)
        source.write_text(text, encoding="utf-8")
        binary = tmp_path / f"{name}_{precision}"
        subprocess.run([compiler, "-std=c99", "-O2", "-I", str(GENERATED), str(source), "-o", str(binary),
                        "-lm"], check=True, timeout=300)
        result = subprocess.run([str(binary)], capture_output=True, text=True, timeout=300, check=True)
        assert result.stdout == "", result.stdout
