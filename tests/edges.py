"""Probes of the validity edge |p| = p_max to the ulp, from an independent φ_max (issue 61).

The edge comes from tests/reference.py alone (:class:`GeneratingFunction`: φ_max by its validity
scan of p(φ) and p′(φ) in mpmath, p_max = |p(φ_max)|), never from symrot's plan, a generated
module's constants or a header. The range is |p| < p_max (Section 3.4: φ ∈ [0, φ_max)); a
backend decides it on x̂ = |p|² rounded (a sum of three rounded squares), so an input whose exact
|p|² and x̂ lie on different sides of p_max² may go either way: such probes are marked undecided
(``inside=None``) and either answer is accepted. Three kinds of probe, in float64 and float32:

* ``axis``: s u along a coordinate axis for s = fl(p_max) and its neighbours up to 3 ulps away:
  x̂ = fl(s²) is one rounding, so the probe is undecided only where fl(s²) and s² straddle p_max²;
* ``ladder``: (a, b, 0) (axes permuted) whose x̂ = fl(fl(a²) + fl(b²)) is each float from 3 ulps
  below to 3 ulps above B = fl(p_max²), with the exact a² + b² within ulp/4 of x̂ on the same side
  of p_max² (always decided): a bound moved by one ulp, or ≤ in place of <, changes one answer;
* ``random``: seeded random directions at |p| = p_max (1 + j u), u the unit roundoff, decided where
  |exact |p|² − p_max²| > γ₃ |p|² (γ₃ = 3u/(1 − 3u) bounds the rounding of a sum of three squares).

Where p is unbounded (a pole: Cayley–Gibbs–Rodrigues, Wiener–Milenkovic, the tangent family at
m < 4) the range is the documented x_limit (a power of two, "|p|^2 < 2^600 (2^85 in float32)" in
the NumPy module's docstring): ladder probes around it, and huge |p| inside.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from functools import cache
from pathlib import Path
from typing import Any

import mpmath
import numpy as np

from .reference import GeneratingFunction, Reference

ROOT = Path(__file__).resolve().parent.parent
FAMILIES: dict[str, str] = {
    "rotation_vector": "phi", "linear": "sin(phi)", "euler_rodrigues": "2*sin(phi/2)",
    "cayley_gibbs_rodrigues": "2*tan(phi/2)", "wiener_milenkovic": "4*tan(phi/4)",
    "det_h_one": "cbrt(6*phi - 6*sin(phi))",
    **{f"sine_m{m}": f"{m}*sin(phi/{m})" for m in (3, 4, 5, 6)},
    "tangent_m1": "tan(phi)", **{f"tangent_m{m}": f"{m}*tan(phi/{m})" for m in (3, 5, 6)},
}
"""p(φ) of every named family as in the paper (eqs 30–36), by the name of its generated files."""
CORPUS_SAMPLE: dict[str, str] = {
    "nu": "phi + phi**3/6", "fold": "sin(phi)*cos(phi)", "slope": "4*phi/5 + asin(phi)/5",
}
"""One tests/corpus.py function per kind of bounded edge, among the cheapest to emit (about 5 s
each, NumPy and C); poles are the named families' (Cayley–Gibbs–Rodrigues, Wiener–Milenkovic, the
tangent family at m = 1 and 3), and no named family ends in a slope."""
UNBOUNDED = mpmath.mpf(10) ** 30
"""|p(φ_max)| above this is a pole (the scan stops just past it: tan(π/2 + 10⁻⁴⁰) ≈ 10⁴⁰)."""
TARGET_ULP = 4.0
DTYPES = (np.float64, np.float32)
STEPS = (-3, -2, -1, 0, 1, 2, 3)
RANDOM_STEPS = (-64, -8, -3, 3, 8, 64)
"""|p| = p_max (1 + j u) of the random probes: ±3 u is often undecided, ±8 u and beyond never."""
HUGE = (2.0**-40, 2.0**-16, 0.5, 1 - 2.0**-6)
"""|p| / √x_limit of the random probes inside an unbounded range: up to |p|² = (1 − 2⁻⁵) x_limit."""


@dataclass(frozen=True)
class Edge:
    """The validity edge of p(φ) from tests/reference.py."""

    expression: str
    function: GeneratingFunction
    p_max: Any
    """|p(φ_max)| (mpmath, 60 digits), or inf at a pole."""

    @property
    def bounded(self) -> bool:
        return bool(mpmath.isfinite(self.p_max))

    @property
    def p_max_squared(self) -> Any:
        with mpmath.workdps(80):
            return self.p_max**2


@dataclass(frozen=True)
class Probe:
    """One input vector with the verdict the definition gives it."""

    p: tuple[float, float, float]
    inside: bool | None
    """None: the rounding of |p|² decides (either answer is right)."""
    kind: str
    step: int


@cache
def edge(expression: str) -> Edge:
    function = GeneratingFunction(expression)
    with mpmath.workdps(60):
        p_max = function.p_max()
        p_max = mpmath.inf if not p_max < UNBOUNDED else +p_max
    return Edge(expression, function, p_max)


def documented_x_limit(documentation: Path, dtype: type, function: str = "angle") -> float:
    """The x_limit that a NumPy module's docstring ("|p|^2 < 2^K (2^L in float32)") or a C header's
    comment of ``function`` (``function_f`` in float: "Valid for every p with |p|^2 < 2^K") documents."""
    text = documentation.read_text(encoding="utf-8")
    if documentation.suffix == ".h":
        suffix = "_f" if dtype == np.float32 else ""
        found = re.search(rf"_{function}{suffix}: [^\n]*\n(?: \* [^\n]*\n)*? \* Valid for every p with "
                          r"\|p\|\^2 < 2\^(\d+)", text)
        exponent = found.group(1) if found else None
    else:
        found = re.search(r"\|p\|\^2 < 2\^(\d+) \(2\^(\d+) in float32\)", text)
        exponent = found.group(1 if dtype == np.float64 else 2) if found else None
    assert exponent is not None, f"{documentation}: no documented x_limit"
    return 2.0 ** int(exponent)


def _exact(value: Any) -> Any:
    return mpmath.mpf(float(value))


def _squared(p: tuple[float, ...]) -> Any:
    with mpmath.workprec(600):
        return mpmath.fsum(_exact(c) ** 2 for c in p)


def _nearest(value: Any, dtype: type) -> Any:
    """value rounded to the nearest number of dtype (as an mpmath number)."""
    with mpmath.workprec(np.finfo(dtype).nmant + 1):
        return +value


def _step(value: Any, steps: int, dtype: type) -> Any:
    toward = dtype(np.inf) if steps > 0 else dtype(0)
    result = dtype(float(value))
    for _ in range(abs(steps)):
        result = np.nextafter(result, toward)
    return result


def _unit_roundoff(dtype: type) -> float:
    return float(np.finfo(dtype).eps) / 2


def _placed(a: Any, b: Any, index: int) -> tuple[float, float, float]:
    """(a, b) on the axes (index, index + 1 mod 3), signs by index: the zero moves around."""
    p = [0.0, 0.0, 0.0]
    p[index % 3] = float(a) * (-1) ** index
    p[(index + 1) % 3] = float(b) * (-1) ** (index // 3)
    return p[0], p[1], p[2]


def _two_squares(target: Any, bound: Any, dtype: type) -> tuple[Any, Any] | None:
    """(a, b) of dtype with fl(fl(a²) + fl(b²)) = target and a² + b² on target's side of bound."""
    outside = target >= bound
    with mpmath.workprec(600):
        value = dtype(float(target))
        ulp = min(_exact(np.spacing(value)), target - _exact(np.nextafter(value, dtype(0))))
        wanted = target + (ulp if outside else -ulp) / 4
        for k in range(6, 24):
            a = dtype(float(mpmath.sqrt(wanted * (1 - mpmath.mpf(2) ** -k))))
            rest = wanted - _exact(a) ** 2
            if rest <= 0:
                continue
            b = dtype(float(mpmath.sqrt(rest)))
            rounded = a * a + b * b  # dtype arithmetic: each operation rounded once
            exact = _exact(a) ** 2 + _exact(b) ** 2
            if _exact(rounded) == target and (exact >= bound) == outside:
                return a, b
    return None


def ladder(bound: Any, dtype: type, kind: str = "ladder") -> list[Probe]:
    """Probes with x̂ = each float from 3 ulps below to 3 ulps above fl(bound); inside: x < bound."""
    centre = _nearest(bound, dtype)
    probes = []
    for index, steps in enumerate(STEPS):
        target = _exact(_step(centre, steps, dtype))
        pair = _two_squares(target, bound, dtype)
        assert pair is not None, (kind, steps, dtype)
        probes.append(Probe(_placed(*pair, index), bool(target < bound), kind, steps))
    return probes


def axis_probes(e: Edge, dtype: type) -> list[Probe]:
    probes = []
    for index, steps in enumerate(STEPS):
        s = _step(_nearest(e.p_max, dtype), steps, dtype)
        inside = bool(_exact(s) < e.p_max)
        rounded_inside = bool(_exact(s * s) < e.p_max_squared)
        p = _placed(s, 0.0, index)
        probes.append(Probe(p, inside if inside == rounded_inside else None, "axis", steps))
    return probes


def random_probes(e: Edge, dtype: type, x_limit: float | None = None, seed: int = 61) -> list[Probe]:
    rng = np.random.default_rng(seed)
    u = _unit_roundoff(dtype)
    gamma = 3 * u / (1 - 3 * u)
    probes = []
    sizes = [(j, e.p_max * (1 + j * u)) for j in RANDOM_STEPS] if e.bounded else \
        [(0, mpmath.sqrt(x_limit) * s) for s in HUGE]
    for j, size in sizes:
        for _ in range(2):
            direction = rng.normal(size=3)
            direction /= np.linalg.norm(direction)
            with mpmath.workdps(40):
                p = tuple(float(dtype(float(size * mpmath.mpf(float(c))))) for c in direction)
            x = _squared(p)
            if not e.bounded:
                probes.append(Probe((p[0], p[1], p[2]), True, "huge", j))
                continue
            decided = abs(x - e.p_max_squared) > gamma * x
            inside = bool(x < e.p_max_squared) if decided else None
            probes.append(Probe((p[0], p[1], p[2]), inside, "random", j))
    return probes


@cache
def probes(expression: str, dtype: type, x_limit: float | None = None) -> tuple[Probe, ...]:
    """Every probe of p(φ)'s edge in dtype; ``x_limit``: the documented bound where p is unbounded."""
    e = edge(expression)
    if e.bounded:
        found = [*axis_probes(e, dtype), *ladder(e.p_max_squared, dtype), *random_probes(e, dtype)]
    else:
        assert x_limit is not None, expression
        found = [*ladder(mpmath.mpf(x_limit), dtype, "limit"), *random_probes(e, dtype, x_limit)]
    decided = [probe for probe in found if probe.inside is not None]
    assert sum(p.inside is True for p in decided) >= 4 and sum(p.inside is False for p in decided) >= 4
    return tuple(found)


def accuracy_probes(found: tuple[Probe, ...]) -> list[Probe]:
    """The inside probes whose values are checked: the nearest the edge of each kind, and two more
    random ones (the reference costs 5–50 ms a vector)."""
    chosen: list[Probe] = []
    for kind in ("axis", "ladder", "limit"):
        inside = [p for p in found if p.kind == kind and p.inside]
        if inside:
            chosen.append(max(inside, key=lambda p: p.step))
    chosen += [p for p in found if p.kind in ("random", "huge") and p.inside][:3]
    return chosen


# -- the accuracy claim ------------------------------------------------------------------------
_STATES: dict[tuple[str, tuple[Any, ...]], Any] = {}


def state(expression: str, p: tuple[Any, ...]) -> Any:
    """tests/reference.py's State at p (cached over backends)."""
    key = (expression, tuple(mpmath.mpf(c) for c in p))
    if key not in _STATES:
        _STATES[key] = Reference(edge(expression).function).state(list(key[1]))
    return _STATES[key]


def _reference_value(s: Any, name: str) -> list[Any]:
    if name == "angle":
        return [s.angle]
    matrix = s.R if name == "rotation_matrix" else s.H
    return [matrix[i, j] for i in range(3) for j in range(3)]


def ulp_error(value: np.ndarray, exact: list[Any], matrix: bool, dtype: type) -> float:
    """Error in ε of dtype: relative to max(1, max |ref|) for matrices, to |ref| for the angle
    (bench/accuracy.py's measure); NaN or inf is infinite."""
    values = np.asarray(value, dtype=np.float64).ravel()
    if not np.all(np.isfinite(values)):
        return float("inf")
    scale = max(abs(v) for v in exact)
    scale = max(scale, mpmath.mpf(1)) if matrix else max(scale, mpmath.mpf(float(np.finfo(dtype).tiny)))
    error = max(abs(mpmath.mpf(float(g)) - v) for g, v in zip(values, exact, strict=True))
    return float(error / scale / float(np.finfo(dtype).eps))


def condition(expression: str, p: tuple[float, ...], name: str, exact: list[Any]) -> float:
    """κ: Σ_i |∂f/∂p_i| |p_i| / scale, max over the entries (bench/accuracy.py's condition), by
    differences of the reference with relative steps 10⁻³⁰."""
    delta = mpmath.mpf(10) ** -30
    scale = max(max(abs(v) for v in exact), mpmath.mpf(1) if name != "angle" else mpmath.mpf(0))
    total = [mpmath.mpf(0)] * len(exact)
    for i, c in enumerate(p):
        if c == 0:
            continue
        with mpmath.workdps(80):
            moved = [mpmath.mpf(v) for v in p]
            moved[i] *= 1 + delta
            other = _reference_value(state(expression, tuple(moved)), name)
            total = [t + abs(a - b) / delta for t, a, b in zip(total, other, exact, strict=True)]
    return float(max(total) / scale) if scale else 1.0


CHECKED = ("angle", "rotation_matrix", "tangent")


def accuracy_misses(expression: str, probe: Probe, values: dict[str, np.ndarray], dtype: type) -> list[str]:
    """The functions of ``values`` (CHECKED) beyond 4 ulp and beyond 4 κ ulp at ``probe``."""
    reference = state(expression, probe.p)
    misses = []
    for name in CHECKED:
        exact = _reference_value(reference, name)
        error = ulp_error(values[name], exact, name != "angle", dtype)
        if error <= TARGET_ULP:
            continue
        kappa = condition(expression, probe.p, name, exact)
        if error > TARGET_ULP * max(1.0, kappa):
            misses.append(f"{name} {np.dtype(dtype).name} at {probe.kind}{probe.step:+d} {probe.p}: "
                          f"{error:.3g} ulp, κ {kappa:.3g}")
    return misses
