"""Bounded symbolic proofs for the audit.

*Generic generating function.* Identities claimed "for any p" are proved once for all p: p and
p′ become free symbols ``p``, ``dp`` (ν = 2 sin(φ/2)/p (15), ε = 2 tan(φ/2)/p (16), μ = 1/p′
(21)), and the truth is the symbolic core (:func:`symrot.core.derivation.tensor_definitions` applied to an
undefined function p(φ)).

*One axis suffices.* Every tensor built from I and (u×) by sums, products, inverses and
transposes satisfies F A(u) Fᵀ = A(Fu) for rotations F. An identity between such tensors
therefore holds for every unit u iff it holds for u = e₁, where (u×) is
``U_CANONICAL`` — which is also its component matrix in any canonical basis {u, v, w} (17).

:func:`is_zero` settles a scalar identity by base-angle reduction modulo sin² + cos² = 1 (a
decision procedure for rational functions of sin, cos, tan of rational multiples of φ and free
symbols) under a time limit, then a bounded ``simplify``.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cache

import sympy as sp

from symrot.core.derivation import tensor_definitions
from symrot.core.parsing import PHI
from symrot.core.simplify import base_angle_reduction
from symrot.core.timeouts import bounded

P, DP = sp.symbols("p dp")
"""Generic p(φ) and p′(φ) as free symbols."""
NU = 2 * sp.sin(PHI / 2) / P
EPS = 2 * sp.tan(PHI / 2) / P
MU = 1 / DP
GENERIC_P = sp.Function("p")(PHI)
U1, U2, U3 = sp.symbols("u1 u2 u3")
U_VECTOR = sp.Matrix([U1, U2, U3])
"""A unit axis u as symbols: printed formulas are transcribed with it; proofs set u = e₁."""
U_CANONICAL = sp.Matrix([[0, 0, 0], [0, 0, -1], [0, 1, 0]])
"""(u×) for u = e₁ = its components in a canonical basis {u, v, w = u × v}."""
EYE = sp.eye(3)
SECONDS = 10.0


def skew(v: sp.Matrix) -> sp.Matrix:
    """(v×) as a 3×3 matrix."""
    return sp.Matrix([[0, -v[2], v[1]], [v[2], 0, -v[0]], [-v[1], v[0], 0]])


U_CROSS = skew(U_VECTOR)
"""(u×) with symbolic u; at u = e₁ it is ``U_CANONICAL``."""


def at_e1(expr: sp.Expr | sp.Matrix) -> sp.Expr | sp.Matrix:
    """Set u = e₁ (legitimate for single-axis identities, see the module docstring)."""
    return expr.subs({U1: 1, U2: 0, U3: 0})


def generic(expr: sp.Expr) -> sp.Expr:
    """Replace p(φ) and p′(φ) by the free symbols ``p``, ``dp``."""
    return expr.subs(sp.Derivative(GENERIC_P, PHI), DP).subs(GENERIC_P, P)


@cache
def core_tensor(name: str) -> sp.Matrix:
    """R, H, H_inverse, G or K of the core for a generic p (symbolic axis u; :func:`at_e1`
    gives its components in a canonical basis)."""
    t = tensor_definitions(GENERIC_P)[name]
    return generic(t.a) * EYE + generic(t.b) * U_CROSS + generic(t.c) * U_CROSS**2


def p_cross(magnitude: sp.Expr = P) -> sp.Matrix:
    """(p×) = p (u×) at u = e₁."""
    return magnitude * U_CANONICAL


def is_zero(expr: sp.Expr, seconds: float = SECONDS) -> bool | None:
    """True if ``expr`` ≡ 0 is proved, False if its reduced form is a non-zero expression
    (not an identity), None if no bounded method decides."""
    expr = _sin_cos_tan(sp.sympify(expr))
    if expr == 0:
        return True
    reduced = bounded(seconds, None, base_angle_reduction, expr)
    if reduced is not None and (reduced == 0 or _decided(reduced)):
        return bool(reduced == 0)
    simplified = bounded(seconds, None, sp.simplify, expr)
    if simplified is not None and simplified == 0:
        return True
    return None


def _sin_cos_tan(expr: sp.Expr) -> sp.Expr:
    """cot, sec, csc → 1/tan, 1/cos, 1/sin (SymPy writes tan(x + π/2) as −cot(x))."""
    inverse = {sp.cot: sp.tan, sp.sec: sp.cos, sp.csc: sp.sin}
    return expr.xreplace({f: 1 / inverse[type(f)](*f.args) for f in expr.atoms(sp.cot, sp.sec, sp.csc)})


def _decided(reduced: sp.Expr) -> bool:
    """A non-zero reduced form refutes the identity only if the reduction was complete: a rational
    function of trigonometric functions of φ and free symbols (no roots or other functions,
    which the reduction treats as opaque)."""
    if any(not isinstance(f, (sp.sin, sp.cos, sp.tan)) for f in reduced.atoms(sp.Function)):
        return False
    return all(power.exp.is_Integer for power in reduced.atoms(sp.Pow))


def matrix_is_zero(m: sp.Matrix, seconds: float = SECONDS) -> bool | None:
    verdicts = [is_zero(entry, seconds) for entry in m]
    if all(v is True for v in verdicts):
        return True
    if any(v is False for v in verdicts):
        return False
    return None


def reduced(expr: sp.Expr, seconds: float = SECONDS) -> sp.Expr:
    """A short equivalent form of ``expr`` for evidence text (falls back to ``expr``)."""
    result = bounded(seconds, None, base_angle_reduction, sp.sympify(expr))
    if result is None:
        return sp.sympify(expr)
    return bounded(seconds, result, sp.factor, result)


@dataclass(frozen=True)
class Verdict:
    """A symbolic identity check: ``holds`` is None when undecided."""

    holds: bool | None
    residual: sp.Expr | sp.Matrix

    def describe(self) -> str:
        if self.holds:
            return "residual = 0 (symbolic)"
        if self.holds is None:
            return "not decided within the time limit"
        return f"residual = {self.residual}"


def identity(lhs: sp.Expr | sp.Matrix, rhs: sp.Expr | sp.Matrix, seconds: float = SECONDS) -> Verdict:
    """Decide lhs = rhs symbolically (scalars or matrices)."""
    residual = lhs - rhs
    if isinstance(residual, sp.MatrixBase):
        holds = matrix_is_zero(residual, seconds)
        shown = residual.applyfunc(lambda e: reduced(e, seconds)) if holds is False else residual
        return Verdict(holds, shown)
    holds = is_zero(residual, seconds)
    return Verdict(holds, reduced(residual, seconds) if holds is False else residual)
