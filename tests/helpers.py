"""Shared test helpers: 50-digit numeric evaluation of derived quantities."""

from __future__ import annotations

import os
import random
import subprocess
import sys
from collections.abc import Callable
from pathlib import Path

import mpmath
import sympy as sp

from symrot.core.axial import AxialTensor
from symrot.core.functions import mpmath_namespace
from symrot.core.parsing import PHI

DIGITS = 50


def mp_function(expr: sp.Expr) -> Callable[[mpmath.mpf], mpmath.mpf]:
    """``expr`` (in φ) as an mpmath function."""
    return sp.lambdify(PHI, expr, modules=[mpmath_namespace(), "mpmath"])


def skew(v: mpmath.matrix) -> mpmath.matrix:
    return mpmath.matrix([[0, -v[2], v[1]], [v[2], 0, -v[0]], [-v[1], v[0], 0]])


def axial_matrix(tensor: AxialTensor, angle: mpmath.mpf, axis: mpmath.matrix) -> mpmath.matrix:
    """a I + b (u×) + c (u×)² at φ = angle, u = axis (unit), at working precision."""
    a, b, c = (mp_function(e)(angle) for e in (tensor.a, tensor.b, tensor.c))
    u = skew(axis)
    return a * mpmath.eye(3) + b * u + c * u * u


def random_axis(rng: random.Random) -> mpmath.matrix:
    v = mpmath.matrix([mpmath.mpf(rng.gauss(0, 1)) for _ in range(3)])
    return v / mpmath.norm(v)


def max_abs(m: mpmath.matrix) -> mpmath.mpf:
    return max(abs(m[i, j]) for i in range(m.rows) for j in range(m.cols))


def run_symrot(*args: str, environment: dict[str, str] | None = None) -> subprocess.CompletedProcess[str]:
    """``python -m symrot *args`` (as a user runs it), with ``environment`` over this process's."""
    return subprocess.run([sys.executable, "-m", "symrot", *args], capture_output=True, text=True,
                          timeout=300, check=False, env={**os.environ, **(environment or {})})


def files(folder: Path) -> dict[str, bytes]:
    """Every file under ``folder`` by its relative path, with its bytes."""
    return {str(path.relative_to(folder)): path.read_bytes() for path in sorted(folder.rglob("*"))
            if path.is_file()}
