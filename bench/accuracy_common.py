"""What bench/accuracy.py and the sweeps beside it share: the 50-digit reference of a derivation,
the angle sweep and the emitted module of a plan (issue 56: shared code below the drivers, so that
bench/ has no import cycle; accuracy.py, accuracy_corpus.py, accuracy_operations.py and
accuracy_derivatives.py import from here, never from each other's drivers).
"""

from __future__ import annotations

import importlib.util
import sys
from pathlib import Path
from types import ModuleType
from typing import Any

import mpmath
import numpy as np
import sympy as sp

from symrot.api import derive
from symrot.backends.numpy_backend import module_source
from symrot.core.derivation import Derivation
from symrot.core.functions import mpmath_namespace
from symrot.core.parsing import PHI
from symrot.core.registry import NAMED
from symrot.plan.builder import evaluation_plan
from symrot.plan.ir import EvaluationPlan

ROOT = Path(__file__).resolve().parent.parent
if str(ROOT) not in sys.path:  # run as a script: tests/ is beside bench/
    sys.path.insert(0, str(ROOT))

from tests.measure import TARGET_ULP, Worst, condition  # noqa: E402

__all__ = ["DIGITS", "DTYPES", "TARGET_ULP", "Reference", "Worst", "condition", "load_module", "subject",
           "sweep"]

TENSORS = {"rotation_matrix": "R", "tangent": "H", "tangent_inverse": "H_inverse", "root_matrix": "G",
           "root_tangent": "K"}
VECTORS = {"pdot": "H_inverse", "omega": "H"}
SCALARS = ("angle", "tangent_det")
FUNCTIONS = (*TENSORS, *VECTORS, *SCALARS)
DTYPES = {"float64": np.float64, "float32": np.float32}
SERIES_TERMS = 24
DIGITS = 50


def default_parameterizations() -> list[str]:
    names = list(NAMED)
    names += [f"sine_m{m}" for m in range(1, 7) if f"sine_m{m}" not in names]
    names += [f"tangent_m{m}" for m in range(1, 7)]
    return names


def load_module(plan: EvaluationPlan, directory: Path) -> ModuleType:
    path = directory / f"{plan.name}.py"
    path.write_text(module_source(plan), encoding="utf-8")
    spec = importlib.util.spec_from_file_location(f"symrot_bench_{plan.name}", path)
    assert spec and spec.loader
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def _mp(c: sp.Expr) -> mpmath.mpf:
    if isinstance(c, sp.Rational):
        return mpmath.mpf(c.p) / c.q
    return mpmath.mpf(str(sp.N(c, DIGITS + 10)))


class Reference:
    """50-digit values of every coefficient at a given |p|."""

    def __init__(self, derivation: Derivation) -> None:
        self.derivation = derivation
        self.names = list(derivation.coefficient_expressions())
        self.series = {n: derivation.series_in_x(n, SERIES_TERMS) for n in self.names}
        modules = [mpmath_namespace(), "mpmath"]
        self.closed = {n: sp.lambdify(PHI, e, modules=modules)
                       for n, e in derivation.coefficient_expressions().items()}
        self.p_of_phi = sp.lambdify(PHI, derivation.p, modules=modules)
        self.phi_series = derivation.phi_of_p(2 * SERIES_TERMS)
        self.phi_max = mpmath.mpf(evaluation_plan(derivation, "reference").phi_max)

    def phi(self, s: mpmath.mpf, guess: float) -> mpmath.mpf:
        if s == 0:
            return mpmath.mpf(0)
        low = mpmath.mpf(guess) * (1 - mpmath.mpf("1e-4"))
        high = min(mpmath.mpf(guess) * (1 + mpmath.mpf("1e-4")), self.phi_max * (1 - mpmath.mpf("1e-30")))
        if self.p_of_phi(low) > s or self.p_of_phi(high) < s:
            low, high = mpmath.mpf(0), self.phi_max * (1 - mpmath.mpf("1e-30"))
        for _ in range(190):  # bisection: 50 digits whatever the slope (p' -> 0 at some phi_max)
            middle = (low + high) / 2
            low, high = (middle, high) if self.p_of_phi(middle) < s else (low, middle)
        root = (low + high) / 2
        if abs(self.p_of_phi(root) - s) > mpmath.mpf(10) ** -40 * s:
            raise ValueError(f"reference angle not found for |p| = {s}")
        return root

    def coefficients(self, x: mpmath.mpf, guess: float) -> dict[str, mpmath.mpf]:
        if x < mpmath.mpf("1e-4"):
            out = {n: mpmath.polyval([_mp(c) for c in reversed(self.series[n])], x) for n in self.names}
            out["__phi__"] = mpmath.polyval([_mp(c) for c in reversed(self.phi_series)], mpmath.sqrt(x))
            return out
        phi = self.phi(mpmath.sqrt(x), guess)
        out = {n: self.closed[n](phi) for n in self.names}
        out["__phi__"] = phi
        return out


def _tensor(c: dict[str, Any], name: str, p: list[Any]) -> mpmath.matrix:
    x = sum(v * v for v in p)
    cross = mpmath.matrix([[0, -p[2], p[1]], [p[2], 0, -p[0]], [-p[1], p[0], 0]])
    outer = mpmath.matrix(3, 3)
    for i in range(3):
        for j in range(3):
            outer[i, j] = p[i] * p[j]
    return (c[name + "_0"] - c[name + "_2"] * x) * mpmath.eye(3) + c[name + "_1"] * cross + \
        c[name + "_2"] * outer


def sweep(phi_max: float, points: int, edge: float = 1e-6) -> np.ndarray:
    """|φ|: 0, log-spaced [1e-300, φ_max − edge], uniform over the upper range and φ_max − 10⁻ᵏ."""
    top = phi_max - edge
    return np.unique(np.concatenate([
        [0.0], np.geomspace(1e-300, top, points), np.linspace(0.5, top, max(2, points // 3)),
        phi_max - np.geomspace(0.1, edge, 6)]))


def subject(name: str) -> tuple[Derivation, EvaluationPlan, Reference]:
    """The derivation, plan and 50-digit reference of one parameterization (shared by both sweeps)."""
    derivation = derive(name).derivation
    return derivation, evaluation_plan(derivation, name), Reference(derivation)
