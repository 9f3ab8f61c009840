"""Newton in w = (φ_max − φ)^k next to the end of the range (``NewtonAngle.edge``), NumPy and C.

At an asin edge (k = 1/2: p′ → ∞ at φ_max = 1) a step of Newton in w that would overshoot past the
edge raises u = k c/δ to ``newton_start.edge_floor`` and takes the step of that u, c = u δ/k. The
C header first printed c = u*delta/1.0/2.0 for k = 1/2, i.e. u δ/2 instead of 2 u δ: hypothesis
row 187 missed in C (bench/accuracy_hypothesis.py: `angle` 1.1·10¹³ ulp next to φ = 1; here
2.2·10⁻¹⁴ off at 1 − 10⁻⁸, 200 ulp) while the NumPy module's angle was right (the shared plan, the
C printing alone). Both must give the same angle, within a few ulp of the exact one.
"""

from __future__ import annotations

import ctypes
import shutil
import subprocess
import tempfile
from functools import cache
from pathlib import Path
from typing import Any

import mpmath
import numpy as np
import pytest
import sympy as sp

from symrot.api import derive
from symrot.backends.c_backend import header_source
from symrot.backends.numpy_backend import module_source
from symrot.core.parsing import PHI, parse_expression
from symrot.plan.builder import evaluation_plan
from symrot.plan.ir import NewtonAngle

from .c_harness import STRICT_C
from .helpers import mp_function
from .reference import GeneratingFunction

EXPRESSION = "4*phi*cos(phi/3)/15 + 3*phi*cos(phi)/5 + 2*cos(phi)*asin(phi)/15"
"""Row 187 of docs/accuracy_hypothesis.md: no closed inverse, p′ → ∞ at φ_max = 1."""


@cache
def plan() -> Any:
    return evaluation_plan(derive(EXPRESSION).derivation, "edge")


@cache
def c_angle() -> Any:
    compiler = shutil.which("gcc") or shutil.which("cc")
    if compiler is None:
        pytest.skip("no C compiler")
    directory = Path(tempfile.mkdtemp())
    (directory / "symrot_edge.h").write_text(header_source(plan(), "edge"), encoding="utf-8")
    (directory / "unit.c").write_text(
        '#include "symrot_edge.h"\ndouble angle(const double p[3]) { return symrot_edge_angle(p); }\n',
        encoding="utf-8")
    library = directory / "unit.so"
    subprocess.run([compiler, *STRICT_C, "-O2", "-shared", "-fPIC", "-I", str(directory),
                    str(directory / "unit.c"), "-o", str(library), "-lm"], check=True)
    function = ctypes.CDLL(str(library)).angle
    function.restype = ctypes.c_double
    function.argtypes = [ctypes.POINTER(ctypes.c_double)]
    return function


def test_the_c_angle_next_to_an_asin_edge_is_the_numpy_modules() -> None:
    angle = plan().precisions["float64"].angle
    assert isinstance(angle, NewtonAngle) and angle.edge == sp.Rational(1, 2)  # the path under test
    namespace: dict[str, Any] = {"__name__": "edge"}
    exec(compile(module_source(plan()), "edge.py", "exec"), namespace)
    p_of = mp_function(parse_expression(EXPRESSION))
    slope = mp_function(sp.diff(parse_expression(EXPRESSION), PHI))
    reference = GeneratingFunction(EXPRESSION)
    off = {}
    for text in ("0.5", "0.9", "0.99", "0.9999", "0.99999999"):
        with mpmath.workdps(40):
            s = float(p_of(mpmath.mpf(text)))
            exact = reference.inverse(mpmath.mpf(s), None)
            width = float(abs(mpmath.mpf(s) * 2.0 ** -52 / slope(exact)))  # what one ulp of s moves φ by
        p = np.array([0.0, s, 0.0])
        c = c_angle()(p.ctypes.data_as(ctypes.POINTER(ctypes.c_double)))
        numpy_angle = float(namespace["angle"](p))
        tolerance = 4 * (np.spacing(float(exact)) + width)
        if abs(c - numpy_angle) > tolerance or abs(numpy_angle - float(exact)) > tolerance:
            off[text] = (c, numpy_angle, float(exact))
    assert not off, off
