"""Rotations of any size, symbolically: Euler–Rodrigues conversion, rescaling and composition.

Pure SymPy (symbolic core layer). For any generating function p(φ):

* to_quaternion (eqs 74-75): e₀ = ν/ε = cos(φ/2), **e** = (ν/2) **p**. The coefficient ν/2 is an
  even function of φ, hence of x = |p|².
* from_quaternion: φ = 2 atan2(|e|, e₀) and **p** = σ(φ) **e** with σ = p(φ)/sin(φ/2) = 2/ν, even
  in φ. With q = 2|e| = 2 sin(φ/2) (the reduced Euler–Rodrigues generating function, eq 32),
  σ is an analytic function of q² = 4|e|² on the hemisphere e₀ ≥ 0, which gives its exact series.
* rescale: rotations by φ and φ − 2π sign φ are the same; in quaternion terms rescaling is the
  choice of the hemisphere e₀ ≥ 0 (|φ| ≤ π). The equivalent vector is
  **p̂** = (p(φ − 2π)/p(φ)) **p** for π < φ < 2π, for *every* parameterization whose validity
  range exceeds π. :func:`rescale_factor` gives that ratio; eqs (41) and (45) are its instances
  for 4 tan(φ/4) and 4 sin(φ/4) (see :func:`paper_rescaling_claims`).
* compose (eqs 18-19, 53): **e**₃ = **e**₂ ∘ **e**₁ for R₃ = R₂ R₁ (**p**₁ applied first).
"""

from __future__ import annotations

from dataclasses import dataclass

import sympy as sp

from symrot.core.derivation import scalar_definitions
from symrot.core.parsing import PHI
from symrot.core.series import coefficient_list, compose_even_in_x, revert, taylor_series

TWO_PI = 2 * sp.pi


def quaternion_coefficients(p: sp.Expr) -> tuple[sp.Expr, sp.Expr]:
    """(e₀(φ), c(φ)) with e₀ = ν/ε (eq 74) and **e** = c **p**, c = ν/2 (eq 75)."""
    scalars = scalar_definitions(p)
    return scalars["nu"] / scalars["epsilon"], scalars["nu"] / 2


def from_quaternion_scale(p: sp.Expr) -> sp.Expr:
    """σ(φ) = p(φ)/sin(φ/2) = 2/ν, with **p** = σ **e** (inverse of eq 75)."""
    return p / sp.sin(PHI / 2)


def from_quaternion_series(p: sp.Expr, n_terms: int) -> list[sp.Expr]:
    """Exact coefficients d_j of σ = Σ d_j y^j with y = 4|e|² = (2 sin(φ/2))², for e₀ ≥ 0."""
    order = 2 * n_terms
    sigma = coefficient_list(taylor_series(from_quaternion_scale(p), order), 0, order)
    q_series = coefficient_list(taylor_series(2 * sp.sin(PHI / 2), order), 0, order)
    return compose_even_in_x(sigma, revert(q_series, order), n_terms)


def rescale_factor(p: sp.Expr) -> sp.Expr:
    """p(φ − 2π)/p(φ): **p̂** = factor · **p** represents the same rotation (π < φ < 2π)."""
    return sp.simplify(p.subs(PHI, PHI - TWO_PI) / p)


@dataclass(frozen=True)
class RescalingClaim:
    """A rescaling formula of Section 3.4 as printed, and what the mechanism gives."""

    equation: str
    parameterization: sp.Expr
    printed_factor: sp.Expr
    """p̂ = printed_factor · p, as printed (in terms of ν)."""
    mechanism_factor: sp.Expr
    """p(φ − 2π)/p(φ), the factor that maps p to the same rotation with |φ̂| < π."""


def paper_rescaling_claims() -> list[RescalingClaim]:
    """Eqs (41) and (45) as printed, beside the hemisphere mechanism."""
    claims = []
    for equation, p, printed in (
        ("41", 4 * sp.tan(PHI / 4), lambda nu: -nu / (1 - nu)),
        ("45", 4 * sp.sin(PHI / 4), lambda nu: nu / sp.sqrt(1 - nu**2)),
    ):
        nu = scalar_definitions(p)["nu"]
        claims.append(RescalingClaim(equation, p, printed(nu), rescale_factor(p)))
    return claims
