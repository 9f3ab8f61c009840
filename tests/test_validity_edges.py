"""The validity edge probed to the ulp, from an independent φ_max (issue 61), in every backend.

For the 7 NumPy, JAX and PyTorch modules of generated/, the 14 C headers of generated/c (through
tests/c_harness.py) and one tests/corpus.py function per kind of edge (nu, fold, pole, slope;
emitted here through symrot's API, NumPy and C), the probes of tests/edges.py: one and a few ulps
inside and outside |p| = p_max (p_max from tests/reference.py, never from the plan, a module or a
header), along axes, on a ladder of |p|² and along seeded random directions; for unbounded p, the
documented x_limit and huge |p|. Decided probes must be answered as the definition says:

* outside: NaN in every output of every function of p (C: the functions that return a status
  return 1, as the headers document: "Returns 0, or 1 with p3 = NaN when p1 or p2 is out of range");
* inside: no NaN in any function of p alone (compose may leave a range narrower than 2π), and
  ``angle``, ``rotation_matrix`` and ``tangent`` within 4 ulp, or 4 κ ulp, of tests/reference.py.

Undecided probes (the rounding of |p|² straddles p_max²) may go either way, but all of a module's
functions must agree on them. A validity test widened by 2 %, a bound moved by one ulp or ≤ in
place of < fails here in NumPy and in C.
"""

from __future__ import annotations

import ctypes
import subprocess
from collections.abc import Callable
from functools import cache
from pathlib import Path
from types import ModuleType
from typing import Any

import mpmath
import numpy as np
import pytest

from . import c_harness
from .edges import (
    CORPUS_SAMPLE,
    DTYPES,
    FAMILIES,
    ROOT,
    Probe,
    accuracy_misses,
    accuracy_probes,
    documented_x_limit,
    edge,
    ladder,
    probes,
)
from .test_array_backends import framework, load

NAMED = ("rotation_vector", "linear", "euler_rodrigues", "cayley_gibbs_rodrigues", "wiener_milenkovic",
         "det_h_one", "sine_m4")
"""The families of generated/numpy, generated/jax and generated/torch."""
OF_P = ("angle", "rotation_matrix", "tangent", "tangent_inverse", "tangent_det", "root_matrix",
        "root_tangent", "to_quaternion", "rescale", "rescale_jacobian")
WITH_VECTOR = ("pdot", "omega", "rotation_derivative", "rotation_transpose_derivative", "tangent_derivative",
               "tangent_transpose_derivative", "tangent_inverse_derivative", "angular_acceleration")
PAIRS = ("compose", "compose_jacobians")
"""Called as f(p, q) and f(q, p) with q inside: NaN when p is outside, either way round."""
DERIVATIVES = {name for name in WITH_VECTOR if name.endswith("derivative")} | {"angular_acceleration"}
"""Where p is unbounded they document a narrower x_limit of their own (2^32 for tan φ in C): only
"NaN outside" is asked of them there."""
Results = dict[str, list[np.ndarray]]


def evaluate(module: Any, p: np.ndarray, to: Callable[[np.ndarray], Any],
             skip: tuple[str, ...] = ()) -> Results:
    """Every function of p of a NumPy, JAX or PyTorch module on the rows of p (``to`` converts),
    but those of ``skip``."""
    vector = to(np.full_like(p, 0.5))
    inner = to(np.full_like(p, 0.1))
    args = to(p)
    results: Results = {}

    def keep(label: str, value: Any) -> None:
        values = value if isinstance(value, tuple) else (value,)
        results[label] = [np.asarray(v.numpy() if hasattr(v, "numpy") else v) for v in values]

    for name in (n for n in OF_P if n not in skip):
        keep(name, getattr(module, name)(args))
    for name in (n for n in WITH_VECTOR if n not in skip):
        extra = (vector, vector) if name == "angular_acceleration" else (vector,)
        keep(name, getattr(module, name)(args, *extra))
    for name in PAIRS:
        keep(f"{name}(p, q)", getattr(module, name)(args, inner))
        keep(f"{name}(q, p)", getattr(module, name)(inner, args))
    return results


def _answer(values: list[np.ndarray]) -> str:
    """"nan" (every output NaN), "value" (none) or "partial"."""
    nan = np.concatenate([np.isnan(v).ravel() for v in values])
    return "nan" if nan.all() else "value" if not nan.any() else "partial"


def failures(expression: str, found: tuple[Probe, ...], results: Results, dtype: type,
             status: dict[str, np.ndarray] | None = None) -> list[str]:
    """What the results of the probes ``found`` get wrong (empty: nothing)."""
    wrong = []
    bounded = edge(expression).bounded
    for row, probe in enumerate(found):
        answer = {label: _answer([v[row] for v in values]) for label, values in results.items()}
        alone = {label: a for label, a in answer.items() if label.split("(")[0] not in PAIRS
                 and (bounded or label not in DERIVATIVES)}
        where = f"{probe.kind}{probe.step:+d} {probe.p}"
        if probe.inside is False:
            wrong += [f"{label} not NaN outside at {where}" for label, a in answer.items() if a != "nan"]
            wrong += [f"{label} status {s[row]} outside at {where}" for label, s in (status or {}).items()
                      if s[row] != 1]
        elif probe.inside:
            wrong += [f"{label} NaN inside at {where}" for label, a in alone.items() if a != "value"]
            wrong += [f"{label} status {s[row]} inside at {where}" for label, s in (status or {}).items()
                      if s[row] != 0 and label in alone]
        elif len(set(alone.values())) != 1 or "partial" in alone.values():  # undecided: either answer
            wrong.append(f"functions disagree on the undecided {where}: {alone}")
    for probe in accuracy_probes(found):
        row = found.index(probe)
        values = {name: results[name][0][row] for name in ("angle", "rotation_matrix", "tangent")}
        wrong += accuracy_misses(expression, probe, values, dtype)
    return wrong


def family_probes(expression: str, dtype: type, documentation: Path) -> tuple[Probe, ...]:
    """The probes of p(φ) in dtype; where p is unbounded, around the x_limit of ``documentation``."""
    limit = None if edge(expression).bounded else documented_x_limit(documentation, dtype)
    return probes(expression, dtype, limit)


def numpy_documentation(name: str) -> Path:
    return ROOT / "generated" / "numpy" / f"{name}.py"


def header(name: str) -> Path:
    return ROOT / "generated" / "c" / f"symrot_{name}.h"


ROWS = 32
"""Every batch is padded to this many rows (p = 0): JAX compiles each primitive once per shape."""


def as_rows(found: tuple[Probe, ...], dtype: type) -> np.ndarray:
    assert len(found) <= ROWS
    return np.array([probe.p for probe in found] + [(0.0, 0.0, 0.0)] * (ROWS - len(found)), dtype=dtype)


# -- NumPy, JAX, PyTorch ------------------------------------------------------------------------
@pytest.mark.parametrize("dtype", DTYPES, ids=["float64", "float32"])
@pytest.mark.parametrize("name", NAMED)
def test_numpy_edge(name: str, dtype: type) -> None:
    module = load(ROOT / "generated" / "numpy" / f"{name}.py", f"edges_numpy_{name}")
    found = family_probes(FAMILIES[name], dtype, numpy_documentation(name))
    with np.errstate(all="ignore"):
        results = evaluate(module, as_rows(found, dtype), lambda a: a)
    assert not failures(FAMILIES[name], found, results, dtype)


# -- C -------------------------------------------------------------------------------------------
STATUS = {"to_quaternion": 4, "rescale": 3, "rescale_jacobian": 9, "compose(p, q)": 3, "compose(q, p)": 3,
          "compose_jacobians(p, q)": 18, "compose_jacobians(q, p)": 18,
          **{n: 9 for n in WITH_VECTOR if n.endswith("derivative")}, "angular_acceleration": 3}
"""The functions outside tests/c_harness.py's nine, with their number of outputs."""
NO_STATUS = {"to_quaternion", "angular_acceleration", *(n for n in WITH_VECTOR if n.endswith("derivative"))}
C_FLAGS = (*c_harness.STRICT_C, "-O0", "-ffp-contract=off")
"""No contraction: x = |p|² is then the sum of three rounded squares the probes were built for."""


def _call(header: str, label: str, suffix: str) -> str:
    function = label.split("(")[0]
    target = f"symrot_{header}_{function}{suffix}"
    first, second = ("q", "p") if label.endswith("(q, p)") else ("p", "q")
    if function == "compose_jacobians":
        return f"{target}({first} + 3*i, {second} + 3*i, out + 18*i, out + 18*i + 9)"
    if function in PAIRS:
        return f"{target}({first} + 3*i, {second} + 3*i, out + 3*i)"
    width = STATUS[label]
    if function == "angular_acceleration":
        return f"{target}(p + 3*i, q + 3*i, q + 3*i, out + {width}*i)"
    if function.endswith("derivative"):
        return f"{target}(p + 3*i, q + 3*i, out + {width}*i)"
    return f"{target}(p + 3*i, out + {width}*i)"


def extra_wrappers(headers: tuple[str, ...]) -> str:
    """e_HEADER_F[_f](n, p, q, out, status) for the functions of STATUS (status -1: none)."""
    lines = []
    for header in headers:
        for ctype, suffix in (("double", ""), ("float", "_f")):
            for index, label in enumerate(STATUS):
                call = _call(header, label, suffix)
                body = f"{call}; status[i] = -1;" if label in NO_STATUS else f"status[i] = {call};"
                signature = (f"void e_{header}_{index}{suffix}(size_t n, const {ctype} *p, const {ctype} *q, "
                             f"{ctype} *out, int *status)")
                loop = f"size_t i; (void)q; for (i = 0; i < n; ++i) {{ {body} }}"
                lines += [f"{signature};", f"{signature} {{ {loop} }}"]
    return "\n".join(lines) + "\n"


@cache
def c_library(headers: tuple[str, ...], include: Path, work: Path) -> ctypes.CDLL:
    source = work / "edges.c"
    source.write_text(c_harness.translation_unit(headers) + extra_wrappers(headers), encoding="utf-8")
    out = work / "edges.so"
    command = ["gcc", *C_FLAGS, "-fPIC", "-shared", f"-I{include}", str(source), "-o", str(out), "-lm"]
    result = subprocess.run(command, capture_output=True, text=True, timeout=600, check=False)
    assert result.returncode == 0, result.stderr[-4000:]
    return ctypes.CDLL(str(out))


def c_evaluate(dll: ctypes.CDLL, header: str, p: np.ndarray) -> tuple[Results, dict[str, np.ndarray]]:
    """(every output, {label: status}) of the header's functions of p on the rows of p."""
    precision = "double" if p.dtype == np.float64 else "float"
    library = c_harness.Library(dll, (header,))
    second = np.full_like(p, 0.5)
    results: Results = {f.name: [library.call(header, f, precision, p, second)] for f in c_harness.FUNCTIONS}
    status: dict[str, np.ndarray] = {}
    ctype = c_harness.CTYPES[precision]
    pointer = ctypes.POINTER(ctype)
    inner = np.ascontiguousarray(np.full_like(p, 0.1))
    for index, (label, width) in enumerate(STATUS.items()):
        q = second if label.split("(")[0] in NO_STATUS else inner
        out = np.full((len(p), width), -7.0, dtype=p.dtype)
        codes = np.full(len(p), -7, dtype=np.intc)
        function = getattr(dll, f"e_{header}_{index}{c_harness.SUFFIX[precision]}")
        function.argtypes = [ctypes.c_size_t, pointer, pointer, pointer, ctypes.POINTER(ctypes.c_int)]
        function.restype = None
        function(len(p), np.ascontiguousarray(p).ctypes.data_as(pointer), q.ctypes.data_as(pointer),
                 out.ctypes.data_as(pointer), codes.ctypes.data_as(ctypes.POINTER(ctypes.c_int)))
        results[label] = [out]
        if label not in NO_STATUS:
            status[label] = codes
    return results, status


@pytest.fixture(scope="module")
def named_c(tmp_path_factory: pytest.TempPathFactory) -> ctypes.CDLL:
    assert not c_harness.missing_compilers()
    return c_library(tuple(FAMILIES), ROOT / "generated" / "c", tmp_path_factory.mktemp("edges_c"))


@pytest.mark.parametrize("name", list(FAMILIES))
def test_c_edge(name: str, named_c: ctypes.CDLL) -> None:
    wrong = []
    for dtype in DTYPES:
        found = family_probes(FAMILIES[name], dtype, header(name))
        results, status = c_evaluate(named_c, name, as_rows(found, dtype))
        wrong += failures(FAMILIES[name], found, results, dtype, status)
    assert not wrong


@pytest.mark.parametrize("name", ["tangent_m1", "tangent_m3"])
def test_c_derivatives_end_at_their_own_documented_limit(name: str, named_c: ctypes.CDLL) -> None:
    """Where a header documents a narrower x_limit for the derivatives (2^32 for tan φ and 3 tan(φ/3),
    against 2^511 for the others), they are NaN from the first |p|² at or above it on (ladder probes,
    ±3 ulps) and finite below, while every other function stays finite on both sides."""
    wrong = []
    for dtype in DTYPES:
        limits = {documented_x_limit(header(name), dtype, f) for f in sorted(DERIVATIVES)}
        assert len(limits) == 1 and limits.pop() < documented_x_limit(header(name), dtype) / 2**16
        found = tuple(ladder(mpmath.mpf(documented_x_limit(header(name), dtype, "rotation_derivative")),
                             dtype, "derivative limit"))
        results, _ = c_evaluate(named_c, name, as_rows(found, dtype))
        for row, probe in enumerate(found):
            for label, values in results.items():
                answer = _answer([v[row] for v in values])
                expected = "nan" if label in DERIVATIVES and not probe.inside else "value"
                if answer != expected and label.split("(")[0] not in PAIRS:
                    wrong.append(f"{label} {np.dtype(dtype).name} {answer} at {probe.step:+d} {probe.p}")
    assert not wrong


# -- a corpus sample, emitted here ---------------------------------------------------------------
CORPUS_MISS = ("NumPy float32 rejects x = fl32(p_max^2) = 2268.1298828125, which lies below p_max^2 = "
               "2268.12991391957832 (inside; measured: NaN at p = (-47.25135, -5.953126, 0), exact |p|^2 "
               "ulp/4 below it): `x < P_MAX_SQUARED` compares with float64's bound 2268.1299139195785 "
               "(above p_max^2, so exclusive) rounded to float32, where the C header has x <= its float "
               "bound")


Emitted = tuple[ModuleType, ctypes.CDLL, Path]


@pytest.fixture(scope="module")
def emitted(tmp_path_factory: pytest.TempPathFactory) -> Callable[[str], Emitted]:
    """kind ↦ (NumPy module, compiled C header, folder) of CORPUS_SAMPLE[kind], emitted once through
    symrot's API (derive, evaluation_plan and the backends' sources, as ``--emit`` does)."""
    from symrot.api import derive
    from symrot.backends.c_backend import header_source
    from symrot.backends.numpy_backend import module_source
    from symrot.plan.builder import evaluation_plan

    built: dict[str, Emitted] = {}

    def build(kind: str) -> Emitted:
        if kind not in built:
            work = tmp_path_factory.mktemp(f"edges_{kind}")
            name = f"edge_{kind}"
            plan = evaluation_plan(derive(CORPUS_SAMPLE[kind]).derivation, name)
            (work / f"{name}.py").write_text(module_source(plan), encoding="utf-8")
            (work / f"symrot_{name}.h").write_text(header_source(plan, name), encoding="utf-8")
            module = load(work / f"{name}.py", f"edges_corpus_{kind}")
            built[kind] = (module, c_library((name,), work, work), work)
        return built[kind]

    return build


CORPUS_CASES = [pytest.param(kind, backend, dtype, id=f"{kind}-{backend}-{np.dtype(dtype).name}",
                             marks=[pytest.mark.xfail(strict=True, reason=CORPUS_MISS)]
                             if (kind, backend, dtype) == ("nu", "numpy", np.float32) else [])
                for kind in CORPUS_SAMPLE for backend in ("numpy", "c") for dtype in DTYPES]


@pytest.mark.parametrize("kind, backend, dtype", CORPUS_CASES)
def test_corpus_edge(kind: str, backend: str, dtype: type,
                     emitted: Callable[[str], Emitted]) -> None:
    module, dll, work = emitted(kind)
    name = f"edge_{kind}"
    expression = CORPUS_SAMPLE[kind]
    if backend == "numpy":
        found = family_probes(expression, dtype, work / f"{name}.py")
        with np.errstate(all="ignore"):
            wrong = failures(expression, found, evaluate(module, as_rows(found, dtype), lambda a: a), dtype)
    else:
        found = family_probes(expression, dtype, work / f"symrot_{name}.h")
        results, status = c_evaluate(dll, name, as_rows(found, dtype))
        wrong = failures(expression, found, results, dtype, status)
    assert not wrong


# -- JAX and PyTorch (last: symrot's emit forks, which JAX's threads make unsafe) --------------
JAX_SKIP = (*sorted(DERIVATIVES - {"angular_acceleration"}), "rescale_jacobian")
"""Not run in JAX (forward-mode derivatives of the kernels checked here, 1–1.5 s a family eagerly;
the same template's PyTorch modules run them)."""


@cache
def array_results(name: str, kind: str, dtype: type) -> tuple[tuple[Probe, ...], Results]:
    """The probes and the results of the JAX or PyTorch module (once for both tests below)."""
    library = framework(kind)
    module = load(ROOT / "generated" / kind / f"{name}.py", f"edges_{kind}_{name}")
    found = family_probes(FAMILIES[name], dtype, numpy_documentation(name))
    convert: Callable[[np.ndarray], Any] = library.numpy.asarray if kind == "jax" else library.from_numpy
    return found, evaluate(module, as_rows(found, dtype), convert, JAX_SKIP if kind == "jax" else ())


@pytest.mark.parametrize("kind", ["jax", "torch"])
@pytest.mark.parametrize("name", NAMED)
def test_array_backend_edge(name: str, kind: str) -> None:
    """Every function as the NumPy modules are checked."""
    wrong = []
    for dtype in DTYPES:
        found, results = array_results(name, kind, dtype)
        wrong += failures(FAMILIES[name], found, results, dtype)
    assert not wrong
