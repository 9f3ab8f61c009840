"""Accuracy of the generated operations on rotations of any size (issue 6), against mpmath.

Same sweep, references and error measure as :mod:`accuracy` (imported from it): for every |φ| of
the sweep, with random axes, in float64 and float32:

* ``to_quaternion(p)``: e₀ = cos(φ/2), **e** = sin(φ/2) **p**/|p| (eqs 74–75);
* ``rescale(p)``: **p** if e₀ ≥ 0, else the parameters of −e (eqs 40–47);
* ``from_quaternion(e)``: e the rounded quaternion of the rotation, with a random overall sign;
  reference φ = 2 atan2(|**e**|, |e₀|), **p** = p(φ) **e**/|**e**| (sign of e₀), NaN when
  φ ≥ φ_max;
* ``compose(p1, p2)``: p₂ a rotation of the same size about another axis (so two 10⁻²⁰⁰ rotations
  are composed, and two near-φ_max ones, whose product is rescaled or, for φ_max ≤ π, NaN);
  reference e₃ = e₂ ∘ e₁ then ``from_quaternion``;
* ``from_rotation_matrix(R)``: R the rounded exact rotation matrix; reference: Shepperd's pivot
  (eqs 61–65) at 50 digits, then ``from_quaternion`` — the function of the *given* (slightly
  non-orthogonal) matrix.

Errors relative to the largest entry of the reference vector; κ as in :mod:`accuracy`.
"""

from __future__ import annotations

import tempfile
import warnings
from collections.abc import Callable
from functools import partial
from pathlib import Path
from typing import Any

import mpmath
import numpy as np
from accuracy_common import DIGITS, DTYPES, Reference, Worst, condition, load_module, subject, sweep

OPERATIONS = ("to_quaternion", "from_quaternion", "from_rotation_matrix", "compose", "rescale")


class OperationReference:
    """50-digit quaternion conversions for one parameterization."""

    def __init__(self, reference: Reference) -> None:
        self.reference = reference
        self.phi_max = reference.phi_max

    def quaternion(self, p: list[Any], guess: float) -> list[Any]:
        x = sum(v * v for v in p)
        if x == 0:
            return [mpmath.mpf(1), mpmath.mpf(0), mpmath.mpf(0), mpmath.mpf(0)]
        phi = self.reference.coefficients(x, guess)["__phi__"]
        factor = mpmath.sin(phi / 2) / mpmath.sqrt(x)
        return [mpmath.cos(phi / 2)] + [factor * v for v in p]

    def parameters(self, e: list[Any]) -> list[Any]:
        vector = e[1:]
        norm = mpmath.sqrt(sum(v * v for v in vector))
        if norm == 0:
            return [mpmath.mpf(0)] * 3
        sign = -1 if e[0] < 0 else 1
        phi = 2 * mpmath.atan2(norm, abs(e[0]))
        if phi >= self.phi_max:
            return [mpmath.nan] * 3
        extra = int(3 * max(0.0, -float(mpmath.log10(phi))))
        with mpmath.workdps(DIGITS + extra):  # p(φ) may cancel to O(φ³) (eq 35)
            magnitude = self.reference.p_of_phi(phi)
        return [sign * magnitude * v / norm for v in vector]


def _shepperd(r: list[Any]) -> list[Any]:
    (r00, r01, r02, r10, r11, r12, r20, r21, r22) = r
    trace = r00 + r11 + r22
    rows = [[1 + trace, r21 - r12, r02 - r20, r10 - r01],
            [r21 - r12, 1 + r00 - r11 - r22, r01 + r10, r02 + r20],
            [r02 - r20, r01 + r10, 1 - r00 + r11 - r22, r12 + r21],
            [r10 - r01, r02 + r20, r12 + r21, 1 - r00 - r11 + r22]]
    pivots = [trace, r00, r11, r22]
    return rows[pivots.index(max(pivots))]


def _rotation(e: list[Any]) -> list[Any]:
    w, a, b, c = e
    return [1 - 2 * (b * b + c * c), 2 * (a * b - w * c), 2 * (a * c + w * b),
            2 * (a * b + w * c), 1 - 2 * (a * a + c * c), 2 * (b * c - w * a),
            2 * (a * c - w * b), 2 * (b * c + w * a), 1 - 2 * (a * a + b * b)]


def _product(b: list[Any], a: list[Any]) -> list[Any]:
    """b ∘ a (eq 53): the quaternion of R(b) R(a)."""
    return [b[0] * a[0] - (b[1] * a[1] + b[2] * a[2] + b[3] * a[3]),
            b[0] * a[1] + a[0] * b[1] + (b[2] * a[3] - b[3] * a[2]),
            b[0] * a[2] + a[0] * b[2] + (b[3] * a[1] - b[1] * a[3]),
            b[0] * a[3] + a[0] * b[3] + (b[1] * a[2] - b[2] * a[1])]


def _rescaled(ops: OperationReference, quaternion: Callable[[list[Any]], list[Any]], p: list[Any]
              ) -> list[Any]:
    e = quaternion(p)
    return p if e[0] >= 0 else ops.parameters(e)


def _composed(ops: OperationReference, quaternion: Callable[[list[Any]], list[Any]], q: list[Any]
              ) -> list[Any]:
    return ops.parameters(_product(quaternion(q[3:]), quaternion(q[:3])))


def _as_output(exact: Callable[[list[Any]], list[Any]], inputs: list[Any]) -> dict[str, Any]:
    return {"f": exact(inputs)}


def _error(value: np.ndarray, reference: list[Any], epsilon: float, tiny: float) -> tuple[float, float]:
    """(ulp error relative to the largest entry, that scale); NaN references must give NaN."""
    if any(mpmath.isnan(v) for v in reference):
        return (0.0 if bool(np.all(np.isnan(value))) else float("inf")), 1.0
    ref = np.array([float(v) for v in reference])
    scale = max(tiny, float(np.max(np.abs(ref))))
    error = float(np.max(np.abs(value.astype(np.float64) - ref)))
    return (error / (scale * epsilon) if np.isfinite(error) else float("inf")), scale


def measure_operations(name: str, points: int, seed: int = 2, edge: float = 1e-6
                       ) -> dict[tuple[str, str, str], Worst]:
    """{(operation, precision, 'plan'): Worst} over the sweep."""
    _derivation, plan, reference = subject(name)
    ops = OperationReference(reference)
    angles = sweep(plan.phi_max, points, edge)
    rng = np.random.default_rng(seed)
    worst: dict[tuple[str, str, str], Worst] = {}
    with tempfile.TemporaryDirectory() as tmp, mpmath.workdps(DIGITS):
        module = load_module(plan, Path(tmp))
        for angle in angles:
            axes = rng.normal(size=(2, 3))
            axes /= np.linalg.norm(axes, axis=1)[:, None]
            flip = -1.0 if rng.random() < 0.5 else 1.0
            extra = int(3 * max(0.0, -np.log10(angle))) if angle > 0 else 0
            with mpmath.workdps(DIGITS + extra):
                size = float(reference.p_of_phi(mpmath.mpf(angle)))
                half = mpmath.mpf(angle) / 2
                e_exact = [float(mpmath.cos(half))] + [float(mpmath.sin(half) * a) for a in axes[0]]
            guess = float(angle) if angle > 0 else 1.0
            for label, dtype in DTYPES.items():
                epsilon, tiny = float(np.finfo(dtype).eps), float(np.finfo(dtype).tiny)
                p1, p2 = (size * axes).astype(dtype)
                p1_mp = [mpmath.mpf(float(v)) for v in p1]
                p2_mp = [mpmath.mpf(float(v)) for v in p2]
                edge_of_range = min(plan.p_max, reference.p_of_phi(reference.phi_max))
                if max(mpmath.sqrt(sum(v * v for v in q)) for q in (p1_mp, p2_mp)) >= \
                        edge_of_range * (1 - 2 * epsilon):
                    continue
                e_in = (flip * np.array(e_exact)).astype(dtype)
                e_mp = [mpmath.mpf(float(v)) for v in e_in]
                r_in = np.array([float(v) for v in _rotation([mpmath.mpf(v) for v in e_exact])]).astype(dtype)
                r_mp = [mpmath.mpf(float(v)) for v in r_in]
                with warnings.catch_warnings():
                    warnings.simplefilter("error")
                    values = {"to_quaternion": module.to_quaternion(p1), "rescale": module.rescale(p1),
                              "from_quaternion": module.from_quaternion(e_in),
                              "compose": module.compose(p1, p2),
                              "from_rotation_matrix": module.from_rotation_matrix(r_in.reshape(3, 3))}
                quaternion = partial(ops.quaternion, guess=guess)
                cases: dict[str, tuple[Any, list[Any]]] = {
                    "to_quaternion": (quaternion, p1_mp),
                    "rescale": (partial(_rescaled, ops, quaternion), p1_mp),
                    "from_quaternion": (ops.parameters, e_mp),
                    "compose": (partial(_composed, ops, quaternion), p1_mp + p2_mp),
                    "from_rotation_matrix": (lambda r: ops.parameters(_shepperd(r)), r_mp),
                }
                for operation, (exact, inputs) in cases.items():
                    value = np.asarray(values[operation])
                    ref = exact(inputs)
                    ulp, scale = _error(value, ref, epsilon, tiny)
                    nan_ref = any(mpmath.isnan(v) for v in ref)
                    kappa = 0.0 if nan_ref else condition(partial(_as_output, exact), inputs,
                                                          {"f": ref}, {"f": scale})["f"]
                    worst.setdefault((operation, label, "plan"), Worst()).add(ulp, float(angle), kappa)
    return worst


if __name__ == "__main__":
    print("bench/accuracy_operations.py is part of bench/accuracy.py: run that (it measures both)")
