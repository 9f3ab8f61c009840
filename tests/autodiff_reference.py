"""60-digit references for the derivatives of R, H and φ with respect to p (issue 20).

Independent of symrot: built on :mod:`tests.reference` (p(φ) parsed by SymPy alone, φ from |p| by
a safeguarded mpmath Newton iteration) and the definitions of Bauchau & Trainelli (2003):

* R from eq (1), R = I + sin φ (n×) + 2 sin²(φ/2) (n×)², and ∂R/∂p_k by the chain rule, with
  ∂φ/∂p = n / p′(φ) (implicit function theorem) and ∂n/∂p_k = (e_k − n n_k)/|p|;
* H from its definition (eq 20 with eq 9): column i = axial((∂R/∂p_i) Rᵀ), H⁻¹ by mpmath;
* second derivatives (of R) and first derivatives of H and H⁻¹ by a central difference of those analytic
  first derivatives, with a step 10⁻⁽ᵈ⁺¹⁰⁾ max(|p|, 1) at 2d + 30 digits (they are smooth in p);
* ∂φ/∂p = φ′ n and ∂²φ/∂p² = φ″ n nᵀ + (φ′/|p|)(I − n nᵀ), φ′ = 1/p′(φ), φ″ = −p″(φ) φ′³.

At p = 0 (κ = 1): ∂R/∂p_k = (e_k×) exactly, the (a×)-form of the gradient at the identity.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import Any

import mpmath
import numpy as np

from .reference import DIGITS, GeneratingFunction, skew


def _axial(w: mpmath.matrix) -> list[Any]:
    return [(w[2, 1] - w[1, 2]) / 2, (w[0, 2] - w[2, 0]) / 2, (w[1, 0] - w[0, 1]) / 2]


class AutodiffReference:
    """Derivatives with respect to p at ``digits`` correct digits."""

    def __init__(self, function: GeneratingFunction, digits: int = DIGITS) -> None:
        self.g = function
        self.digits = digits

    def _slope(self, phi: Any) -> Any:
        """p′(φ) with the guard digits of its size (p′ of φ − sin φ cancels at small φ)."""
        with mpmath.workdps(mpmath.mp.dps + self.g.guard(abs(phi))):
            return +self.g.dp(phi)

    def _polar(self, p: Sequence[Any]) -> tuple[Any, Any, list[Any]]:
        s = mpmath.sqrt(sum(mpmath.mpf(c) ** 2 for c in p))
        return s, self.g.inverse(s), [mpmath.mpf(c) / s for c in p]

    def _rotation_and_jacobian(self, p: Sequence[Any]) -> tuple[mpmath.matrix, list[mpmath.matrix]]:
        """R(p) and [∂R/∂p_k]."""
        if all(c == 0 for c in p):
            return mpmath.eye(3), [skew([1 if i == k else 0 for i in range(3)]) for k in range(3)]
        s, phi, n = self._polar(p)
        big_n = skew(n)
        n2 = big_n * big_n
        sin, cos, versine = mpmath.sin(phi), mpmath.cos(phi), 2 * mpmath.sin(phi / 2) ** 2
        rotation = mpmath.eye(3) + sin * big_n + versine * n2
        rate = 1 / self._slope(phi)
        columns = []
        for k in range(3):
            dn = skew([((1 if i == k else 0) - n[i] * n[k]) / s for i in range(3)])
            columns.append((cos * big_n + sin * n2) * (rate * n[k]) + sin * dn
                           + versine * (dn * big_n + big_n * dn))
        return rotation, columns

    def _tangent(self, p: Sequence[Any]) -> mpmath.matrix:
        rotation, columns = self._rotation_and_jacobian(p)
        tangent = mpmath.matrix(3, 3)
        for i, column in enumerate(columns):
            for row, value in enumerate(_axial(column * rotation.T)):
                tangent[row, i] = value
        return tangent

    def _difference(self, function: Callable[[list[Any]], mpmath.matrix], p: Sequence[float]
                    ) -> list[mpmath.matrix]:
        """[∂function/∂p_j] by central differences at 2d + 30 digits."""
        with mpmath.workdps(2 * self.digits + 30):
            base = [mpmath.mpf(c) for c in p]
            size = max(mpmath.sqrt(sum(c * c for c in base)), mpmath.mpf(1))  # smooth in p near 0
            step = size * mpmath.mpf(10) ** (-(self.digits + 10))
            out = []
            for j in range(3):
                plus = [c + (step if i == j else 0) for i, c in enumerate(base)]
                minus = [c - (step if i == j else 0) for i, c in enumerate(base)]
                out.append((function(plus) - function(minus)) / (2 * step))
            return out

    def rotation_jacobian(self, p: Sequence[float]) -> np.ndarray:
        """∂R_ab/∂p_k as an array (3, 3, 3) indexed [a, b, k]."""
        with mpmath.workdps(self.digits + 20):
            columns = self._rotation_and_jacobian([mpmath.mpf(c) for c in p])[1]
            return np.array([[[float(columns[k][a, b]) for k in range(3)] for b in range(3)]
                             for a in range(3)])

    def rotation_hessian(self, p: Sequence[float]) -> np.ndarray:
        """∂²R_ab/∂p_k∂p_j as an array (3, 3, 3, 3) indexed [a, b, k, j]."""
        def jacobian(q: list[Any]) -> mpmath.matrix:
            columns = self._rotation_and_jacobian(q)[1]
            return mpmath.matrix([[columns[k][a, b] for k in range(3)] for a in range(3) for b in range(3)])

        blocks = self._difference(jacobian, p)
        return np.array([[[[float(blocks[j][3 * a + b, k]) for j in range(3)] for k in range(3)]
                          for b in range(3)] for a in range(3)])

    def tangent_jacobian(self, p: Sequence[float]) -> np.ndarray:
        """∂H_ab/∂p_j as an array (3, 3, 3) indexed [a, b, j]."""
        blocks = self._difference(self._tangent, p)
        return np.array([[[float(blocks[j][a, b]) for j in range(3)] for b in range(3)] for a in range(3)])

    def tangent_inverse_jacobian(self, p: Sequence[float]) -> np.ndarray:
        """∂(H⁻¹)_ab/∂p_j as an array (3, 3, 3) indexed [a, b, j]."""
        blocks = self._difference(lambda q: mpmath.inverse(self._tangent(q)), p)
        return np.array([[[float(blocks[j][a, b]) for j in range(3)] for b in range(3)] for a in range(3)])

    def angle_derivatives(self, p: Sequence[float]) -> tuple[np.ndarray, np.ndarray]:
        """(∂φ/∂p, ∂²φ/∂p²) at p ≠ 0."""
        with mpmath.workdps(self.digits + 20):
            s, phi, n = self._polar([mpmath.mpf(c) for c in p])
            rate = 1 / self._slope(phi)
            with mpmath.workdps(2 * self.digits + 30):
                curvature = mpmath.diff(self._slope, phi)
            second = -curvature * rate ** 3
            gradient = np.array([float(rate * c) for c in n])
            hessian = np.array([[float(second * n[i] * n[j] + rate / s * ((1 if i == j else 0) - n[i] * n[j]))
                                 for j in range(3)] for i in range(3)])
            return gradient, hessian

    def point(self, phi: Any, axis: Sequence[float], dtype: type) -> np.ndarray:
        """p = p(φ) u rounded to ``dtype`` (u normalized at high precision)."""
        with mpmath.workdps(self.digits + 20):
            u = [mpmath.mpf(c) for c in axis]
            norm = mpmath.sqrt(sum(c * c for c in u))
            value = self.g.value(mpmath.mpf(phi))
            return np.array([float(value * c / norm) for c in u]).astype(dtype)
