"""Accuracy of the generated NumPy kernels against mpmath (issue 4).

For each parameterization, every public function of its generated module is evaluated at
p = p(φ) u for |φ| ∈ {0} ∪ log-spaced [1e-300, φ_max − 1e-6] ∪ uniform [0.5, φ_max − 1e-6] ∪
{φ_max − 10⁻ᵏ, k = 1…6} (:func:`sweep`) with random unit axes u, in float64
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
import sys
import tempfile
import warnings
from pathlib import Path
from types import ModuleType
from typing import Any

import mpmath
import numpy as np

from symrot.backends.numpy_backend import numpy_function

sys.path.insert(0, str(Path(__file__).resolve().parent))

from accuracy_common import (
    DIGITS,
    DTYPES,
    FUNCTIONS,
    TARGET_ULP,
    TENSORS,
    VECTORS,
    Worst,
    _tensor,
    condition,
    default_parameterizations,
    load_module,
    subject,
    sweep,
)

from tests.measure import scale as _scale
from tests.measure import ulp as _ulp

__all__ = ["main", "measure", "summary", "table"]


def measure(name: str, points: int, seed: int = 1, edge: float = 1e-6) -> dict[tuple[str, str, str], Worst]:
    """{(function, precision, kind): Worst} with kind 'plan' or 'naive'."""
    derivation, plan, reference = subject(name)
    naive = {n: numpy_function(e) for n, e in derivation.simplified_coefficients().items()}
    angles = sweep(plan.phi_max, points, edge)
    rng = np.random.default_rng(seed)
    worst: dict[tuple[str, str, str], Worst] = {}
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
                if not np.all(np.isfinite(p)):
                    continue
                p_mp = [mpmath.mpf(float(v)) for v in p]
                edge_of_range = min(plan.p_max, reference.p_of_phi(reference.phi_max))
                if mpmath.sqrt(sum(v * v for v in p_mp)) >= edge_of_range * (1 - 2 * epsilon):
                    continue  # within 2 ulp of the edge: |p| rounds onto it and the module returns NaN
                w_d = w.astype(dtype)
                w_mp = [mpmath.mpf(float(v)) for v in w_d]
                guess = float(angle) if angle > 0 else 1.0

                def refs_at(inputs: list[Any], guess: float = guess, w_mp: list[Any] = w_mp
                            ) -> dict[str, Any]:
                    c = reference.coefficients(sum(v * v for v in inputs), guess)
                    return _references(c, inputs, w_mp, c["__phi__"])

                refs = refs_at(p_mp)
                tiny = float(np.finfo(dtype).tiny)
                scales = {f: _scale(refs[f], f in TENSORS, tiny) for f in FUNCTIONS}
                kappas = condition(refs_at, p_mp, refs, scales)
                with warnings.catch_warnings():
                    warnings.simplefilter("error")
                    results = _evaluate(module, p, w_d)
                naive_results = _naive(module, naive, p, w_d)
                for function in FUNCTIONS:
                    matrix = function in TENSORS
                    for kind, values in (("plan", results), ("naive", naive_results)):
                        if function not in values:
                            continue
                        ulp = _ulp(values[function], refs[function], epsilon, matrix, tiny)
                        worst.setdefault((function, label, kind), Worst()).add(ulp, float(angle),
                                                                               kappas[function])
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


def _cell(entry: Worst | None) -> str:
    if entry is None:
        return "—"
    return f"{entry.ulp:.3g} ({entry.at:.3g}; κ {entry.kappa:.2g})"


def _verdict(entries: list[Worst]) -> str:
    if all(e.ulp <= TARGET_ULP for e in entries):
        return "meets"
    if all(e.excess <= TARGET_ULP for e in entries):
        return "conditioned"
    return "**miss**"


def table(results: dict[str, dict[tuple[str, str, str], Worst]], functions: tuple[str, ...]) -> str:
    lines = ["| parameterization | function | float64 ulp (at φ; κ there) | ulp/κ | naive float64 "
             "| float32 ulp (at φ; κ there) | ulp/κ | naive float32 | verdict |",
             "|---|---|---|---|---|---|---|---|---|"]
    for name, worst in results.items():
        for function in functions:
            cells, plans = [], []
            for label in DTYPES:
                plan = worst.get((function, label, "plan"))
                naive = worst.get((function, label, "naive"))
                cells += [_cell(plan), f"{plan.excess:.3g}" if plan else "—",
                          f"{naive.ulp:.3g}" if naive else "—"]
                plans += [plan] if plan else []
            if plans:
                lines.append(f"| {name} | {function} | " + " | ".join(cells) + f" | {_verdict(plans)} |")
    return "\n".join(lines)


def summary(name: str, worst: dict[tuple[str, str, str], Worst]) -> str:
    plans = {k: v for k, v in worst.items() if k[2] == "plan"}
    parts = []
    for label in DTYPES:
        mine = [v for k, v in plans.items() if k[1] == label]
        parts.append(f"{label} worst {max(v.ulp for v in mine):.3g} ulp, "
                     f"worst ulp/κ {max(v.excess for v in mine):.3g}")
    misses = sum(v.excess > TARGET_ULP for v in plans.values())
    return f"{name}: " + "; ".join(parts) + f"; {misses} misses"


def main(argv: list[str] | None = None) -> int:
    from accuracy_operations import OPERATIONS, measure_operations

    parser = argparse.ArgumentParser()
    parser.add_argument("--points", type=int, default=60)
    parser.add_argument("--only", nargs="*")
    parser.add_argument("--out", help="default docs/accuracy.md (--corpus: docs/accuracy_corpus.md)")
    parser.add_argument("--corpus", action="store_true",
                        help="measure the user generating functions of tests/corpus.py instead "
                             "(bench/accuracy_corpus.py; its other options follow)")
    args, rest = parser.parse_known_args(argv)
    if args.corpus:
        from accuracy_corpus import main as corpus_main

        points = ["--points", str(args.points)] if args.points != parser.get_default("points") else []
        only = ["--only", *args.only] if args.only else []
        return corpus_main([*rest, *points, *only, "--out", args.out or "docs/accuracy_corpus.md"])
    if rest:
        parser.error(f"unrecognized arguments: {' '.join(rest)}")
    args.out = args.out or "docs/accuracy.md"
    names = args.only or default_parameterizations()
    results, operations = {}, {}
    for name in names:
        results[name] = measure(name, args.points)
        operations[name] = measure_operations(name, args.points)
        print(summary(name, results[name]), "|", summary("operations", operations[name]), flush=True)
    command = "python bench/accuracy.py " + " ".join(argv if argv is not None else sys.argv[1:])
    text = ("# Accuracy of the generated NumPy kernels\n\n"
            f"Produced by `{command.strip()}` (|φ| = 0, {args.points} log-spaced angles in "
            f"[1e-300, φ_max − 1e-6], {max(2, args.points // 3)} uniform in [0.5, φ_max − 1e-6] and "
            "φ_max − 10⁻ᵏ for k = 1…6, random axes; reference: mpmath at 50 digits at the "
            "rounded input; inputs within 2 ulp of the edge of the range, which the kernels may "
            "classify as outside it, are skipped).\n\n"
            "Worst error in ulp (matrices relative to max(1, max|entry|), vectors and scalars relative "
            "to their largest entry), the |φ| where it occurs and κ there: the relative condition "
            "number of the output with respect to componentwise relative changes of the input "
            "(50-digit differences). *ulp/κ* is the worst of error / max(1, κ) over the sweep. "
            f"Verdict: *meets* — every error ≤ {TARGET_ULP:g} ulp; *conditioned* — some error exceeds "
            f"{TARGET_ULP:g} ulp but never {TARGET_ULP:g} κ ulp, i.e. never more than a "
            f"{TARGET_ULP:g} ε relative change of the input p itself causes (the input is ill-conditioned "
            "there: near the edge of the range, a function that vanishes or blows up); *miss* — "
            "neither. *naive*: the closed forms in φ without branches (inf = NaN/inf, typically at "
            "p = 0).\n\n## Kinematic functions (issue 4)\n\n" + table(results, FUNCTIONS)
            + "\n\n## Operations on rotations of any size (issue 6)\n\n" + table(operations, OPERATIONS)
            + "\n")
    Path(args.out).parent.mkdir(parents=True, exist_ok=True)
    Path(args.out).write_text(text, encoding="utf-8")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
