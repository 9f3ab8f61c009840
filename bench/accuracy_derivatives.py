"""Accuracy of the derivatives of issue 19 in the generated NumPy modules (docs/accuracy.md).

For each named parameterization, ``rotation_derivative``, ``rotation_transpose_derivative``,
``tangent_derivative``, ``tangent_transpose_derivative`` and ``tangent_inverse_derivative`` of
generated/numpy/NAME.py are evaluated at p = p(φ) u for |φ| in the sweep of bench/accuracy.py
(0, log-spaced [1e-300, φ_max − 1e-6], uniform over the upper range, φ_max − 10⁻ᵏ) with random unit
axes u and random a, and ``angular_acceleration`` at random ṗ, p̈, in float64 and float32. The
reference is tests/reference.py (R from eq 1, H from ω = H ṗ, differentiated again at 150 digits),
evaluated at the rounded inputs. Error: max |D − D_ref| / (ε max |D_ref|), the worst over the sweep.
Target ≤ 8 ulp, or 8 κ ulp ("conditioned") where the radial condition number κ of the derivative
(how much the one rounding of x = |p|² moves it) exceeds 1, next to singular edges. For α = H p̈ + Ḣ ṗ
κ is the larger of its radial condition and the cancellation (|H p̈| + |Ḣ ṗ|)/|α| of its two terms
(tests/test_derivatives.py: acceleration_condition).

Corpus mode (``--corpus``, or ``--only I,J`` for entries of tests/corpus.py): each user generating
function is emitted to a NumPy module in a temporary directory through the public API, as
bench/accuracy_corpus.py does (:func:`accuracy_corpus.emit`), each in its own worker process with a
time limit, and the same six functions are measured over the same sweep (φ_max and |p|_max the
smaller of the reference's and the plan's) against the reference's p(φ) of the entry. Outputs that
are not finite inside the range are counted (verdict NaN-in-range); an emit that fails or outlasts
the limit is recorded (emit-failed, with its one-line reason) and the run goes on.

With ``--c`` (corpus mode) the same worker also emits the entry's C header (as bench/accuracy_corpus.py
does, :func:`accuracy_corpus.c_library`), compiles the derivative wrappers of tests/test_derivatives_c.py
over it with gcc -O2 -ffp-contract=off (tests/c_harness.py) and measures the six C functions (double, and
float with suffix ``_f``) at the same points against the same references, with the same verdicts; they
are reported as backend "c" (columns C double, C float; ``c_tallies`` in the JSON).

Run: ``python bench/accuracy_derivatives.py [--points N] [--names a,b]`` (prints a Markdown table);
``python bench/accuracy_derivatives.py --corpus [--only I,J] [--points N] [--out FILE.md] [--json FILE.json]
[--resume] [--timeout S] [--c]`` (--resume: entries already in the --json file are not measured again; the
file is rewritten after every entry).
"""

from __future__ import annotations

import argparse
import ctypes
import datetime
import json
import subprocess
import sys
import tempfile
import time
import warnings
from dataclasses import dataclass, field
from pathlib import Path
from types import ModuleType
from typing import Any

import mpmath
import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "bench"))

from accuracy_common import load_module as emitted_module  # noqa: E402
from accuracy_common import sweep  # noqa: E402
from accuracy_corpus import c_library, emit, one_line, run_worker  # noqa: E402

from tests.c_harness import build_config  # noqa: E402
from tests.corpus import CORPUS  # noqa: E402
from tests.reference import GeneratingFunction, Reference  # noqa: E402
from tests.test_derivatives import _as_array as _array  # noqa: E402
from tests.test_derivatives import _ulp, acceleration_condition, radial_condition  # noqa: E402
from tests.test_derivatives import load as load_module  # noqa: E402
from tests.test_derivatives_c import build as build_wrappers  # noqa: E402
from tests.test_derivatives_c import call as call_c  # noqa: E402

NAMED = {"rotation_vector": "phi", "linear": "sin(phi)", "euler_rodrigues": "2*sin(phi/2)",
         "cayley_gibbs_rodrigues": "2*tan(phi/2)", "wiener_milenkovic": "4*tan(phi/4)",
         "det_h_one": "cbrt(6*(phi - sin(phi)))", "sine_m4": "4*sin(phi/4)"}
FUNCTIONS = {"rotation_derivative": "R", "rotation_transpose_derivative": "R_T",
             "tangent_derivative": "H", "tangent_transpose_derivative": "H_T",
             "tangent_inverse_derivative": "H_inverse"}
DTYPES = {"float64": np.float64, "float32": np.float32}
TARGET_ULP = 8.0


def load(name: str) -> ModuleType:
    return load_module(ROOT / "generated" / "numpy" / f"{name}.py", f"bench_{name}")


WorstPoint = tuple[float, float, float]
"""(ulp, at φ, κ) of the worst point of one (function, precision)."""


@dataclass
class Swept:
    """The worst points of one module over the sweep, its non-finite outputs and errors."""

    worst: dict[tuple[str, str], WorstPoint] = field(default_factory=dict)
    nonfinite: dict[tuple[str, str], int] = field(default_factory=dict)
    points: dict[tuple[str, str], int] = field(default_factory=dict)
    errors: list[str] = field(default_factory=list)


def measure(name: str, points: int, seed: int = 19) -> dict[tuple[str, str], WorstPoint]:
    """{(function, precision): (ulp, at φ, κ)} at the worst ulp/κ; NaN inside the range counts as inf.
    κ (radial condition of the derivative, tests/test_derivatives.py) is measured only where ulp > 8."""
    return measure_module(load(name), GeneratingFunction(NAMED[name]), points, seed)["numpy"].worst


def measure_module(module: ModuleType, function: GeneratingFunction, points: int, seed: int = 19,
                   phi_max: float | None = None, p_max: float | None = None, strict: bool = True,
                   c: tuple[ctypes.CDLL, str] | None = None) -> dict[str, Swept]:
    """The sweep of :func:`measure` for any emitted module of ``function`` (φ_max, |p|_max: the
    reference's unless given), {backend: Swept}. ``strict``: a floating-point warning or an exception
    stops the sweep (the named parameterizations); otherwise it is recorded, the outputs count as
    non-finite and a point whose reference fails is skipped (the corpus). ``c``: (library of the
    wrappers of tests/test_derivatives_c.py, header name) of the same plan, measured as backend "c" at
    the same points against the same references (κ computed once per point and function)."""
    reference = Reference(function)
    rng = np.random.default_rng(seed)
    phi_max = float(function.phi_max) if phi_max is None else phi_max
    p_max = float(function.p_max()) if p_max is None else p_max
    backends = {"numpy": Swept(), **({"c": Swept()} if c is not None else {})}
    swept = backends["numpy"]
    for angle in sweep(min(phi_max, 4 * np.pi), points):
        axis = rng.normal(size=3)
        axis /= np.linalg.norm(axis)
        a, pdot, pddot = (rng.normal(size=3) for _ in range(3))
        with mpmath.workdps(40):
            size = float(function.value(mpmath.mpf(angle)))
        for label, dtype in DTYPES.items():
            p = (size * axis).astype(dtype)
            if float(np.linalg.norm(p.astype(np.float64))) >= p_max * (1 - 4 * float(np.finfo(dtype).eps)):
                continue  # rounded onto the edge of the range: NaN by design
            if angle > 0 and not np.any(p):
                continue  # underflows to p = 0 in this precision
            suffix = "64" if dtype is np.float64 else "32"
            wide = p.astype(np.float64)
            if float(wide @ wide) >= float(module._DERIVATIVE_X_LIMIT[suffix]):
                continue  # beyond the documented domain of unbounded p: NaN by design
            ins = [v.astype(dtype) for v in (a, pdot, pddot)]
            exact = [list(v.astype(np.float64)) for v in (p, *ins)]
            outputs = {"numpy": _evaluate(module, p, ins, strict, swept.errors, f"{label} φ={angle:.3g}")}
            if c is not None:
                outputs["c"] = _evaluate_c(*c, p, ins)
            try:
                refs = {f: _array(reference.derivative(exact[0], exact[1], t)) for f, t in FUNCTIONS.items()}
                _, alpha = reference.along(exact[0], exact[2], exact[3])
            except Exception as error:
                if strict:
                    raise
                swept.errors.append(f"reference {label} φ={angle:.3g}: {one_line(error)}")
                continue
            refs["angular_acceleration"] = np.array([float(v) for v in alpha])
            kappas: dict[str, float] = {}
            for backend, values in outputs.items():
                tally = backends[backend]
                for f, value in values.items():
                    key = (f, label)
                    tally.points[key] = tally.points.get(key, 0) + 1
                    finite = bool(np.all(np.isfinite(value)))
                    if not finite:
                        tally.nonfinite[key] = tally.nonfinite.get(key, 0) + 1
                    ulp = _ulp(value, refs[f], dtype)
                    kappa = 1.0
                    if ulp > TARGET_ULP and (finite or strict):
                        if f not in kappas:
                            kappas[f] = _condition(reference, f, exact, refs[f])
                        kappa = kappas[f]
                    worst = tally.worst
                    if ulp / kappa >= worst.get(key, (-1.0, 0.0, 1.0))[0] / worst.get(key, (0, 0, 1.0))[2]:
                        worst[key] = (ulp, float(angle), kappa)
    return backends


def _condition(reference: Reference, f: str, exact: list[list[float]], ref: np.ndarray) -> float:
    """κ of ``f`` at p, a, ṗ, p̈ = ``exact``, at least 1: the radial condition next to a singular edge;
    for α, the larger of it and the cancellation of its terms."""
    p = np.array(exact[0])
    if f in FUNCTIONS:
        return max(1.0, radial_condition(reference, p, np.array(exact[1]), FUNCTIONS[f], ref))
    return max(1.0, acceleration_condition(reference, p, np.array(exact[2]), np.array(exact[3]), ref))


def _evaluate_c(library: ctypes.CDLL, header: str, p: np.ndarray, ins: list[np.ndarray]
                ) -> dict[str, np.ndarray]:
    """The six C derivative functions of ``header`` at one point, in the precision of ``p``."""
    precision = "double" if p.dtype == np.float64 else "float"
    values: dict[str, np.ndarray] = {}
    for f in (*FUNCTIONS, "angular_acceleration"):
        inputs = (p, ins[1], ins[2]) if f == "angular_acceleration" else (p, ins[0])
        (out,), _ = call_c(library, header, f, precision, *inputs)
        values[f] = out.reshape(3) if f == "angular_acceleration" else out.reshape(3, 3)
    return values


def _evaluate(module: ModuleType, p: np.ndarray, ins: list[np.ndarray], strict: bool, errors: list[str],
              where: str) -> dict[str, np.ndarray]:
    """The six derivative functions at one point (see :func:`measure_module` for ``strict``)."""
    def call(f: str) -> np.ndarray:
        return module.angular_acceleration(p, ins[1], ins[2]) if f == "angular_acceleration" \
            else getattr(module, f)(p, ins[0])

    values: dict[str, np.ndarray] = {}
    with warnings.catch_warnings(), np.errstate(**({} if strict else {"all": "ignore"})):
        warnings.simplefilter("error" if strict else "ignore")
        for f in (*FUNCTIONS, "angular_acceleration"):
            try:
                values[f] = call(f)
            except Exception as error:  # a raising kernel is a measured failure (corpus mode)
                if strict:
                    raise
                errors.append(f"{f} {where}: {one_line(error)}")
                values[f] = np.full(3 if f == "angular_acceleration" else (3, 3), np.nan)
    return values


def table(results: dict[str, dict[tuple[str, str], tuple[float, float, float]]]) -> str:
    lines = ["| parameterization | function | float64 ulp (at φ; κ) | ulp/κ | float32 ulp (at φ; κ) | ulp/κ "
             "| verdict |",
             "|---|---|---|---|---|---|---|"]
    for name, worst in results.items():
        for f in (*FUNCTIONS, "angular_acceleration"):
            cells = [worst.get((f, label)) for label in DTYPES]
            text = []
            for c in cells:
                text += [f"{c[0]:.3g} ({c[1]:.3g}; κ {c[2]:.2g})", f"{c[0] / c[2]:.3g}"] if c else ["—", "—"]
            raw = all(c is None or c[0] <= TARGET_ULP for c in cells)
            scaled = all(c is None or c[0] / c[2] <= TARGET_ULP for c in cells)
            verdict = "meets" if raw else ("conditioned" if scaled else "misses")
            lines.append(f"| {name} | {f} | {' | '.join(text)} | {verdict} |")
    return "\n".join(lines) + "\n"


# -- the user-function corpus (tests/corpus.py) --------------------------------------------------------

ALL_FUNCTIONS = (*FUNCTIONS, "angular_acceleration")
WORKER_TIMEOUT = 900.0
"""Seconds for one corpus entry, emit and sweep (the emits of docs/accuracy_corpus.md take 8–35 s)."""
GOOD = ("meets", "conditioned")
SEVERITY = ("meets", "conditioned", "misses", "NaN-in-range")


def commit() -> str:
    """The checked-out commit of this tree (short), with ``+uncommitted`` when symrot/, bench/ or tests/
    differ from it."""
    def git(*words: str) -> str:
        return subprocess.run(["git", "-C", str(ROOT), *words], capture_output=True, text=True,
                              check=False).stdout.strip()
    dirty = git("status", "--porcelain", "--untracked-files=no", "symrot", "bench", "tests")
    return (git("rev-parse", "--short", "HEAD") or "unknown") + ("+uncommitted" if dirty else "")


def corpus_worker(index: int, points: int, with_c: bool = False) -> dict[str, Any]:
    """Emit corpus entry ``index`` (and its C header, ``with_c``) and sweep its derivatives; a JSON-ready
    result (emit failures included). Progress goes to standard error (the last line says where a
    timed-out worker was)."""
    entry = CORPUS[index]
    result: dict[str, Any] = {"index": index, "expression": entry.expression, "category": entry.category,
                              "edge": entry.edge, "closed_inverse": entry.closed_inverse, "commit": commit()}
    function = entry.generating_function()
    result["phi_max_reference"] = float(function.phi_max)
    print("in the emit", file=sys.stderr, flush=True)
    with tempfile.TemporaryDirectory() as tmp:
        try:
            plan, _source, seconds = emit(function.expression, f"corpus_{index:02d}")
            module = emitted_module(plan, Path(tmp))
        except Exception as error:  # any exception of the emit is the measurement
            result["emit_error"] = one_line(error)
            return result
        result["emit_seconds"] = seconds
        result["phi_max_plan"] = float(plan.phi_max)
        c = None
        if with_c:
            print("in the C emit and compile", file=sys.stderr, flush=True)
            library, header, result["c"] = c_library(plan, f"corpus_{index:02d}", Path(tmp),
                                                     _derivative_library)
            c = (library, header) if library is not None and header is not None else None
        print(f"in the sweep (emitted in {seconds:.0f} s)", file=sys.stderr, flush=True)
        start = time.perf_counter()
        phi_max = min(float(function.phi_max), float(plan.phi_max))
        p_max = min(float(function.p_max()), float(plan.p_max))
        backends = measure_module(module, function, points, phi_max=phi_max, p_max=p_max, strict=False, c=c)
    swept = backends["numpy"]
    result["sweep_seconds"] = time.perf_counter() - start
    result["errors"] = swept.errors[:5]
    result["tallies"] = _tallies(swept)
    if "c" in backends:
        result["c_tallies"] = _tallies(backends["c"])
    return result


def _derivative_library(directory: Path, name: str) -> ctypes.CDLL:
    """The derivative wrappers of tests/test_derivatives_c.py over symrot_NAME.h in ``directory``,
    compiled with gcc -O2 -ffp-contract=off (tests/c_harness.py) and loaded."""
    return build_wrappers(build_config("gcc-O2-nofma"), directory, [name], directory)


def _tallies(swept: Swept) -> list[dict[str, Any]]:
    return [{"function": key[0], "precision": key[1], "ulp": ulp, "at": at, "kappa": kappa,
             "nonfinite": swept.nonfinite.get(key, 0), "points": swept.points.get(key, 0)}
            for key, (ulp, at, kappa) in swept.worst.items()]


def tally_verdict(t: dict[str, Any]) -> str:
    """meets (≤ 8 ulp), conditioned (≤ 8 κ ulp), misses, or NaN-in-range (any non-finite output)."""
    if t["nonfinite"]:
        return "NaN-in-range"
    if t["ulp"] <= TARGET_ULP:
        return "meets"
    return "conditioned" if t["ulp"] / t["kappa"] <= TARGET_ULP else "misses"


def backends(with_c: bool) -> tuple[str, ...]:
    return ("numpy", "c") if with_c else ("numpy",)


TALLIES = {"numpy": "tallies", "c": "c_tallies"}
"""backend → the key of its tallies in a corpus result."""
TITLES = {("numpy", "float64"): "NumPy float64", ("numpy", "float32"): "NumPy float32",
          ("c", "float64"): "C double", ("c", "float32"): "C float"}
"""Column titles of a report with the C backend (without it: the precision)."""


def entry_verdict(result: dict[str, Any], label: str, backend: str = "numpy") -> str:
    """The worst verdict of the six functions of one entry in one precision and backend (emit-failed,
    or incomplete when a function has no measured point)."""
    if TALLIES[backend] not in result:
        return "emit-failed"
    mine = {t["function"]: tally_verdict(t) for t in result[TALLIES[backend]] if t["precision"] == label}
    if set(mine) != set(ALL_FUNCTIONS):
        return "incomplete"
    return max(mine.values(), key=SEVERITY.index)


def _failure(result: dict[str, Any]) -> str:
    return _escape(str(result.get("emit_error") or result.get("worker_error") or "no result"))


def _escape(text: str) -> str:
    """``text`` fit for a Markdown table cell."""
    return text.replace("|", "\\|")


def corpus_report(results: list[dict[str, Any]], command: str, points: int, with_c: bool = False) -> str:
    """The Markdown report of a corpus run: header, summary per entry, every function, the misses
    (``with_c``: the C backend as well, in columns C double and C float)."""
    columns = [(b, label) for b in backends(with_c) for label in DTYPES]
    title = {key: TITLES[key] if with_c else key[1] for key in columns}
    measured = sorted({r["commit"] for r in results if "commit" in r})
    verdicts = {r["index"]: {key: entry_verdict(r, key[1], key[0]) for key in columns} for r in results}
    per = {key: sum(v[key] in GOOD for v in verdicts.values()) for key in columns}
    both = {b: sum(all(v[(b, label)] in GOOD for label in DTYPES) for v in verdicts.values())
            for b in backends(with_c)}
    n = len(results)
    f64, f32 = per[("numpy", "float64")], per[("numpy", "float32")]
    summary = (f"**Summary**: {both['numpy']} of {n} entries meet the target (meets or conditioned, all six "
               f"functions, no NaN) in both precisions; float64: {f64} of {n}, float32: {f32} of {n}.")
    if with_c:
        every = sum(all(c in GOOD for c in v.values()) for v in verdicts.values())
        summary = (f"**Summary** (entries meeting the target: meets or conditioned, all six functions, no "
                   f"NaN): NumPy {both['numpy']} of {n} in both precisions (float64 {f64}, float32 {f32}); "
                   f"C {both['c']} of {n} in both (double {per[('c', 'float64')]}, float "
                   f"{per[('c', 'float32')]}); NumPy and C, both precisions: {every} of {n}.")
    lines = ["# Accuracy of the derivatives of issue 19 for the user-function corpus", "",
             f"Produced by `{command}` at commit {commit()} on {datetime.date.today().isoformat()}"
             + (f" (entries measured at {', '.join(measured)})" if measured else "")
             + ": each entry of tests/corpus.py emitted to a NumPy module " + (
                 "and a C header (gcc -O2 -ffp-contract=off, double and float) " if with_c else "") +
             "through the public API (as bench/accuracy_corpus.py does), its six derivative functions swept "
             f"as bench/accuracy_derivatives.py sweeps the named parameterizations (`accuracy.sweep(φ_max, "
             f"{points})` with p = 0 and 1e-300, random unit axes and a, ṗ, p̈; float64 and float32; φ_max "
             "and |p|_max the smaller of the reference's and the plan's) against the 60-digit reference of "
             "tests/reference.py (differentiated again at 150 digits). Error: max |D − D_ref| / (ε max "
             f"|D_ref|) at the worst point (the worst ulp/κ). *meets*: ≤ {TARGET_ULP:g} ulp; *conditioned*: "
             f"≤ {TARGET_ULP:g} κ ulp, κ the radial condition number (for α also the cancellation of H p̈ and "
             "Ḣ ṗ), computed only where the error exceeds 8 ulp; *misses* otherwise; *NaN-in-range*: a "
             "non-finite output inside the range.", "", summary, "", "## Entries", "",
             "| # | p(φ) | edge | emit s | " + ("C emit s | " if with_c else "")
             + "sweep s | φ_max ref / plan | " + " | ".join(title[key] for key in columns) + " |",
             "|---|---|---|---|---|---|" + "---|" * (len(columns) + with_c)]
    for r in results:
        head = f"| {r['index']} | `{r['expression']}` | {r.get('edge', '')} | "
        if "tallies" not in r:
            lines.append(head + f"emit-failed: {_failure(r)} | " + ("— | " if with_c else "") + "— | "
                         f"{r.get('phi_max_reference', 0):.6g} / — | "
                         + " | ".join(["emit-failed"] * len(columns)) + " |")
            continue
        c_emit = ""
        if with_c:
            c = r.get("c", {})
            c_emit = (f"{c['emit_seconds']:.1f}" if "emit_seconds" in c else "—") \
                + (f", failed: {_escape(c['error'])}" if "error" in c else "") + " | "
        cells = [verdicts[r["index"]][key] for key in columns]
        cells = [c if c in GOOD else f"**{c}**" for c in cells]
        lines.append(head + f"{r['emit_seconds']:.1f} | {c_emit}{r['sweep_seconds']:.0f} | "
                     f"{r['phi_max_reference']:.6g} / {r['phi_max_plan']:.6g} | {' | '.join(cells)} |")
    misses = []
    lines += ["", "## Every function", "",
              "| # | function | " + " | ".join(f"{title[k]} ulp (at φ; κ) | {title[k]}" for k in columns)
              + " |",
              "|---|---|" + "---|---|" * len(columns)]
    for r in results:
        if "tallies" not in r:
            lines.append(f"| {r['index']} | all | emit-failed: {_failure(r)} | emit-failed | "
                         + " | ".join(["—", "emit-failed"] * (len(columns) - 1)) + " |")
            continue
        by_key = {(backend, t["function"], t["precision"]): t for backend in ("numpy", "c")
                  for t in r.get(TALLIES[backend], [])}
        for f in ALL_FUNCTIONS:
            cells = []
            for backend, label in columns:
                t = by_key.get((backend, f, label))
                if t is None:
                    cells += ["—", "—"]
                    continue
                nan = f"; {t['nonfinite']} NaN" if t["nonfinite"] else ""
                v = tally_verdict(t)
                cells += [f"{t['ulp']:.3g} ({t['at']:.8g}; κ {t['kappa']:.2g}{nan})",
                          v if v in GOOD else f"**{v}**"]
                if v not in GOOD:
                    misses.append(f"| {r['index']} | `{r['expression']}` | {f} | {title[(backend, label)]} | "
                                  f"{t['ulp']:.3g} | {t['at']:.8g} | {t['kappa']:.2g} | {v} |")
            lines.append(f"| {r['index']} | {f} | {' | '.join(cells)} |")
    lines += ["", "## Misses", "", "| # | p(φ) | function | precision | ulp | at φ | κ | verdict |",
              "|---|---|---|---|---|---|---|---|", *misses]
    errors = [f"- {r['index']}: " + "; ".join(r["errors"]) for r in results if r.get("errors")]
    if errors:
        lines += ["", "Recorded kernel or reference errors (first five per entry):", "", *errors]
    return "\n".join(lines) + "\n"


def corpus_main(args: argparse.Namespace, argv: list[str]) -> int:
    """Every entry of ``--only`` (or all) in its own worker process; the report to --out (or printed)."""
    indices = [int(i) for i in args.only.split(",")] if args.only else list(range(len(CORPUS)))
    done: dict[int, dict[str, Any]] = {}
    if args.resume and args.json and Path(args.json).exists():
        done = {r["index"]: r for r in json.loads(Path(args.json).read_text(encoding="utf-8"))
                if "worker_error" not in r and (not args.c or "c" in r or "tallies" not in r)}
    for index in indices:
        if index in done:
            continue
        start = time.perf_counter()
        command = [sys.executable, __file__, "--worker", str(index), "--points", str(args.points)]
        result = run_worker(command + (["--c"] if args.c else []), index, args.timeout)
        if "worker_error" in result:
            result["emit_error"] = result["worker_error"]
        done[index] = result
        found = [entry_verdict(result, label, backend) for backend in backends(args.c)
                 for label in DTYPES]
        print(f"{index} {CORPUS[index].expression}: {time.perf_counter() - start:.0f} s "
              f"{' / '.join(found)} {result.get('emit_error') or ''}", flush=True)
        if args.json:
            raw = json.dumps([done[i] for i in sorted(done)], indent=1)
            Path(args.json).write_text(raw, encoding="utf-8")
    results = [done[i] for i in sorted(done) if i in indices or args.resume]
    command = "python bench/accuracy_derivatives.py " + " ".join(argv)
    text = corpus_report(results, command.strip(), args.points, args.c)
    if args.out:
        Path(args.out).write_text(text, encoding="utf-8")
    else:
        print(text, end="")
    return 0 if all(entry_verdict(r, label, b) in GOOD for r in results for label in DTYPES
                    for b in backends(args.c)) else 1


def main(argv: list[str] | None = None) -> int:
    argv = sys.argv[1:] if argv is None else argv
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--points", type=int, default=12)
    parser.add_argument("--names", default=",".join(NAMED))
    parser.add_argument("--corpus", action="store_true", help="the user-function corpus (tests/corpus.py)")
    parser.add_argument("--only", help="corpus mode, these entries only: indices of tests/corpus.py, I,J,...")
    parser.add_argument("--out", help="corpus mode: write the Markdown report here (default: print it)")
    parser.add_argument("--json", help="corpus mode: the raw results, rewritten after every entry")
    parser.add_argument("--resume", action="store_true",
                        help="corpus mode: take the entries already in --json, do not measure them again")
    parser.add_argument("--timeout", type=float, default=WORKER_TIMEOUT,
                        help="corpus mode: seconds per entry")
    parser.add_argument("--c", action="store_true",
                        help="corpus mode: the C derivative functions as well (gcc -O2 -ffp-contract=off)")
    parser.add_argument("--worker", type=int, help=argparse.SUPPRESS)
    args = parser.parse_args(argv)
    if args.worker is not None:
        print(json.dumps(corpus_worker(args.worker, args.points, args.c)))
        return 0
    if args.corpus or args.only:
        return corpus_main(args, argv)
    results = {name: measure(name, args.points) for name in args.names.split(",")}
    print(table(results), end="")
    return 0 if all(v[0] / v[2] <= TARGET_ULP for worst in results.values() for v in worst.values()) else 1


if __name__ == "__main__":
    raise SystemExit(main())
