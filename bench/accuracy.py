"""Accuracy of the generated NumPy kernels against mpmath (issue 4).

For each parameterization, every public function of its generated module is evaluated at
p = p(φ) u for |φ| ∈ {0} ∪ log-spaced [1e-300, φ_max − 1e-6] with random unit axes u, in float64
and float32, and compared with a 50-digit mpmath reference computed at the *rounded* input p.
Reference: for x = |p|² < 1e-4 the exact rational series in x (24 terms, truncation < 1e-90
relative), else the closed forms at φ = p⁻¹(|p|) found by mpmath.findroot.  Errors in ulp:
matrices max|M − M_ref| / (ε · max(1, max|M_ref|)); vectors and scalars max|v − v_ref| /
(ε · max|v_ref|).  Target ≤ 4 ulp.  The "naive" column evaluates the same closed forms in φ with
no branch (φ from the generated ``angle``): what a direct transcription of the formulas gives.

Run: ``python bench/accuracy.py [--points N] [--out docs/accuracy.md]``.
"""

from __future__ import annotations

import argparse
import importlib.util
import sys
import tempfile
import warnings
from pathlib import Path
from types import ModuleType
from typing import Any

import mpmath
import numpy as np
import sympy as sp

from symrot.api import derive
from symrot.backends.numpy_backend import module_source, numpy_function
from symrot.core import Derivation
from symrot.functions import mpmath_namespace
from symrot.parsing import PHI
from symrot.plan import EvaluationPlan, evaluation_plan
from symrot.registry import NAMED

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


def _ulp(value: np.ndarray, reference: Any, epsilon: float, matrix: bool, tiny: float) -> float:
    ref = np.array([[float(reference[i, j]) for j in range(3)] for i in range(3)]) if matrix else \
        np.array([float(v) for v in reference])
    # subnormal results cannot carry 4 eps relative accuracy: scale by at least the smallest normal
    scale = max(1.0, float(np.max(np.abs(ref)))) if matrix else max(tiny, float(np.max(np.abs(ref))))
    error = float(np.max(np.abs(value.astype(np.float64) - ref)))
    if not np.isfinite(error):
        return float("inf")
    if scale == 0:
        return 0.0 if error == 0 else float("inf")
    return error / (scale * epsilon)


def measure(name: str, points: int, seed: int = 1, edge: float = 1e-6
            ) -> dict[tuple[str, str, str], tuple[float, float]]:
    """{(function, precision, kind): (worst ulp, phi where)} with kind 'plan' or 'naive'."""
    derivation = derive(name).derivation
    plan = evaluation_plan(derivation, name)
    reference = Reference(derivation)
    naive = {n: numpy_function(e) for n, e in derivation.simplified_coefficients().items()}
    top = plan.phi_max - edge
    angles = np.concatenate([[0.0], np.geomspace(1e-300, top, points)])
    rng = np.random.default_rng(seed)
    worst: dict[tuple[str, str, str], tuple[float, float]] = {}
    with tempfile.TemporaryDirectory() as tmp, mpmath.workdps(DIGITS):
        module = load_module(plan, Path(tmp))
        for angle in angles:
            axis = rng.normal(size=3)
            axis /= np.linalg.norm(axis)
            w = rng.normal(size=3)
            extra = int(3 * max(0.0, -np.log10(angle))) if angle > 0 else 0
            with mpmath.workdps(DIGITS + extra):  # p(φ) may cancel to O(φ³) (eq 35)
                p_exact = float(reference.p_of_phi(mpmath.mpf(angle))) * axis
            for label, dtype in DTYPES.items():
                epsilon = float(np.finfo(dtype).eps)
                p = p_exact.astype(dtype)
                p_mp = [mpmath.mpf(float(v)) for v in p]
                x = sum(v * v for v in p_mp)
                if not np.all(np.isfinite(p)):
                    continue
                if mpmath.sqrt(x) >= min(plan.p_max, reference.p_of_phi(reference.phi_max)):
                    continue  # rounding moved p outside the validity range: the module returns NaN
                c = reference.coefficients(x, float(angle) if angle > 0 else 1.0)
                phi_ref = c["__phi__"]
                w_d = w.astype(dtype)
                w_mp = [mpmath.mpf(float(v)) for v in w_d]
                with warnings.catch_warnings():
                    warnings.simplefilter("error")
                    results = _evaluate(module, p, w_d)
                refs = _references(c, p_mp, w_mp, phi_ref)
                naive_results = _naive(module, naive, p, w_d)
                for function in FUNCTIONS:
                    matrix = function in TENSORS
                    for kind, values in (("plan", results), ("naive", naive_results)):
                        if function not in values:
                            continue
                        ulp = _ulp(values[function], refs[function], epsilon, matrix,
                                   float(np.finfo(dtype).tiny))
                        ulp = float("inf") if np.isnan(ulp) else ulp
                        key = (function, label, kind)
                        if key not in worst or ulp > worst[key][0] or np.isnan(worst[key][0]):
                            worst[key] = (ulp if not np.isnan(ulp) else float("inf"), float(angle))
    return worst


def _evaluate(module: ModuleType, p: np.ndarray, w: np.ndarray) -> dict[str, np.ndarray]:
    out = {f: getattr(module, f)(p) for f in TENSORS}
    out["pdot"] = module.pdot(p, w)
    out["omega"] = module.omega(p, w)
    out["angle"] = np.atleast_1d(module.angle(p))
    out["tangent_det"] = np.atleast_1d(module.tangent_det(p))
    return out


def _references(c: dict[str, Any], p: list[Any], w: list[Any], phi: Any) -> dict[str, Any]:
    refs: dict[str, Any] = {f: _tensor(c, t, p) for f, t in TENSORS.items()}
    for f, t in VECTORS.items():
        refs[f] = _tensor(c, t, p) * mpmath.matrix(w)
    refs["angle"] = [phi]
    refs["tangent_det"] = [c["det_H"]]
    return refs


def _naive(module: ModuleType, naive: dict[str, Any], p: np.ndarray, w: np.ndarray) -> dict[str, np.ndarray]:
    """Closed forms in φ with no branch (errors at p = 0 are reported as inf)."""
    phi = module.angle(p)
    x = np.dot(p, p)
    out: dict[str, np.ndarray] = {}
    with np.errstate(all="ignore"), warnings.catch_warnings():
        warnings.simplefilter("ignore")
        c = {n: np.asarray(f(phi), dtype=p.dtype) * np.ones((), dtype=p.dtype) for n, f in naive.items()}
        cross = np.array([[0, -p[2], p[1]], [p[2], 0, -p[0]], [-p[1], p[0], 0]], dtype=p.dtype)
        for f, t in TENSORS.items():
            out[f] = (c[t + "_0"] - c[t + "_2"] * x) * np.eye(3, dtype=p.dtype) + c[t + "_1"] * cross + \
                c[t + "_2"] * np.outer(p, p)
        for f, t in VECTORS.items():
            out[f] = out[TENSORS_BY_NAME[t]] @ w
        out["tangent_det"] = np.atleast_1d(c["det_H"])
    return out


TENSORS_BY_NAME = {t: f for f, t in TENSORS.items()}


def table(results: dict[str, dict[tuple[str, str, str], tuple[float, float]]]) -> str:
    lines = ["| parameterization | function | float64 ulp (at φ) | naive float64 | float32 ulp (at φ) "
             "| naive float32 |", "|---|---|---|---|---|---|"]
    for name, worst in results.items():
        for function in FUNCTIONS:
            cells = []
            for label in DTYPES:
                for kind in ("plan", "naive"):
                    if (function, label, kind) not in worst:
                        cells.append("—")
                        continue
                    ulp, where = worst[(function, label, kind)]
                    mark = " **miss**" if kind == "plan" and ulp > 4 else ""
                    cells.append(f"{ulp:.3g} ({where:.3g}){mark}" if kind == "plan" else f"{ulp:.3g}")
            lines.append(f"| {name} | {function} | " + " | ".join(cells) + " |")
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser()
    parser.add_argument("--points", type=int, default=60)
    parser.add_argument("--only", nargs="*")
    parser.add_argument("--out", default="docs/accuracy.md")
    args = parser.parse_args(argv)
    names = args.only or default_parameterizations()
    results = {}
    for name in names:
        results[name] = measure(name, args.points)
        misses = [(k, v) for k, v in results[name].items() if k[2] == "plan" and v[0] > 4]
        print(f"{name}: worst plan ulp float64 "
              f"{max(v[0] for k, v in results[name].items() if k[1:] == ('float64', 'plan')):.3g}, "
              f"float32 {max(v[0] for k, v in results[name].items() if k[1:] == ('float32', 'plan')):.3g}; "
              f"{len(misses)} misses", flush=True)
    command = "python bench/accuracy.py " + " ".join(argv if argv is not None else sys.argv[1:])
    text = ("# Accuracy of the generated NumPy kernels\n\n"
            f"Produced by `{command.strip()}` ({args.points} log-spaced angles in "
            "[1e-300, φ_max − 1e-6] plus 0, "
            "random axes; reference: mpmath at 50 digits at the rounded input). Worst error in ulp "
            "(matrices relative to max(1, max|entry|), vectors and scalars relative to their max entry) "
            "and the |φ| where it occurs; target ≤ 4. *naive*: the closed forms in φ without branches "
            "(inf = NaN/inf, typically at p = 0).\n\n" + table(results) + "\n")
    Path(args.out).parent.mkdir(parents=True, exist_ok=True)
    Path(args.out).write_text(text, encoding="utf-8")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
