"""What the C header offers, and how a tensor or vector function is assembled from its coefficients.

:data:`FUNCTIONS` lists the per-vector functions of every header (each in double and, suffixed
``_f``, float; matrix ones also as ``_batch`` kernels); :func:`tensor_entries` and
:func:`applied_entries` write T = c0 I + c1 (p×) + c2 (p×)² = t I + c1 (p×) + c2 p pᵀ and T v entry by
entry, for the single calls (:mod:`symrot.backends.c_writer`) and the batch kernels
(:mod:`symrot.backends.c_batch`).
"""

from __future__ import annotations

from collections.abc import Collection
from dataclasses import dataclass
from typing import Literal

import sympy as sp

P = sp.symbols("p[0] p[1] p[2]", real=True)
"""The parameter vector p as the C array it is in every signature."""


FunctionKind = Literal["scalar", "matrix", "vector"]


@dataclass(frozen=True)
class CFunction:
    """One function of the generated header (each exists for ``double`` and, suffixed ``_f``, float)."""

    name: str
    kind: FunctionKind
    equation: str
    summary: str

    @property
    def width(self) -> int:
        """Outputs per parameter vector."""
        return {"scalar": 1, "vector": 3, "matrix": 9}[self.kind]

    def shape(self, n: int) -> tuple[int, ...]:
        return {"scalar": (n,), "vector": (n, 3), "matrix": (n, 3, 3)}[self.kind]


FUNCTIONS: tuple[CFunction, ...] = (
    CFunction("angle", "scalar", "11", "rotation angle phi = |phi(p)|, the inverse of p(phi)"),
    CFunction("rotation_matrix", "matrix", "14", "rotation tensor R"),
    CFunction("tangent", "matrix", "22", "tangent tensor H, omega = H pdot (eq 20)"),
    CFunction("tangent_inverse", "matrix", "26", "inverse tangent tensor H^-1, pdot = H^-1 omega"),
    CFunction("tangent_det", "scalar", "24", "det H = mu nu^2"),
    CFunction("root_matrix", "matrix", "81", "square root G of R, G G = R"),
    CFunction("root_tangent", "matrix", "83", "tangent K of the square root, gamma = K pdot (82)"),
    CFunction("pdot", "vector", "25", "pdot = H^-1 omega"),
    CFunction("omega", "vector", "20", "omega = H pdot"),
)


# -- outputs from coefficients ---------------------------------------------------------------------
def tensor_coefficients(tensor: str, across: Collection[str]) -> list[str]:
    """The coefficients a tensor's outputs read: its across-axis part t = c₀ − c₂|p|² where the plan
    has it (``T_across``, :meth:`~symrot.plan.ir.EvaluationPlan.across_tensors`), else c₀; c₁; c₂."""
    first = f"{tensor}_across" if tensor in across else f"{tensor}_0"
    return [first, f"{tensor}_1", f"{tensor}_2"]


def across_value(tensor: str, across: Collection[str], first: sp.Expr, c: sp.Expr, x: sp.Expr) -> sp.Expr:
    """t = c₀ − c₂ x from the values of :func:`tensor_coefficients` (c₀ is then a constant)."""
    return first if tensor in across else first - c * x


def tensor_entries(t: sp.Expr, b: sp.Expr, c: sp.Expr) -> list[sp.Expr]:
    """Row-major entries of T = a I + b (p×) + c (p×)² (the form of eqs 14, 22, 26, 81, 83), written
    as T = t I + b (p×) + c p pᵀ with t = a − c |p|² (:func:`across_value`): T_ii = t + c p_i²,
    T_ij = c p_i p_j − b ε_ijk p_k.
    """
    entries = []
    for i in range(3):
        for j in range(3):
            if i == j:
                entries.append(t + c * P[i] ** 2)
            else:
                k = 3 - i - j
                sign = 1 if (i, j) in ((0, 1), (1, 2), (2, 0)) else -1
                entries.append(c * P[i] * P[j] - sign * b * P[k])
    return entries


def applied_entries(t: sp.Expr, b: sp.Expr, c: sp.Expr, v: tuple[sp.Symbol, sp.Symbol, sp.Symbol],
                    w: tuple[sp.Symbol, sp.Symbol, sp.Symbol], dot: sp.Symbol
                    ) -> tuple[list[sp.Expr], sp.Expr, list[sp.Expr]]:
    """T v for T = t I + b (p×) + c p pᵀ: (w = p × v, p·v, t v + b w + (c p·v) p). Across the axis
    only t and b act, so ω next to 2π, where c₀ ≈ c₂|p|², is not a difference of two large terms."""
    cross_pv = [P[1] * v[2] - P[2] * v[1], P[2] * v[0] - P[0] * v[2], P[0] * v[1] - P[1] * v[0]]
    p_dot_v = (P[0] * v[0] + P[1] * v[1]) + P[2] * v[2]
    return cross_pv, p_dot_v, [t * v[i] + b * w[i] + (c * dot) * P[i] for i in range(3)]


def vector_entries(a: sp.Expr, b: sp.Expr, c: sp.Expr, v: tuple[sp.Symbol, sp.Symbol, sp.Symbol],
                   w: tuple[sp.Symbol, sp.Symbol, sp.Symbol]) -> tuple[list[sp.Expr], list[sp.Expr]]:
    """T v for T = a I + b (p×) + c (p×)²: (w = p × v, then a v + b w + c p × w); the derivative
    functions' first term (:mod:`symrot.backends.c_derivatives`)."""
    cross_pv = [P[1] * v[2] - P[2] * v[1], P[2] * v[0] - P[0] * v[2], P[0] * v[1] - P[1] * v[0]]
    cross_pw = [P[1] * w[2] - P[2] * w[1], P[2] * w[0] - P[0] * w[2], P[0] * w[1] - P[1] * w[0]]
    return cross_pv, [a * v[i] + b * w[i] + c * cross_pw[i] for i in range(3)]


TENSOR_OF = {"rotation_matrix": "R", "tangent": "H", "tangent_inverse": "H_inverse", "root_matrix": "G",
             "root_tangent": "K", "pdot": "H_inverse", "omega": "H"}
OUTPUT_NAMES = {"rotation_matrix": "R", "tangent": "H", "tangent_inverse": "Hinv", "root_matrix": "G",
                "root_tangent": "K"}
VECTOR_NAMES = {"pdot": ("omega", "pdot"), "omega": ("pdot", "omega")}
