"""Accuracy of the generated code for the user generating functions of tests/corpus.py (issue 16).

For each corpus function: emit the NumPy module (and the C header) through the public API, time
it, and compare every function it exports with the *independent* reference of tests/reference.py
(φ by Newton on p(φ), R from eq 1, H from ω = H ṗ by differentiation, ≥ 60 digits), never with
symrot's own derivation. Angles: :func:`accuracy.sweep` plus 1e-30, 1e-8, 1e-3, 0.1, 1 (float32
only from its smallest normal), random axes. Error measure, condition number κ and verdict as in
docs/accuracy.md (:mod:`accuracy`): ulp relative to max(1, max|entry|) for matrices, to the largest
entry for vectors and scalars; *meets* ≤ 4 ulp, *conditioned* ≤ 4 κ ulp, else *miss*. κ is only
computed at points where the error exceeds 4 ulp. NaN/Inf: outputs that are not finite where the
reference is (inside the validity range; inputs within 2 ulp of its edge are skipped).

Each function runs in its own worker process (``--worker INDEX``), so that an emit that hangs or
crashes is recorded, not fatal.

Run: ``python bench/accuracy_corpus.py [--points N] [--only I ...] [--no-c] [--out docs/accuracy_corpus.md]``.
"""

from __future__ import annotations

import argparse
import ctypes
import json
import subprocess
import sys
import tempfile
import time
import traceback
import warnings
from collections.abc import Callable
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Any

import mpmath
import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "bench"))

from accuracy_common import DTYPES, load_module, sweep  # noqa: E402

from tests.corpus import CORPUS  # noqa: E402
from tests.measure import TARGET_ULP, Worst, condition  # noqa: E402
from tests.measure import scale as _scale  # noqa: E402
from tests.measure import ulp as _ulp  # noqa: E402
from tests.reference import GeneratingFunction, Reference, State  # noqa: E402

MATRICES = {"rotation_matrix": "R", "tangent": "H", "tangent_inverse": "H_inverse", "root_matrix": "G",
            "root_tangent": "K"}
KINEMATIC = (*MATRICES, "pdot", "omega", "angle", "tangent_det", "to_quaternion")
OPERATIONS = ("from_quaternion", "rescale", "compose")
FUNCTIONS = (*KINEMATIC, *OPERATIONS)
FIXED_ANGLES = (1e-30, 1e-8, 1e-3, 0.1, 1.0)
WORKER_TIMEOUT = 1800
COLUMNS = (("numpy", "float64"), ("numpy", "float32"), ("c", "float64"), ("c", "float32"))


def angles(phi_max: float, points: int) -> np.ndarray:
    """The sweep of docs/accuracy.md plus the fixed small angles of issue 16, below φ_max."""
    fixed = [a for a in FIXED_ANGLES if a < phi_max - 1e-6]
    return np.unique(np.concatenate([sweep(phi_max, points), fixed]))


def kinematic(state: State, w: list[Any]) -> dict[str, Any]:
    """Reference value of every kinematic function at one p (pdot and omega applied to w)."""
    out: dict[str, Any] = {f: getattr(state, t) for f, t in MATRICES.items()}
    out["pdot"] = state.H_inverse * mpmath.matrix(w)
    out["omega"] = state.H * mpmath.matrix(w)
    out["angle"] = [state.angle]
    out["tangent_det"] = [state.det_H]
    out["to_quaternion"] = list(state.quaternion)
    return out


def module_values(module: Any, p: np.ndarray, p2: np.ndarray, w: np.ndarray, e: np.ndarray
                  ) -> dict[str, np.ndarray]:
    """Every exported function of a generated NumPy module at one point."""
    out = {f: getattr(module, f)(p) for f in MATRICES}
    out["pdot"] = module.pdot(p, w)
    out["omega"] = module.omega(p, w)
    out["angle"] = np.atleast_1d(module.angle(p))
    out["tangent_det"] = np.atleast_1d(module.tangent_det(p))
    out["to_quaternion"] = module.to_quaternion(p)
    out["from_quaternion"] = module.from_quaternion(e)
    out["rescale"] = module.rescale(p)
    out["compose"] = module.compose(p, p2)
    return out


@dataclass
class Tally:
    """Worst error and NaN/Inf count of one (function, precision, backend)."""

    worst: Worst = field(default_factory=Worst)
    nonfinite: int = 0
    points: int = 0


C_OPERATIONS: dict[str, tuple[tuple[str, ...], int]] = {
    "to_quaternion": (("p",), 4), "from_quaternion": (("e",), 3), "rescale": (("p",), 3),
    "compose": (("p", "p2"), 3)}
"""The header's quaternion operations (eqs 67, 74–75 and the rescaling of eqs 40–47): their inputs
and number of outputs. tests/c_harness.py wraps only the nine kinematic functions."""


def operation_wrappers(headers: list[str],
                       operations: dict[str, tuple[tuple[str, ...], int]] = C_OPERATIONS) -> str:
    """C source of one wrapper ``o_HEADER_NAME[_f](inputs..., out)`` per operation (default
    C_OPERATIONS: name → (inputs, number of outputs)), header and precision (the status is dropped:
    NaN says the same)."""
    lines = [f'#include "symrot_{header}.h"' for header in headers]
    for header in headers:
        for ctype, suffix in (("double", ""), ("float", "_f")):
            for name, (inputs, _width) in operations.items():
                parameters = ", ".join([*(f"const {ctype} *{i}" for i in inputs), f"{ctype} *out"])
                signature = f"void o_{header}_{name}{suffix}({parameters})"
                call = f"symrot_{header}_{name}{suffix}({', '.join(inputs)}, out)"
                lines += [f"{signature};", f"{signature} {{ (void){call}; }}"]
    return "\n".join(lines) + "\n"


def call_operation(dll: ctypes.CDLL, header: str, name: str, dtype: Any, *arrays: np.ndarray,
                   operations: dict[str, tuple[tuple[str, ...], int]] = C_OPERATIONS) -> np.ndarray:
    """Operation ``name`` of ``header`` (wrapped by :func:`operation_wrappers`) for one input (each
    array one vector), in ``dtype``."""
    inputs, width = operations[name]
    ctype = ctypes.c_double if dtype == np.float64 else ctypes.c_float
    pointer = ctypes.POINTER(ctype)
    values = [np.ascontiguousarray(a, dtype=dtype) for a in arrays]
    out = np.empty(width, dtype=dtype)
    function = getattr(dll, f"o_{header}_{name}" + ("" if dtype == np.float64 else "_f"))
    function.argtypes = [pointer] * (len(inputs) + 1)
    function.restype = None
    function(*[v.ctypes.data_as(pointer) for v in values], out.ctypes.data_as(pointer))
    return out


class COperations:
    """The quaternion operations of a compiled C header, called through ctypes (gcc -O2
    -ffp-contract=off, the configuration of the kinematic wrappers)."""

    def __init__(self, directory: Path, header: str) -> None:
        from tests.c_harness import build_config, compile_one

        self.header = header
        out_dir = directory / "operations"
        out_dir.mkdir()
        source = out_dir / "operations.c"
        source.write_text(operation_wrappers([header]), encoding="utf-8")
        self.dll = ctypes.CDLL(str(compile_one(build_config("gcc-O2-nofma"), source, directory, out_dir)))

    def call(self, name: str, dtype: Any, *arrays: np.ndarray) -> np.ndarray:
        """``name``'s outputs for one input (each array one vector), in ``dtype``."""
        return call_operation(self.dll, self.header, name, dtype, *arrays)


def _is_nan_reference(ref: Any) -> bool:
    values = [ref[i, j] for i in range(ref.rows) for j in range(ref.cols)] if isinstance(ref, mpmath.matrix) \
        else list(ref)
    return any(mpmath.isnan(v) for v in values)


def _error(value: np.ndarray, ref: Any, function: str, epsilon: float, tiny: float) -> tuple[float, bool]:
    """(ulp error, non-finite where the reference is finite)."""
    value = np.asarray(value)
    if _is_nan_reference(ref):
        return (0.0 if bool(np.all(np.isnan(value))) else float("inf")), False
    nonfinite = not bool(np.all(np.isfinite(value)))
    matrix = function in MATRICES
    shaped = value.reshape(3, 3) if matrix else value.reshape(-1)
    return _ulp(shaped, ref, epsilon, matrix, tiny), nonfinite


class Measurement:
    """The sweep of one corpus function against its reference (NumPy and, optionally, C)."""

    def __init__(self, function: GeneratingFunction, plan: Any, module: Any, library: Any,
                 header: str | None, points: int, seed: int = 16,
                 operations: COperations | None = None) -> None:
        self.operations = operations
        self.reference = Reference(function)
        self.function = function
        self.plan = plan
        self.module = module
        self.library = library
        self.header = header
        self.points = points
        self.rng = np.random.default_rng(seed)
        self.tallies: dict[tuple[str, str, str], Tally] = {}
        self.errors: list[str] = []

    def record(self, function: str, label: str, backend: str, ulp: float, nonfinite: bool,
               angle: float, kappa: Callable[[], float]) -> None:
        tally = self.tallies.setdefault((function, label, backend), Tally())
        tally.points += 1
        tally.nonfinite += int(nonfinite)
        tally.worst.add(ulp, angle, kappa() if ulp > TARGET_ULP else 1.0)

    def run(self) -> None:
        phi_max = min(float(self.function.phi_max), float(self.plan.phi_max))
        edge_p = min(float(self.plan.p_max), float(self.function.p_max()))
        with mpmath.workdps(60):  # condition() perturbs inputs by 1e-30 at the ambient precision
            self._run(phi_max, edge_p)

    def _run(self, phi_max: float, edge_p: float) -> None:
        for angle in angles(phi_max, self.points):
            axes = self.rng.normal(size=(3, 3))
            axes /= np.linalg.norm(axes, axis=1)[:, None]
            with mpmath.workdps(40):
                size = float(self.function.value(mpmath.mpf(angle)))
                half = mpmath.mpf(angle) / 2
                e_exact = [float(mpmath.cos(half))] + [float(mpmath.sin(half) * a) for a in axes[2]]
            flip = -1.0 if self.rng.random() < 0.5 else 1.0
            for label, dtype in DTYPES.items():
                epsilon, tiny = float(np.finfo(dtype).eps), float(np.finfo(dtype).tiny)
                if 0 < angle < tiny:
                    continue
                p, p2 = (size * axes[0]).astype(dtype), (size * axes[1]).astype(dtype)
                if max(np.linalg.norm(p.astype(np.float64)), np.linalg.norm(p2.astype(np.float64))) >= \
                        edge_p * (1 - 2 * epsilon) or not np.all(np.isfinite(p)):
                    continue
                w = self.rng.normal(size=3).astype(dtype)
                e = (flip * np.array(e_exact)).astype(dtype)
                self.point(float(angle), label, dtype, p, p2, w, e)

    def point(self, angle: float, label: str, dtype: Any, p: np.ndarray, p2: np.ndarray, w: np.ndarray,
              e: np.ndarray) -> None:
        epsilon, tiny = float(np.finfo(dtype).eps), float(np.finfo(dtype).tiny)
        guess = angle if angle > 0 else None
        p_mp = [mpmath.mpf(float(v)) for v in p]
        p2_mp = [mpmath.mpf(float(v)) for v in p2]
        w_mp = [mpmath.mpf(float(v)) for v in w]
        e_mp = [mpmath.mpf(float(v)) for v in e]

        def kinematic_at(inputs: list[Any]) -> dict[str, Any]:
            return kinematic(self.reference.state(inputs, guess), w_mp)

        refs = kinematic_at(p_mp)
        refs["from_quaternion"] = self.reference.from_quaternion(e_mp)
        refs["rescale"] = self.reference.rescale(p_mp, guess)
        refs["compose"] = self.reference.compose(p_mp, p2_mp, (guess, guess))
        kappas: dict[str, float] = {}

        def kappa(function: str) -> Callable[[], float]:
            def compute() -> float:
                if function not in kappas:
                    kappas.update(self.condition(function, refs, kinematic_at, p_mp, p2_mp, e_mp, guess,
                                                 tiny))
                return kappas[function]
            return compute

        with warnings.catch_warnings(), np.errstate(all="ignore"):
            warnings.simplefilter("ignore")
            try:
                values = module_values(self.module, p, p2, w, e)
            except Exception as error:  # a raising kernel is a measured failure
                values = {f: np.full(9, np.inf) for f in FUNCTIONS}
                self.errors.append(f"{label} φ={angle:.3g}: {type(error).__name__}: {error}")
        for function in FUNCTIONS:
            ulp, nonfinite = _error(values[function], refs[function], function, epsilon, tiny)
            self.record(function, label, "numpy", ulp, nonfinite, angle, kappa(function))
        if self.library is not None:
            from tests.c_harness import FUNCTIONS as C_FUNCTIONS

            precision = "double" if label == "float64" else "float"
            for spec in C_FUNCTIONS:
                got = self.library.call(self.header, spec, precision, p[None, :], w[None, :])[0]
                ulp, nonfinite = _error(got, refs[spec.name], spec.name, epsilon, tiny)
                self.record(spec.name, label, "c", ulp, nonfinite, angle, kappa(spec.name))
        if self.operations is not None:
            inputs = {"p": p, "e": e, "p2": p2}
            for name, (names, _width) in C_OPERATIONS.items():
                got = self.operations.call(name, dtype, *(inputs[n] for n in names))
                ulp, nonfinite = _error(got, refs[name], name, epsilon, tiny)
                self.record(name, label, "c", ulp, nonfinite, angle, kappa(name))

    def condition(self, function: str, refs: dict[str, Any],
                  kinematic_at: Callable[[list[Any]], dict[str, Any]], p: list[Any], p2: list[Any],
                  e: list[Any], guess: float | None, tiny: float) -> dict[str, float]:
        """κ of ``function`` (and, for the kinematic ones, of all of them at once)."""
        return condition_of(self.reference, function, refs, kinematic_at, p, p2, e, guess, tiny)


def condition_of(ref: Reference, function: str, refs: dict[str, Any],
                 kinematic_at: Callable[[list[Any]], dict[str, Any]], p: list[Any], p2: list[Any],
                 e: list[Any], guess: float | None, tiny: float) -> dict[str, float]:
    """κ of ``function`` at p (p2 for compose, e for from_quaternion), against ``ref``: for a
    kinematic function that of all of them at once (``kinematic_at(p)`` gives their references, as
    :func:`kinematic`), for an operation its own; ``refs`` the values at the unperturbed inputs."""
    def scale(value: Any, matrix: bool) -> float:
        return _scale(value, matrix, tiny)

    if function in KINEMATIC:
        base = {f: refs[f] for f in KINEMATIC}
        return condition(kinematic_at, p, base, {f: scale(r, f in MATRICES) for f, r in base.items()})
    exact: dict[str, tuple[Callable[[list[Any]], dict[str, Any]], list[Any]]] = {
        "from_quaternion": (lambda x: {"f": ref.from_quaternion(x)}, e),
        "rescale": (lambda x: {"f": ref.rescale(x, guess)}, p),
        "compose": (lambda x: {"f": ref.compose(x[:3], x[3:], (guess, guess))}, p + p2),
    }
    evaluate, inputs = exact[function]
    s = scale(refs[function], False)
    if s == 0:
        return {function: 0.0}
    return {function: condition(evaluate, inputs, {"f": refs[function]}, {"f": s})["f"]}


def emit(expression: str, name: str) -> tuple[Any, str, float]:
    """(plan, NumPy module source, seconds) through the public API, as ``--emit numpy`` does."""
    from symrot.api import derive
    from symrot.backends.numpy_backend import module_source
    from symrot.plan.builder import evaluation_plan

    start = time.perf_counter()
    plan = evaluation_plan(derive(expression).derivation, name)
    source = module_source(plan)
    return plan, source, time.perf_counter() - start


def one_line(error: BaseException) -> str:
    """``Type: first line of the message`` (at most 300 characters of it)."""
    lines = str(error).splitlines()
    return f"{type(error).__name__}: {lines[0][:300] if lines else ''}"


def worker(index: int, points: int, with_c: bool) -> dict[str, Any]:
    """Measure corpus entry ``index``; a JSON-ready result (emit failures included)."""
    entry = CORPUS[index]
    result: dict[str, Any] = {"index": index, "expression": entry.expression, "category": entry.category,
                              "edge": entry.edge, "closed_inverse": entry.closed_inverse}
    return measure_expression(entry.generating_function(), f"corpus_{index:02d}", points, with_c, result)


def measure_expression(function: GeneratingFunction, name: str, points: int, with_c: bool,
                       result: dict[str, Any]) -> dict[str, Any]:
    """Emit ``function`` as module ``name``, measure it; ``result`` completed, JSON-ready."""
    result["phi_max_reference"] = float(function.phi_max)
    try:
        plan, _source, seconds = emit(function.expression, name)
    except Exception as error:  # any exception of the emit is the measurement
        result["emit_error"] = one_line(error)
        result["traceback"] = traceback.format_exc()[-2000:]
        return result
    result["emit_seconds"] = seconds
    result["phi_max_plan"] = float(plan.phi_max)
    result["angle_kind"] = {label: type(p.angle).__name__ for label, p in plan.precisions.items()}
    library, header = None, None
    with tempfile.TemporaryDirectory() as tmp:
        directory = Path(tmp)
        module = load_module(plan, directory)
        operations = None
        if with_c:
            library, header, result["c"] = c_library(plan, name, directory)
            if header is not None:
                try:
                    operations = COperations(directory, header)
                except Exception as error:  # recorded, the other measurements go on
                    result["c"]["operations_error"] = one_line(error)
        measurement = Measurement(function, plan, module, library, header, points, operations=operations)
        measurement.run()
    result["kernel_errors"] = measurement.errors[:5]
    result["tallies"] = [{"function": f, "precision": label, "backend": backend, **asdict(t.worst),
                          "nonfinite": t.nonfinite, "points": t.points}
                         for (f, label, backend), t in measurement.tallies.items()]
    return result


def c_library(plan: Any, name: str, directory: Path,
              load: Callable[[Path, str], Any] | None = None) -> tuple[Any, str | None, dict[str, Any]]:
    """Emit and time the C header symrot_NAME.h into ``directory`` and compile it (gcc -O2
    -ffp-contract=off); (library, header, info). ``load(directory, name)`` compiles and loads the
    library (default: the kinematic wrappers of tests/c_harness.py)."""
    from symrot.backends.c_backend import header_source
    from tests.c_harness import build_config, compile_all

    info: dict[str, Any] = {}
    try:
        start = time.perf_counter()
        (directory / f"symrot_{name}.h").write_text(header_source(plan, name), encoding="utf-8")
        info["emit_seconds"] = time.perf_counter() - start
        if load is not None:
            return load(directory, name), name, info
        build = compile_all([build_config("gcc-O2-nofma")], [name], directory, directory)["gcc-O2-nofma"]
        return build.load(), name, info
    except Exception as error:  # recorded, the NumPy measurement goes on
        info["error"] = one_line(error)
        return None, None, info


def run_worker(command: list[str], index: int, timeout: float) -> dict[str, Any]:
    """Run the worker ``command`` for corpus entry ``index`` in its own process; its JSON result (the
    last line of its standard output), or one with ``worker_error`` when it fails or outlasts
    ``timeout`` seconds (then the last line of its standard error, if any, says where it was)."""
    base: dict[str, Any] = {"index": index, "expression": CORPUS[index].expression}
    try:
        done = subprocess.run(command, capture_output=True, text=True, timeout=timeout, check=False)
        result = json.loads(done.stdout.strip().splitlines()[-1]) if done.returncode == 0 else {
            **base, "worker_error": f"worker exit {done.returncode}: {done.stderr.strip().splitlines()[-1:]}"}
    except subprocess.TimeoutExpired as expired:
        stderr = expired.stderr.decode(errors="replace") if isinstance(expired.stderr, bytes) \
            else (expired.stderr or "")
        last = stderr.strip().splitlines()[-1:]
        result = {**base, "worker_error": f"timeout after {timeout:g} s" + (f" ({last[0]})" if last else "")}
    for key in ("category", "edge", "closed_inverse"):
        result.setdefault(key, getattr(CORPUS[index], key))
    return result


# -- report ----------------------------------------------------------------------------------------

def verdict(entries: list[dict[str, Any]]) -> str:
    if any(e["nonfinite"] for e in entries):
        return "**NaN/Inf**"
    if all(e["ulp"] <= TARGET_ULP for e in entries):
        return "meets"
    if all(e["excess"] <= TARGET_ULP for e in entries):
        return "conditioned"
    return "**miss**"


def miss_text(e: dict[str, Any]) -> str:
    """Where a tally misses: its worst ulp/κ and that angle, then its worst ulp where that is
    elsewhere (results written before ``excess_at`` existed give the worst ulp only)."""
    nan = f" ({e['nonfinite']} NaN/Inf)" if e["nonfinite"] else ""
    worst = f"{e['ulp']:.3g} ulp at φ = {e['at']:.3g}"
    if "excess_at" not in e or e["excess_at"] == e["at"]:
        return worst + (f" (κ {e['kappa']:.2g})" if e["kappa"] > 1 else "") + nan
    return f"{e['excess']:.3g} κ ulp at φ = {e['excess_at']:.3g} (worst {worst}, κ {e['kappa']:.2g}){nan}"


def _cell(e: dict[str, Any] | None) -> str:
    if e is None:
        return "—"
    nan = f"; {e['nonfinite']} NaN/Inf" if e["nonfinite"] else ""
    where = f"; {e['excess']:.3g} κ at {e['excess_at']:.3g}" \
        if e["excess"] > TARGET_ULP and e.get("excess_at", e["at"]) != e["at"] else ""
    return f"{e['ulp']:.3g} ({e['at']:.3g}; κ {e['kappa']:.2g}{where}{nan})"


def _verdicts(result: dict[str, Any]) -> dict[tuple[str, str], str]:
    """{(backend, precision): verdict} of one measured corpus function (empty if not emitted)."""
    out = {}
    for backend, label in COLUMNS:
        mine = [t for t in result.get("tallies", []) if t["backend"] == backend and t["precision"] == label]
        if mine:
            out[(backend, label)] = verdict(mine)
    return out


def report(results: list[dict[str, Any]], command: str, points: int) -> str:
    lines = ["# Accuracy of the generated code for user generating functions (issue 16)", "",
             f"Produced by `{command}`. Reference: tests/reference.py (φ from |p| by safeguarded "
             "Newton at ≥ 60 digits, R from eq 1, H = ∂(axial(Ṙ Rᵀ))/∂ṗ by central differences at "
             "150 digits, H⁻¹, det H by mpmath; independent of symrot's derivation). Sweep: "
             f"`accuracy.sweep(φ_max, {points})` plus |φ| ∈ {{1e-30, 1e-8, 1e-3, 0.1, 1}}, float32 "
             "from its smallest normal, random axes; φ_max = min(reference, plan). Error and verdict as "
             f"in docs/accuracy.md: *meets* ≤ {TARGET_ULP:g} ulp, *conditioned* ≤ {TARGET_ULP:g} κ ulp, "
             "*miss* otherwise, **NaN/Inf** when any output is not finite inside the validity range. "
             "C: the header compiled with gcc -O2 -ffp-contract=off (the kinematic functions and the "
             "quaternion operations; from_rotation_matrix is not swept).", "",
             "## Summary", "",
             "| # | p(φ) | category | edge | closed φ(p) | emit s (NumPy / C) | angle (f64) "
             "| φ_max ref / plan | NumPy f64 | NumPy f32 | C double | C float | NaN/Inf |",
             "|---|---|---|---|---|---|---|---|---|---|---|---|---|"]
    counts: dict[str, int] = {}
    for r in results:
        head = (f"| {r['index']} | `{r['expression']}` | {r['category']} | {r['edge']} | "
                f"{'yes' if r['closed_inverse'] else 'no'} | ")
        if "emit_error" in r or "tallies" not in r:
            reason = r.get("emit_error", r.get("worker_error", "no result"))
            lines.append(head + f"**emit failed**: {reason} | — | {r.get('phi_max_reference', 0):.6g} / — "
                         "| — | — | — | — | — |")
            counts["emit failed"] = counts.get("emit failed", 0) + 1
            continue
        c = r.get("c", {})
        c_time = f"{c['emit_seconds']:.1f}" if "emit_seconds" in c else ("fail" if c else "—")
        found = _verdicts(r)
        cells = [found.get(key, "—") for key in COLUMNS]
        for (backend, label), cell in found.items():
            counts[f"{backend} {label} {cell}"] = counts.get(f"{backend} {label} {cell}", 0) + 1
        nonfinite = sum(t["nonfinite"] for t in r["tallies"])
        mismatch = "" if abs(r["phi_max_plan"] - r["phi_max_reference"]) <= 1e-9 * r["phi_max_reference"] \
            else " **≠**"
        lines.append(head + f"{r['emit_seconds']:.1f} / {c_time} | {r['angle_kind']['float64']} | "
                     f"{r['phi_max_reference']:.6g} / {r['phi_max_plan']:.6g}{mismatch} | "
                     + " | ".join(cells) + f" | {nonfinite} |")
    good = ("meets", "conditioned")
    verdicts = [_verdicts(r) for r in results]
    numpy_ok = sum(all(v.get(k) in good for k in COLUMNS[:2]) for v in verdicts)
    all_ok = sum(all(v.get(k) in good for k in COLUMNS) for v in verdicts)
    lines += ["", f"**Target met** (meets or conditioned, no NaN/Inf) in NumPy float64 and float32: "
              f"{numpy_ok} of {len(results)} corpus functions; in NumPy and C, both precisions: {all_ok} of "
              f"{len(results)}.", "",
              "Counts (corpus functions): " + ", ".join(f"{k}: {v}" for k, v in sorted(counts.items())),
              "", "## Per function", ""]
    for r in results:
        if "tallies" not in r:
            continue
        lines += [f"### {r['index']}. `{r['expression']}`", ""]
        if r.get("kernel_errors"):
            lines += ["Kernel exceptions: " + "; ".join(r["kernel_errors"]), ""]
        if r.get("c", {}).get("error"):
            lines += [f"C: {r['c']['error']}", ""]
        lines += ["| function | NumPy float64 ulp (at φ; κ) | NumPy float32 | C double | C float | verdict |",
                  "|---|---|---|---|---|---|"]
        by_key = {(t["function"], t["precision"], t["backend"]): t for t in r["tallies"]}
        for function in FUNCTIONS:
            entries = [by_key.get((function, label, backend)) for backend, label in COLUMNS]
            present = [e for e in entries if e is not None]
            if present:
                cells = " | ".join(_cell(e) for e in entries)
                lines.append(f"| {function} | {cells} | {verdict(present)} |")
        lines.append("")
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--points", type=int, default=12)
    parser.add_argument("--only", type=int, nargs="*")
    parser.add_argument("--no-c", action="store_true")
    parser.add_argument("--out", default="docs/accuracy_corpus.md")
    parser.add_argument("--json", help="also write the raw results here")
    parser.add_argument("--reuse", help="results JSON of an earlier run (--json): entries not in --only "
                                        "are taken from it instead of being measured again")
    parser.add_argument("--worker", type=int, help=argparse.SUPPRESS)
    args = parser.parse_args(argv)
    if args.worker is not None:
        print(json.dumps(worker(args.worker, args.points, not args.no_c)))
        return 0
    indices = args.only if args.only else list(range(len(CORPUS)))
    reused = {r["index"]: r for r in json.loads(Path(args.reuse).read_text(encoding="utf-8"))} \
        if args.reuse else {}
    results = []
    for index in sorted(set(indices) | set(reused)):
        if index in reused and index not in indices:
            results.append(reused[index])
            continue
        command = [sys.executable, __file__, "--worker", str(index), "--points", str(args.points)]
        command += ["--no-c"] if args.no_c else []
        start = time.perf_counter()
        result = run_worker(command, index, WORKER_TIMEOUT)
        results.append(result)
        print(f"{index} {CORPUS[index].expression}: {time.perf_counter() - start:.0f} s "
              f"{result.get('emit_error') or result.get('worker_error') or ''}", flush=True)
    command = "python bench/accuracy_corpus.py " + " ".join(argv if argv is not None else sys.argv[1:])
    Path(args.out).write_text(report(results, command.strip(), args.points) + "\n", encoding="utf-8")
    if args.json:
        Path(args.json).write_text(json.dumps(results, indent=1), encoding="utf-8")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
