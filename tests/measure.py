"""The error measure and condition number of docs/accuracy.md, shared by tests and benchmarks.

* :func:`ulp`: the error of a computed value in units of ε of its format — matrices
  max|M − M_ref| / (ε · max(1, max|M_ref|)), vectors and scalars max|v − v_ref| / (ε · max|v_ref|)
  (at least the smallest normal: a subnormal result cannot carry 4 ε relative accuracy).
* :func:`condition`: κ, the relative condition number of each output with respect to componentwise
  relative changes of the input, by perturbing each input component by 10⁻³⁰ (relative) in a
  high-precision reference. An error ≤ 4 κ ulp is no larger than a 4 ε change of the input causes.
* :class:`Worst`: the worst point of a sweep (ulp, and ulp / max(1, κ)).

Used by bench/accuracy.py, bench/accuracy_corpus.py and tests/test_independent_values.py.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import mpmath
import numpy as np

TARGET_ULP = 4.0
"""The accuracy the docs claim: ≤ 4 ulp, or ≤ 4 κ ulp where the input is ill-conditioned."""


def entries(value: Any) -> list[Any]:
    """The entries of an mpmath matrix (row by row) or of a sequence, as a flat list."""
    if isinstance(value, mpmath.matrix):
        return [value[i, j] for i in range(value.rows) for j in range(value.cols)]
    return list(value)


def scale(reference: Any, matrix: bool, tiny: float) -> float:
    """The denominator of :func:`ulp` (without ε): max(1, max|entry|) for a matrix, else
    max(tiny, max|entry|); 0 where the reference is NaN (no κ there)."""
    if any(mpmath.isnan(v) for v in entries(reference)):
        return 0.0
    biggest = max(float(abs(v)) for v in entries(reference))
    return max(1.0, biggest) if matrix else max(tiny, biggest)


def ulp(value: np.ndarray, reference: Any, epsilon: float, matrix: bool, tiny: float) -> float:
    """Error of ``value`` against the high-precision ``reference`` (a 3×3 mpmath matrix when
    ``matrix``, else a sequence or column) in units of ``epsilon``; inf when not finite."""
    ref = np.array([float(v) for v in entries(reference)])
    if matrix:
        ref = ref.reshape(3, 3)
    denominator = scale(reference, matrix, tiny) if ref.size else 0.0
    error = float(np.max(np.abs(np.asarray(value).astype(np.float64).reshape(ref.shape) - ref)))
    if not np.isfinite(error):
        return float("inf")
    if denominator == 0:
        return 0.0 if error == 0 else float("inf")
    return error / (denominator * epsilon)


def condition(reference: Callable[[list[Any]], dict[str, Any]], inputs: list[Any],
              base: dict[str, Any], scales: dict[str, float]) -> dict[str, float]:
    """κ_f = max over the entries of output f of Σ_i |∂f/∂x_i| |x_i| / scales[f].

    ``reference(inputs)`` gives every output f at the inputs (high precision), ``base`` its values at
    ``inputs``; each nonzero input is moved by a relative 10⁻³⁰ (run at ≥ 50 digits).
    """
    delta = mpmath.mpf(10) ** -30
    totals: dict[str, np.ndarray] = {}
    for i, value in enumerate(inputs):
        if value == 0:
            continue
        moved = list(inputs)
        moved[i] = value * (1 + delta)
        other = reference(moved)
        for f, ref in base.items():
            pairs = zip(entries(other[f]), entries(ref), strict=True)
            diff = np.array([float(abs(a - b)) for a, b in pairs])
            totals[f] = totals.get(f, 0) + diff / float(delta)
    return {f: float(np.max(totals[f])) / scales[f] if f in totals and scales[f] > 0 else 0.0
            for f in base}


@dataclass
class Worst:
    """The worst point of one (function, precision, kind) over the sweep."""

    ulp: float = 0.0
    at: float = 0.0
    kappa: float = 1.0
    excess: float = 0.0
    """max over points of ulp / max(1, κ): ≤ 4 means at most the error of a 4 ε relative input change."""
    excess_at: float = 0.0
    """The angle of that worst ulp/κ: a miss is there, not always at ``at`` (p = φ − φ³/6 + φ⁵/120:
    10¹² ulp at its fold, within κ, but 9·10⁵ κ ulp at φ = 0.1)."""

    def add(self, ulp: float, at: float, kappa: float) -> None:
        ulp = float("inf") if np.isnan(ulp) else ulp
        if ulp > self.ulp or (ulp == self.ulp == 0 and at == 0):
            self.ulp, self.at, self.kappa = ulp, at, kappa
        excess = ulp / max(1.0, kappa)
        if excess > self.excess:
            self.excess, self.excess_at = excess, at
