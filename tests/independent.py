"""Inputs, independent references and backend outputs for tests/test_independent_values.py (issue 61).

The references come from :mod:`tests.reference` alone (φ by Newton on p(φ), R from eq 1, H from
ω = H ṗ by differentiation, the quaternion of eq 74, the operations through the quaternion
product), never from symrot's derivation, plan or generated constants; φ_max is the paper's
(Section 3.4: a pole, a fold p′ = 0, or 2π where ν → 0), written here as text.

Inputs (:func:`points`): for each family and precision, |φ| from 0 and 10⁻³⁰⁰ (float32: its
smallest normal) through small, moderate and large angles to φ_max − 10⁻⁶, p = fl(p(φ) u) on unit
axes u of a seeded generator; w (the vector of pdot, omega and the derivatives), p2 (compose), a
second vector for α, and the quaternion e of a third axis with a random sign (from_quaternion).
Points whose |p| is within 2 ulp of p_max are left out (they may round onto the edge).
Everything is cached per process: references per (family, precision), outputs per backend.
"""

from __future__ import annotations

import sys
import warnings
from collections.abc import Callable
from dataclasses import dataclass
from functools import cache
from pathlib import Path
from typing import Any

import mpmath
import numpy as np

from .reference import GeneratingFunction, Reference, rodrigues

ROOT = Path(__file__).resolve().parent.parent
if str(ROOT / "bench") not in sys.path:
    sys.path.insert(0, str(ROOT / "bench"))

from accuracy_corpus import (  # noqa: E402
    C_OPERATIONS,
    FUNCTIONS,
    MATRICES,
    call_operation,
    condition_of,
    kinematic,
    operation_wrappers,
)
from accuracy_operations import _shepperd  # noqa: E402

from .measure import TARGET_ULP, condition, scale  # noqa: E402
from .measure import entries as _entries  # noqa: E402
from .measure import ulp as ulp_error  # noqa: E402

DTYPES: dict[str, type[np.floating[Any]]] = {"float64": np.float64, "float32": np.float32}
ALL = (*FUNCTIONS, "from_rotation_matrix")
"""Every value function: the kinematic ones, the quaternion operations and from_rotation_matrix."""
C_CALLS = {**C_OPERATIONS, "from_rotation_matrix": (("R",), 3)}
"""The C functions besides the nine of tests/c_harness.py: inputs and number of outputs."""
PAPER: dict[str, tuple[str, str]] = {
    "rotation_vector": ("phi", "2*pi"), "cayley_gibbs_rodrigues": ("2*tan(phi/2)", "pi"),
    "euler_rodrigues": ("2*sin(phi/2)", "pi"), "wiener_milenkovic": ("4*tan(phi/4)", "2*pi"),
    "linear": ("sin(phi)", "pi/2"), "det_h_one": ("cbrt(6*(phi - sin(phi)))", "2*pi"),
    "sine_m4": ("4*sin(phi/4)", "2*pi"), "sine_m3": ("3*sin(phi/3)", "3*pi/2"),
    "sine_m5": ("5*sin(phi/5)", "2*pi"), "sine_m6": ("6*sin(phi/6)", "2*pi"),
    "tangent_m1": ("tan(phi)", "pi/2"), "tangent_m3": ("3*tan(phi/3)", "3*pi/2"),
    "tangent_m5": ("5*tan(phi/5)", "2*pi"), "tangent_m6": ("6*tan(phi/6)", "2*pi")}
"""p(φ) (Table 1, eq 35, the families of eq 36) and φ_max: the fold of m sin(φ/m) at mπ/2, the pole
of m tan(φ/m) at mπ/2, else 2π."""
NUMPY_NAMED = ("rotation_vector", "cayley_gibbs_rodrigues", "euler_rodrigues", "wiener_milenkovic",
               "linear", "det_h_one", "sine_m4")
DERIVATIVES = {"rotation_derivative": "R", "rotation_transpose_derivative": "R_T",
               "tangent_derivative": "H", "tangent_transpose_derivative": "H_T",
               "tangent_inverse_derivative": "H_inverse", "angular_acceleration": "alpha"}
WORKING_DIGITS = 60
"""The ambient precision of every reference call: tests/reference.py rounds what it returns from
products done outside its own precision blocks (H⁻¹ w, H w, the quaternion product of compose) to
the ambient precision, and κ perturbs inputs by 10⁻³⁰ (at 15 digits compose's reference was 10⁻¹⁶
off and its κ read 10¹⁴)."""
BATCH = 16
"""The rows of every Python call (:func:`python_values`): at least the longest sweep."""
DERIVATIVE_ULP = 8.0
"""The derivatives' documented target (docs/accuracy.md, derivatives): ≤ 8 ulp of the largest entry,
or ≤ 8 κ ulp."""


def angles(phi_max: float, dtype: Any) -> list[float]:
    """The |φ| of the sweep below φ_max (float32 from its smallest normal): tiny, the series range,
    the switches to the closed forms, moderate and large angles, φ_max − 10⁻³ and φ_max − 10⁻⁶.
    Not 0.5 φ_max: for φ_max = 2π that is π, where rescale's choice between p and its flip follows
    the sign of e0 = cos(φ/2) ≈ 0 (both right, 10⁷ ulp apart)."""
    smallest = 1e-300 if dtype == np.float64 else float(np.finfo(np.float32).tiny)
    fixed = [0.0, smallest, 1e-30, 1e-8, 1e-4, 1e-2, 0.05, 0.2]
    upper = [f * phi_max for f in (0.3, 0.6, 0.8, 0.95, 0.99)] + [phi_max - 1e-3, phi_max - 1e-6]
    return sorted({a for a in fixed if a < 0.25 * phi_max} | set(upper))


def derivative_points(sweep: np.ndarray, label: str) -> list[int]:
    """The indices of the sweep where the derivatives are checked (their references cost ~0.2 s a
    point): float64 at p = 0, the point nearest 10⁻⁸ (series), 0.6 φ_max (closed form) and the last
    (the edge); float32 at the last two."""
    middle = int(np.argmin(np.abs(sweep - 0.6 * sweep[-1])))
    if label == "float32":
        return sorted({middle, len(sweep) - 1})
    small = int(np.argmin(np.abs(np.log10(np.maximum(sweep, 1e-300)) + 8)))
    return sorted({0, small, middle, len(sweep) - 1})


@dataclass
class Points:
    """The inputs of one (family, precision) and their references."""

    angle: np.ndarray
    p: np.ndarray
    p2: np.ndarray
    w: np.ndarray
    v: np.ndarray
    e: np.ndarray
    r: np.ndarray
    """Rows of R̃: the rotation of e rounded to the format, row-major (from_rotation_matrix)."""
    refs: list[dict[str, Any]]
    """Per point: {function: reference value} for every function of ALL."""


class Family:
    """A generating function with its independent reference and cached κ."""

    def __init__(self, name: str, expression: str, phi_max: str | None = None, cancels: bool = False) -> None:
        self.name = name
        self.function = GeneratingFunction(expression, cancels=cancels, phi_max_text=phi_max)
        self.reference = Reference(self.function)
        self._kappa: dict[tuple[str, int, str], float] = {}
        self._derivatives: dict[tuple[str, int], dict[str, Any]] = {}

    @cache  # noqa: B019 (one Family per name, kept for the session)
    def points(self, label: str) -> Points:
        dtype = DTYPES[label]
        phi_max = float(self.function.phi_max)
        p_max = float(self.function.p_max())
        epsilon = float(np.finfo(dtype).eps)
        rng = np.random.default_rng(sum(map(ord, self.name + label)))
        rows: dict[str, list[Any]] = {k: [] for k in ("angle", "p", "w", "v", "e", "r")}
        sweep = angles(phi_max, dtype)
        with mpmath.workdps(40):
            sizes = [float(self.function.value(mpmath.mpf(a))) for a in sweep]
        for k, angle in enumerate(sweep):
            axes = rng.normal(size=(3, 3))
            axes /= np.linalg.norm(axes, axis=1)[:, None]
            p = (sizes[k] * axes[0]).astype(dtype)
            if np.linalg.norm(p.astype(np.float64)) >= p_max * (1 - 2 * epsilon):
                continue
            with mpmath.workdps(40):
                half = mpmath.mpf(angle) / 2
                e = [float(mpmath.cos(half))] + [float(mpmath.sin(half) * a) for a in axes[2]]
                r = [float(x) for x in _entries(rodrigues(mpmath.mpf(angle), list(axes[2])))]
            rows["angle"].append(angle)
            rows["p"].append(p)
            rows["w"].append(rng.normal(size=3).astype(dtype))
            rows["v"].append(rng.normal(size=3).astype(dtype))
            rows["r"].append(np.array(r).astype(dtype))
            rows["e"].append((np.array(e) * (-1.0 if rng.random() < 0.5 else 1.0)).astype(dtype))
        arrays = {k: np.array(v, dtype=np.float64 if k == "angle" else dtype) for k, v in rows.items()}
        # compose(p, p2) with p2 another point of the sweep (its reference state is there already),
        # one well inside the range: next to a fold or pole p2 would make compose's κ ~1e14 and hide
        # a compose with its factors swapped
        inner = np.flatnonzero((arrays["angle"] > 0) & (arrays["angle"] <= 0.8 * phi_max))
        second = inner[(np.arange(len(arrays["angle"])) + 3) % len(inner)]
        arrays["p2"] = arrays["p"][second]
        with mpmath.workdps(WORKING_DIGITS):
            refs = [self._references(i, arrays, second) for i in range(len(arrays["angle"]))]
        return Points(refs=refs, **arrays)

    def _references(self, i: int, arrays: dict[str, np.ndarray], second: np.ndarray) -> dict[str, Any]:
        p, p2, w, e = (_mp(arrays[k][i]) for k in ("p", "p2", "w", "e"))
        guess = float(arrays["angle"][i]) or None
        out = kinematic(self.reference.state(p, guess), w)
        out["from_quaternion"] = self.reference.from_quaternion(e)
        out["rescale"] = self.reference.rescale(p, guess)
        other = float(arrays["angle"][second[i]])
        out["compose"] = self.reference.compose(p, p2, (guess, other))
        out["from_rotation_matrix"] = self._from_rotation_matrix(_mp(arrays["r"][i]))
        return out

    def _from_rotation_matrix(self, r: list[Any]) -> list[Any]:
        """p of the given (rounded, not exactly orthogonal) R̃: Shepperd's largest pivot (eqs 61–65)
        at high precision, then :meth:`Reference.from_quaternion`."""
        with mpmath.workdps(self.reference.digits + 20):
            return self.reference.from_quaternion(_shepperd(r))

    def kappa(self, function: str, label: str, i: int) -> float:
        """κ of ``function`` at point i (perturbing its inputs), computed once."""
        key = (label, i, function)
        if key not in self._kappa:
            points, tiny = self.points(label), float(np.finfo(DTYPES[label]).tiny)
            p, p2, w, e = (_mp(getattr(points, k)[i]) for k in ("p", "p2", "w", "e"))
            guess = float(points.angle[i]) or None
            if function == "from_rotation_matrix":
                ref = points.refs[i][function]
                with mpmath.workdps(WORKING_DIGITS):
                    found = condition(lambda x: {"f": self._from_rotation_matrix(x)}, _mp(points.r[i]),
                                      {"f": ref}, {"f": scale(ref, False, tiny)})
                self._kappa[key] = found["f"]
                return self._kappa[key]
            with mpmath.workdps(WORKING_DIGITS):
                found = condition_of(self.reference, function, points.refs[i],
                                     lambda x: kinematic(self.reference.state(x, guess), w), p, p2, e, guess,
                                     tiny)
            self._kappa.update({(label, i, f): k for f, k in found.items()})
        return self._kappa[key]

    def derivative_reference(self, label: str, i: int) -> dict[str, Any]:
        """{derivative function: reference} at point i: ∂(T w)/∂p (:meth:`Reference.derivative`) and
        α = d(H ṗ)/dt with ṗ = w, p̈ = v (:meth:`Reference.along`)."""
        key = (label, i)
        if key not in self._derivatives:
            points = self.points(label)
            p, w, v = (_mp(getattr(points, k)[i]) for k in ("p", "w", "v"))
            with mpmath.workdps(WORKING_DIGITS):
                self._derivatives[key] = self._derivatives_at(p, w, v)
        return self._derivatives[key]

    def _derivatives_at(self, p: list[Any], w: list[Any], v: list[Any]) -> dict[str, Any]:
        out: dict[str, Any] = {f: self.reference.derivative(p, w, t) for f, t in DERIVATIVES.items()
                               if t != "alpha"}
        out["angular_acceleration"] = self.reference.along(p, w, v)[1]
        return out

    def derivative_kappa(self, function: str, label: str, i: int) -> float:
        """κ of a derivative function at point i: :func:`measure.condition` over the components of p
        and w (and p̈ for α), relative to the largest entry."""
        points = self.points(label)
        p, w, v = (_mp(getattr(points, k)[i]) for k in ("p", "w", "v"))
        base = {function: self.derivative_reference(label, i)[function]}

        def at(x: list[Any]) -> dict[str, Any]:
            if function == "angular_acceleration":
                return {function: self.reference.along(x[:3], x[3:6], x[6:])[1]}
            return {function: self.reference.derivative(x[:3], x[3:6], DERIVATIVES[function])}

        inputs = p + w + (v if function == "angular_acceleration" else [])
        tiny = float(np.finfo(DTYPES[label]).tiny)
        with mpmath.workdps(WORKING_DIGITS):
            return condition(at, inputs, base, {function: scale(base[function], False, tiny)})[function]


def _mp(values: np.ndarray) -> list[Any]:
    return [mpmath.mpf(float(v)) for v in values]


@cache
def family(name: str) -> Family:
    """The named family (PAPER) or a corpus expression (tests/corpus.py)."""
    if name in PAPER:
        return Family(name, *PAPER[name])
    from .corpus import by_expression

    entry = by_expression(name)
    return Family(name, entry.expression, entry.phi_max, entry.cancels)


# -- outputs -----------------------------------------------------------------------------------

def python_values(module: Any, to: Callable[[np.ndarray], Any], back: Callable[[Any], np.ndarray],
                  points: Points, derivatives: bool) -> dict[str, np.ndarray]:
    """Every function of a generated NumPy, JAX or PyTorch module on the batch of ``points``, padded
    to BATCH rows by repeating them (one shape for every family: JAX compiles each operation once)."""
    rows = np.arange(max(BATCH, len(points.p))) % len(points.p)
    p, p2, w, v, e = (to(getattr(points, k)[rows]) for k in ("p", "p2", "w", "v", "e"))
    r = to(points.r[rows].reshape(-1, 3, 3))
    out: dict[str, Any] = {f: getattr(module, f)(p) for f in MATRICES}
    out.update(pdot=module.pdot(p, w), omega=module.omega(p, w), angle=module.angle(p),
               tangent_det=module.tangent_det(p), to_quaternion=module.to_quaternion(p),
               from_quaternion=module.from_quaternion(e), rescale=module.rescale(p),
               compose=module.compose(p, p2), from_rotation_matrix=module.from_rotation_matrix(r))
    if derivatives:
        out.update({f: getattr(module, f)(p, w) for f in DERIVATIVES if f != "angular_acceleration"})
        out["angular_acceleration"] = module.angular_acceleration(p, w, v)
    return {f: back(value)[:len(points.p)] for f, value in out.items()}


def c_source(headers: list[str]) -> str:
    """The kinematic wrappers of tests/c_harness.py and the operation wrappers, one unit."""
    from .c_harness import translation_unit

    return translation_unit(headers, batches=False) + operation_wrappers(headers, C_CALLS)


def c_values(library: Any, header: str, points: Points, label: str) -> dict[str, np.ndarray]:
    """Every C function (the nine kinematic ones and the quaternion operations) on ``points``."""
    from symrot.backends.c_backend import FUNCTIONS as C_FUNCTIONS

    precision = "double" if label == "float64" else "float"
    out = {spec.name: library.call(header, spec, precision, points.p, points.w) for spec in C_FUNCTIONS}
    inputs = {"p": points.p, "p2": points.p2, "e": points.e, "R": points.r}
    for name, (names, _width) in C_CALLS.items():
        out[name] = np.array([call_operation(library.dll, header, name, DTYPES[label],
                                             *(inputs[n][i] for n in names), operations=C_CALLS)
                              for i in range(len(points.p))])
    return out


def errors(family_: Family, label: str, function: str, values: np.ndarray,
           only: Callable[[float], bool] = lambda angle: True) -> list[str]:
    """The points (of those whose angle passes ``only``) where ``values`` (one row per point) misses
    the documented target: ulp > target and ulp > target κ (κ computed only there); 'φ=…: N ulp (κ K)'
    each."""
    points = family_.points(label)
    epsilon, tiny = float(np.finfo(DTYPES[label]).eps), float(np.finfo(DTYPES[label]).tiny)
    derivative = function in DERIVATIVES
    target = DERIVATIVE_ULP if derivative else TARGET_ULP
    misses = []
    for i in derivative_points(points.angle, label) if derivative else range(len(points.angle)):
        angle = points.angle[i]
        if not only(float(angle)):
            continue
        ref = family_.derivative_reference(label, i)[function] if derivative else points.refs[i][function]
        value = np.asarray(values[i])
        if _is_nan(ref):
            if not np.all(np.isnan(value)):
                misses.append(f"φ={angle:.6g}: {value.ravel().tolist()} where NaN is expected")
            continue
        error = ulp_error(value, ref, epsilon, function in MATRICES, tiny)
        if error <= target:
            continue
        kappa = (family_.derivative_kappa if derivative else family_.kappa)(function, label, i)
        if not np.isfinite(error) or error > target * max(1.0, kappa):
            misses.append(f"φ={angle:.6g}: {error:.3g} ulp (κ {kappa:.3g})")
    return misses


def _is_nan(ref: Any) -> bool:
    return any(mpmath.isnan(v) for v in _entries(ref))


def quiet(function: Callable[[], dict[str, np.ndarray]]) -> dict[str, np.ndarray]:
    """``function()`` with floating-point warnings off (NaN outside the range is documented)."""
    with warnings.catch_warnings(), np.errstate(all="ignore"):
        warnings.simplefilter("ignore")
        return function()


__all__ = ["ALL", "DERIVATIVES", "DTYPES", "FUNCTIONS", "NUMPY_NAMED", "PAPER", "Family", "Points", "angles",
           "c_source", "c_values", "derivative_points", "errors", "family", "python_values", "quiet"]
