"""The fold complement d = p_max² − |p|² of the generated C headers (sine family, eqs 31–32, 36).

Next to the fold |p| → p_max, x = |p|² rounded leaves no correct digit of p_max² − x, so the
headers compute d from exact products (fma) and error-free sums. The sums are Fast2Sum, which is
exact only under a precondition (each running p_max² − p₀² − … at least the next square, or within
a factor 2 of it) that holds inside the validity range: here d is compared bit for bit with the
TwoSum algorithm the headers printed before (emulated in Python with exact fma error terms), and
with the exact value (to one ulp of d plus 4 ε² p_max²), in double and float, on vectors up to
10⁻¹⁶ from the fold."""

from __future__ import annotations

import ctypes
import subprocess
from fractions import Fraction
from functools import cache
from pathlib import Path

import mpmath
import numpy as np
import pytest

from symrot.api import derive
from symrot.backends.c_backend import COVERED
from symrot.core.singularities import validity
from symrot.plan.algebraic import fold_complement
from symrot.plan.forms import closed_inverse

from . import c_harness
from .test_c_backend import GENERATED

FOLDED = [name for name in COVERED
          if f"symrot_{name}__complement(" in (GENERATED / f"symrot_{name}.h").read_text(encoding="utf-8")]
"""The headers that print the complement (read at collection, where computing the 14 plans took
about 2 minutes of CPU time in every pytest-xdist worker)."""


@cache
def squared_edge(name: str) -> Fraction:
    """k² = p_max² of the fold, from the inverse and the validity range (:func:`fold_complement`),
    without the plan."""
    derivation = derive(name).derivation
    complement = fold_complement(closed_inverse(derivation.p, derivation.kappa),
                                 float(validity(derivation).p_max_float))
    assert complement is not None, name
    return Fraction(int(complement.p), int(complement.q))


def two_sum_complement(p: np.ndarray, k2: float, dtype: type) -> float:
    """The headers' earlier algorithm: exact products (the fma error term, exact in the format),
    TwoSum of each step, then high + low, in ``dtype`` arithmetic."""
    f = dtype
    high, low = f(k2), f(0)
    for component in p:
        c = f(component)
        square = f(c * c)
        error = f(Fraction(float(c)) ** 2 - Fraction(float(square)))  # exact: fma(c, c, -square)
        total = f(high - square)
        virtual = f(total - high)
        low = f(low + f(f(f(high - f(total - virtual)) + f(-square - virtual)) - error))
        high = total
    return float(f(high + low))


def fold_vectors(k: float, dtype: type, rng: np.random.Generator) -> np.ndarray:
    """Directions × magnitudes from p_max/2 (where the compensated branch starts) to 10⁻¹⁶ below
    p_max, kept inside the range in exact arithmetic."""
    directions = rng.normal(size=(400, 3))
    directions /= np.linalg.norm(directions, axis=1, keepdims=True)
    magnitudes = np.concatenate([rng.uniform(0.5 * k, k, 200), k * (1 - np.geomspace(0.1, 1e-16, 200))])
    rows = (directions * magnitudes[:, None]).astype(dtype)
    k2 = Fraction(k) ** 2
    return np.array([row for row in rows if sum(Fraction(float(c)) ** 2 for c in row) < k2])


@pytest.fixture(scope="module")
def library(tmp_path_factory: pytest.TempPathFactory) -> ctypes.CDLL:
    work = tmp_path_factory.mktemp("complement")
    lines = [f'#include "symrot_{name}.h"' for name in FOLDED]
    for name in FOLDED:
        for ctype, suffix in (("double", ""), ("float", "_f")):
            lines.append(f"{ctype} t_{name}{suffix}(const {ctype} *p, {ctype} x) "
                         f"{{ return symrot_{name}__complement{suffix}(p, x); }}")
    source = work / "complement.c"
    source.write_text("\n".join(lines) + "\n", encoding="utf-8")
    out = work / "complement.so"
    command = ["gcc", *c_harness.STRICT_C, "-O2", "-ffp-contract=off", f"-I{GENERATED}", "-shared", "-fPIC",
               str(source), "-o", str(out), "-lm"]
    subprocess.run(command, check=True, capture_output=True, timeout=300)
    return ctypes.CDLL(str(out))


def test_the_folded_headers_are_the_sine_family() -> None:
    assert {"linear", "euler_rodrigues", "sine_m3", "sine_m4"} <= set(FOLDED)


@pytest.mark.parametrize("name", FOLDED)
@pytest.mark.parametrize("dtype", [np.float64, np.float32])
def test_fast2sum_complement_has_the_bits_of_two_sum_and_is_accurate(name: str, dtype: type,
                                                                    library: ctypes.CDLL) -> None:
    k2 = float(squared_edge(name))
    ctype = ctypes.c_double if dtype == np.float64 else ctypes.c_float
    function = getattr(library, f"t_{name}" + ("" if dtype == np.float64 else "_f"))
    function.argtypes = [ctypes.POINTER(ctype), ctype]
    function.restype = ctype
    vectors = fold_vectors(float(np.sqrt(k2)), dtype, np.random.default_rng(len(name)))
    assert len(vectors) > 300
    # d is high + low with low the sum of the exact error terms, each at most half an ulp of p_max²,
    # rounded in the format: its own rounding is of order ε² p_max², beyond one ulp of d only for d
    # within ~ε p_max² of 0 (float vectors can sit that close to the fold)
    epsilon = float(np.finfo(dtype).eps)
    floor = 4 * epsilon ** 2 * k2
    worst = 0.0
    for p in vectors:
        p = np.ascontiguousarray(p, dtype=dtype)
        x = (p[0] * p[0] + p[1] * p[1]) + p[2] * p[2]  # as the headers sum it, in dtype
        got = function(p.ctypes.data_as(ctypes.POINTER(ctype)), ctype(x))
        if x <= dtype(k2 / 4):
            continue  # the plain branch, k² − x
        assert got == two_sum_complement(p, k2, dtype), (name, p.tolist())
        exact = Fraction(k2) - sum(Fraction(float(c)) ** 2 for c in p)
        allowed = float(np.spacing(dtype(float(exact)))) + floor
        worst = max(worst, float(abs(Fraction(got) - exact)) / allowed)
    assert worst <= 1.0, (name, np.dtype(dtype).name, worst)


@pytest.mark.parametrize("dtype", [np.float64, np.float32])
def test_a_fold_whose_p_max_squared_is_no_float(dtype: type, tmp_path: Path) -> None:
    """(4/3) sin(3φ/4), a hypothesis function: p_max² = 16/9. The header printed
    ``sp.Integer(16/9)`` = 1 as k², so d = 1 − x: the C angle was NaN for |p| > 1 (φ > 1.13, 6 NaN
    at φ = 1.99 in the sweep) and wrong below, while NumPy printed 16/9. The compensated sum now
    starts from 16/9 as two floats (high + low), and d is within one ulp of the exact
    p_max² − |p|² up to 10⁻¹⁶ from the fold, as for the named families; the angle
    (4/3) atan2(s, √d) stays within 2 ulp of (4/3) asin(3s/4)."""
    from symrot.backends.c_backend import header_source
    from symrot.plan.builder import evaluation_plan

    plan = evaluation_plan(derive("4*sin(3*phi/4)/3").derivation, "sin_three_quarters")
    assert plan.complement == Fraction(16, 9)
    (tmp_path / "symrot_sin_three_quarters.h").write_text(header_source(plan, "sin_three_quarters"),
                                                          encoding="utf-8")
    ctype_name, suffix = ("double", "") if dtype == np.float64 else ("float", "_f")
    source = tmp_path / "fold.c"
    source.write_text('#include "symrot_sin_three_quarters.h"\n'
                      f"{ctype_name} t_d(const {ctype_name} *p, {ctype_name} x) "
                      f"{{ return symrot_sin_three_quarters__complement{suffix}(p, x); }}\n"
                      f"{ctype_name} t_angle(const {ctype_name} *p) "
                      f"{{ return symrot_sin_three_quarters_angle{suffix}(p); }}\n", encoding="utf-8")
    out = tmp_path / "fold.so"
    command = ["gcc", *c_harness.STRICT_C, "-O2", "-ffp-contract=off", f"-I{tmp_path}", "-shared", "-fPIC",
               str(source), "-o", str(out), "-lm"]
    subprocess.run(command, check=True, capture_output=True, timeout=300)
    library = ctypes.CDLL(str(out))
    ctype = ctypes.c_double if dtype == np.float64 else ctypes.c_float
    complement, angle = library.t_d, library.t_angle
    complement.argtypes, complement.restype = [ctypes.POINTER(ctype), ctype], ctype
    angle.argtypes, angle.restype = [ctypes.POINTER(ctype)], ctype
    k2 = Fraction(16, 9)
    vectors = fold_vectors(4 / 3, dtype, np.random.default_rng(43))
    assert len(vectors) > 300
    epsilon = float(np.finfo(dtype).eps)
    worst_d = worst_angle = 0.0
    for p in vectors:
        p = np.ascontiguousarray(p, dtype=dtype)
        x = (p[0] * p[0] + p[1] * p[1]) + p[2] * p[2]
        pointer = p.ctypes.data_as(ctypes.POINTER(ctype))
        exact = k2 - sum(Fraction(float(c)) ** 2 for c in p)
        if x > dtype(float(k2) / 4):
            got = Fraction(complement(pointer, ctype(x)))
            allowed = float(np.spacing(dtype(float(exact)))) + 4 * epsilon**2 * float(k2)
            worst_d = max(worst_d, float(abs(got - exact)) / allowed)
        with mpmath.workdps(60):
            s = mpmath.sqrt(sum(mpmath.mpf(float(c)) ** 2 for c in p))
            reference = 4 * mpmath.asin(3 * s / 4) / 3
            value = angle(pointer)
            worst_angle = max(worst_angle, float(abs(value - reference) / reference) / epsilon)
    assert worst_d <= 1.0 and worst_angle <= 2.0, (worst_d, worst_angle)


def test_numpy_complement_of_a_p_max_squared_that_is_no_float() -> None:
    """The NumPy module's d for (4/3) sin(3φ/4) starts from 16/9 as two floats as well: within one
    ulp of the exact p_max² − |p|² next to the fold (with the float64 of 16/9 alone, 9.9·10⁻¹⁷ off,
    the worst was 2.2·10¹⁴ ulp of d)."""
    from symrot.backends.numpy_backend import module_source
    from symrot.plan.builder import evaluation_plan

    namespace: dict[str, object] = {}
    plan = evaluation_plan(derive("4*sin(3*phi/4)/3").derivation, "sin_three_quarters")
    exec(compile(module_source(plan), "<sin_three_quarters>", "exec"), namespace)
    complement = namespace["_complement"]
    vectors = fold_vectors(4 / 3, np.float64, np.random.default_rng(34))
    got = complement(vectors)  # type: ignore[operator]
    worst = 0.0
    for p, d in zip(vectors, got, strict=True):
        exact = Fraction(16, 9) - sum(Fraction(float(c)) ** 2 for c in p)
        allowed = float(np.spacing(float(exact))) + 4 * float(np.finfo(float).eps) ** 2 * 16 / 9
        worst = max(worst, float(abs(Fraction(float(d)) - exact)) / allowed)
    assert worst <= 1.0, worst
