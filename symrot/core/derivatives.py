"""Derivatives of the tensors with respect to p, for implicit solvers (issue 19).

Pure SymPy, no printing. Every tensor of the parameterization is T(p) = c0 I + c1 P + c2 P² with
P = (p×) and scalar coefficients c_k(x) of x = |p|² (eqs 14, 22, 26). For a fixed vector a the
3×3 directional derivative ∂(T a)/∂p is *derived* here, not typed in:
:func:`tensor_derivative` differentiates c0(x) a + c1(x) p×a + c2(x) p×(p×a) with SymPy for
undefined functions c_k and free p, a, then finds the rational coefficients of each scalar
(c_k and c_k′ = dc_k/dx) on a basis of tensors built from p and a by exact linear algebra. The
result (checked against the Jacobian as a polynomial identity by :func:`check_tensor_derivative`) is

    ∂(T a)/∂p = 2 (c0′ a + c1′ p×a + c2′ p×(p×a)) ⊗ p − c1 (a×) − c2 [((p×a)×) + (p×)(a×)],

where u ⊗ p is the matrix u pᵀ (column j of the derivative is ∂(T a)/∂p_j).  Rᵀ and Hᵀ have the
coefficients (c0, −c1, c2), so their derivatives follow with c1, c1′ negated.

The new scalars are the slopes c_k′(x) = (dc_k/dφ) / (dx/dφ) = (dc_k/dφ) / (2 p p′) of R (eq 14),
H (eq 22) and H⁻¹ (eq 26): even analytic functions of φ when c_k is, so they are coefficients of x
like the others. Their exact series in x come from the parent's series in x (term by term:
Σ d_j x^j ↦ Σ (j + 1) d_(j+1) x^j), never from ``sympy.series``.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache
from typing import Any

import sympy as sp
from sympy.polys.domains import QQ
from sympy.polys.rings import PolyElement, PolyRing, ring

from symrot.core.parsing import PHI

DIFFERENTIATED = ("R", "H", "H_inverse")
"""Tensors whose coefficient slopes are derived and planned: the emitted derivative functions read
them (Rᵀ and Hᵀ share R's and H's)."""
ROOT_DIFFERENTIATED = ("G", "K")
"""Tensors of Appendix B whose slopes are derived too (∂(G a)/∂p, ∂(K a)/∂p by the same
:func:`tensor_derivative`, eqs 81, 83) but not planned: no emitted function reads them."""
SLOPE_SUFFIX = "_x"
Monomials = dict[tuple[int, ...], Any]
"""A polynomial in p and a as {exponents of p₁ p₂ p₃ a₁ a₂ a₃: rational coefficient}."""

_P = sp.Matrix(sp.symbols("p_1:4", real=True))
_A = sp.Matrix(sp.symbols("a_1:4", real=True))
VALUES = sp.symbols("c_0:3", real=True)
"""Symbols of the coefficients c0, c1, c2 in :class:`TensorDerivative`."""
SLOPES = sp.symbols("dc_0:3", real=True)
"""Symbols of their slopes c0′, c1′, c2′ = dc_k/dx."""


def slope_name(coefficient: str) -> str:
    """Name of dc/dx for the coefficient ``coefficient`` (e.g. ``H_1`` → ``H_1_x``)."""
    return coefficient + SLOPE_SUFFIX


def slope_definitions(coefficients: dict[str, sp.Expr], p: sp.Expr,
                      tensors: tuple[str, ...] = DIFFERENTIATED) -> dict[str, tuple[str, sp.Expr]]:
    """{slope name: (parent coefficient, dc/dx = (dc/dφ) / (2 p p′))} for the coefficients of
    ``tensors`` (R, H, H⁻¹ unless told)."""
    denominator = 2 * p * sp.diff(p, PHI)
    out = {}
    for tensor in tensors:
        for k in range(3):
            parent = f"{tensor}_{k}"
            out[slope_name(parent)] = (parent, sp.diff(coefficients[parent], PHI) / denominator)
    return out


def slope_series(parent_series: list[sp.Expr], n_terms: int) -> list[sp.Expr]:
    """Series of dc/dx in x from ``parent_series`` of c in x (needs n_terms + 1 parent terms)."""
    if len(parent_series) < n_terms + 1:
        raise ValueError("the slope needs one more term of its parent's series")
    return [(j + 1) * parent_series[j + 1] for j in range(n_terms)]


# -- the directional derivative as tensors --------------------------------------------------------
def skew(v: sp.Matrix) -> sp.Matrix:
    """(v×) as a 3×3 matrix."""
    return sp.Matrix([[0, -v[2], v[1]], [v[2], 0, -v[0]], [-v[1], v[0], 0]])


def basis(p: sp.Matrix, a: sp.Matrix) -> dict[str, sp.Matrix]:
    """The tensors the derivative is written on (u ⊗ p = u pᵀ); linearly independent for free p, a."""
    pa = p.cross(a)
    return {
        "a*p": a * p.T,
        "(p x a)*p": pa * p.T,
        "(p x (p x a))*p": p.cross(pa) * p.T,
        "[a x]": skew(a),
        "[(p x a) x]": skew(pa),
        "[p x][a x]": skew(p) * skew(a),
    }


@dataclass(frozen=True)
class TensorDerivative:
    """∂(T a)/∂p = Σ_s s Σ_b terms[s][b] · basis b, s in :data:`VALUES` + :data:`SLOPES`."""

    terms: dict[sp.Symbol, dict[str, sp.Rational]]

    def matrix(self, p: sp.Matrix, a: sp.Matrix, values: dict[sp.Symbol, sp.Expr]) -> sp.Matrix:
        """The derivative for explicit p, a and scalar values (c_k, c_k′)."""
        tensors = basis(p, a)
        out = sp.zeros(3, 3)
        for scalar, combination in self.terms.items():
            for name, factor in combination.items():
                out += values[scalar] * factor * tensors[name]
        return out


def _jacobian_in_scalars() -> sp.Matrix:
    """∂(T a)/∂p for undefined c_k(x), x = |p|², with c_k(x) → c_k and c_k′(x) → dc_k."""
    x = (_P.T * _P)[0, 0]
    functions = [sp.Function(f"c{k}") for k in range(3)]
    pa = _P.cross(_A)
    image = functions[0](x) * _A + functions[1](x) * pa + functions[2](x) * _P.cross(pa)
    jacobian = image.jacobian(_P)
    replacements: dict[sp.Expr, sp.Expr] = {}
    for atom in jacobian.atoms(sp.Subs, sp.Derivative):
        derivative = atom.expr if isinstance(atom, sp.Subs) else atom
        replacements[atom] = SLOPES[functions.index(derivative.expr.func)]
    jacobian = jacobian.xreplace(replacements)
    return jacobian.xreplace({f(x): VALUES[k] for k, f in enumerate(functions)})


_COMPONENTS = len(_P) + len(_A)
"""A monomial of :func:`_ring`'s first exponents count p and a; the scalars' follow."""


@lru_cache(maxsize=1)
def _ring() -> PolyRing:
    """The polynomial ring over QQ in p, a and the scalars (c_k′, c_k)."""
    return ring([*_P, *_A, *SLOPES, *VALUES], QQ)[0]


def _polynomials(matrix: sp.Matrix) -> list[PolyElement]:
    return [_ring()(entry) for entry in matrix]


def _coordinates(target: list[Monomials], basis: list[list[Monomials]]) -> list[sp.Rational]:
    """The unique rationals k_b with Σ_b k_b basis[b] = target entry by entry, as polynomials in
    p and a ({monomial: coefficient} per entry): exact Gauss–Jordan elimination on the equations
    of every monomial, which raises when they have no solution."""
    rows, right = [], []
    for index, wanted in enumerate(target):
        monomials = set(wanted).union(*(element[index] for element in basis))
        for monomial in sorted(monomials):
            rows.append([element[index].get(monomial, 0) for element in basis])
            right.append(wanted.get(monomial, 0))
    solution, free = sp.Matrix(rows).gauss_jordan_solve(sp.Matrix(right))
    if free.shape[0]:
        raise ArithmeticError("the derivative is not on the basis uniquely")
    return [sp.Rational(value) for value in solution]


def _in_vectors(matrix: sp.Matrix) -> list[Monomials]:
    """The entries of a matrix polynomial in p and a, as {monomial in p, a: coefficient}."""
    return [_part_in(entry, None) for entry in _polynomials(matrix)]


def _part_in(element: PolyElement, scalar: int | None) -> Monomials:
    """{monomial in p, a: coefficient} of the terms of ``element`` with the scalar of that index
    among the ring's generators (linear in the scalars), or of all its terms (``None``)."""
    return {m[:_COMPONENTS]: c for m, c in element.terms() if scalar is None or m[scalar] == 1}


@lru_cache(maxsize=1)
def tensor_derivative() -> TensorDerivative:
    """∂(T a)/∂p on :func:`basis`, found by solving for rational coefficients (see module doc):
    the Jacobian's entries as polynomials over QQ, one exact linear system per scalar. Through
    ``sp.expand``, ``sp.Poly`` and ``sp.solve``, this and :func:`rate_vector` took 1.2 s of every
    emit; on the ring, 0.18 s."""
    jacobian = _polynomials(_jacobian_in_scalars())
    tensors = basis(_P, _A)
    spanning = [_in_vectors(tensor) for tensor in tensors.values()]
    terms: dict[sp.Symbol, dict[str, sp.Rational]] = {}
    for offset, scalar in enumerate((*SLOPES, *VALUES)):
        part = [_part_in(entry, _COMPONENTS + offset) for entry in jacobian]
        if not any(part):
            continue
        coordinates = _coordinates(part, spanning)
        terms[scalar] = {name: k for name, k in zip(tensors, coordinates, strict=True) if k != 0}
    return TensorDerivative(terms)


def check_tensor_derivative() -> bool:
    """The derived form equals SymPy's Jacobian as a polynomial identity in p, a, c_k, c_k′."""
    derived = tensor_derivative().matrix(_P, _A, {s: s for s in (*VALUES, *SLOPES)})
    return sp.expand(derived - _jacobian_in_scalars()) == sp.zeros(3, 3)


def rate_basis(p: sp.Matrix, a: sp.Matrix) -> dict[str, sp.Matrix]:
    """The vectors Ṫ ṗ is written on, for a = ṗ: the basis tensors of :func:`basis` applied to a
    itself, without the ones that vanish ((a×) a = 0, (p×)(a×) a = 0)."""
    dot = (p.T * a)[0, 0]
    pa = p.cross(a)
    return {"a (p.a)": a * dot, "(p x a) (p.a)": pa * dot, "(p x (p x a)) (p.a)": p.cross(pa) * dot,
            "(p x a) x a": pa.cross(a)}


@lru_cache(maxsize=1)
def rate_vector() -> dict[sp.Symbol, dict[str, sp.Rational]]:
    """Ṫ ṗ = [∂(T a)/∂p]_(a = ṗ) ṗ on :func:`rate_basis`, from :func:`tensor_derivative` applied to
    a = ṗ and solved for rational coefficients like it."""
    vectors = rate_basis(_P, _A)
    spanning = [_in_vectors(vector) for vector in vectors.values()]
    tensors = basis(_P, _A)
    out: dict[sp.Symbol, dict[str, sp.Rational]] = {}
    for scalar, combination in tensor_derivative().terms.items():
        applied = _in_vectors(sum((f * tensors[n] * _A for n, f in combination.items()), sp.zeros(3, 1)))
        if not any(applied):
            continue
        coordinates = _coordinates(applied, spanning)
        out[scalar] = {name: k for name, k in zip(vectors, coordinates, strict=True) if k != 0}
    return out


def rate_value(p: sp.Matrix, a: sp.Matrix, values: dict[sp.Symbol, sp.Expr]) -> sp.Matrix:
    """Ṫ ṗ for explicit p, ṗ = a and scalar values (c_k, c_k′), from :func:`rate_vector`."""
    vectors = rate_basis(p, a)
    out = sp.zeros(3, 1)
    for scalar, combination in rate_vector().items():
        for name, factor in combination.items():
            out += values[scalar] * factor * vectors[name]
    return out
