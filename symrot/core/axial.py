"""The algebra of axial tensors: A = a I + b (u×) + c (u×)², a, b, c scalar functions of φ.

Every tensor of the vectorial parameterization (R, H, H⁻¹, G, K) has this form. With U = (u×),
U³ = −U, so these tensors form a commutative algebra. In a canonical basis {u, v, w} (eq 17)
    [A]_B = [[a, 0, 0], [0, a − c, −b], [0, b, a − c]],
i.e. A is the pair (a, z) with z = (a − c) + i b: products multiply the pairs, the transpose
conjugates z, and the eigenvalues are a and (a − c) ± i b (eqs 17, 23, 27).

Coefficients on (p×)^k follow from p = p(φ) u: (p×)^k = p^k U^k, so the coefficient of (p×) is
b/p and that of (p×)² is c/p² (the form printed in eqs 14, 22, 26, 81, 83).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import sympy as sp


@dataclass(frozen=True)
class AxialTensor:
    """a I + b (u×) + c (u×)², with a, b, c SymPy expressions in φ."""

    a: sp.Expr
    b: sp.Expr
    c: sp.Expr

    @staticmethod
    def from_canonical(axial: sp.Expr, real: sp.Expr, imag: sp.Expr) -> AxialTensor:
        """The tensor with eigenvalue ``axial`` on u and (real ± i imag) in the normal plane."""
        return AxialTensor(axial, imag, axial - real)

    @property
    def axial_eigenvalue(self) -> sp.Expr:
        return self.a

    @property
    def planar(self) -> tuple[sp.Expr, sp.Expr]:
        """(Re z, Im z) with z = (a − c) + i b."""
        return self.a - self.c, self.b

    def __matmul__(self, other: AxialTensor) -> AxialTensor:
        re1, im1 = self.planar
        re2, im2 = other.planar
        return AxialTensor.from_canonical(
            self.a * other.a, re1 * re2 - im1 * im2, re1 * im2 + im1 * re2
        )

    def __sub__(self, other: AxialTensor) -> AxialTensor:
        return AxialTensor(self.a - other.a, self.b - other.b, self.c - other.c)

    def transpose(self) -> AxialTensor:
        return AxialTensor(self.a, -self.b, self.c)

    def inverse(self) -> AxialTensor:
        re, im = self.planar
        modulus = re**2 + im**2
        return AxialTensor.from_canonical(1 / self.a, re / modulus, -im / modulus)

    def determinant(self) -> sp.Expr:
        re, im = self.planar
        return self.a * (re**2 + im**2)

    def canonical_matrix(self) -> sp.Matrix:
        """Components in a canonical basis {u, v, w} (eqs 17, 23, 27)."""
        re, im = self.planar
        return sp.Matrix([[self.a, 0, 0], [0, re, -im], [0, im, re]])

    def in_p_basis(self, p: sp.Expr) -> tuple[sp.Expr, sp.Expr, sp.Expr]:
        """Coefficients on I, (p×), (p×)² for p = p(φ) u."""
        return self.a, self.b / p, self.c / p**2

    def map(self, func: Callable[[sp.Expr], sp.Expr]) -> AxialTensor:
        return AxialTensor(func(self.a), func(self.b), func(self.c))


def identity() -> AxialTensor:
    return AxialTensor(sp.S.One, sp.S.Zero, sp.S.Zero)


def skew(vector: sp.Matrix) -> sp.Matrix:
    """(v×) as a 3×3 matrix."""
    x, y, z = vector
    return sp.Matrix([[0, -z, y], [z, 0, -x], [-y, x, 0]])
