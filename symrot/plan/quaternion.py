"""Evaluation plans of the quaternion operations (eqs 74–75, 18–19, 40–47): issue 6.

Every operation on rotations of any size goes through Euler–Rodrigues parameters (a unit
quaternion e = (e₀, **e**), scalar first):

* ``to_quaternion``: e₀ = ν/ε = cos(φ/2) (eq 74) and **e** = (ν/2) **p** (eq 75). ν is already a
  coefficient of the plan; e₀ is planned here as the coefficient ``e_0`` of x = |p|².
* ``from_quaternion``: on the hemisphere e₀ ≥ 0 (|φ| ≤ π, which *is* rescaling, eqs 40–47),
  **p** = σ **e** with σ = p(φ)/sin(φ/2) (the inverse of eq 75). σ is planned as
  :class:`~symrot.plan.ir.QuaternionScale`: trig-free in e₀ when substituting φ = 2 acos e₀
  leaves an algebraic function (e.g. 4/(1 + e₀) for 4 tan(φ/4), 2/e₀ for 2 tan(φ/2)), otherwise
  a :class:`~symrot.plan.ir.Branch` in t = φ² with φ = 2 atan2(|**e**|, e₀) (never acos).
* validity of the result: with e₀ ≥ 0 the angle is at most π, so every parameterization whose
  range exceeds π represents every rotation; a range φ_max ≤ π needs e₀ > cos(φ_max/2)
  (``e0_min``), otherwise the result is the documented out-of-range value.

Pure planning (SymPy + the plan's error model); backends print it.
"""

from __future__ import annotations

import sympy as sp
from sympy.functions.elementary.trigonometric import TrigonometricFunction

from symrot.core.derivation import Derivation
from symrot.core.parsing import PHI
from symrot.core.series import coefficient_list, compose_even_in_x, taylor_series
from symrot.core.timeouts import bounded
from symrot.plan.ir import QuaternionScale as QuaternionScale  # re-exported: defined with the plan's IR

E0 = sp.Symbol("e0", positive=True)
"""The scalar part e₀ of the unit quaternion on the hemisphere e₀ ≥ 0."""
QUATERNION_SCALAR = "e_0"
"""Name of the plan coefficient e₀ = cos(φ/2) (eq 74) among the coefficients of x."""
ROTATION_TOLERANCE_POWER = {"float64": -26, "float32": -11}
"""``from_rotation_matrix`` accepts R only when max |RᵀR − I| ≤ 2^power and det R > 0 (eqs 61–65
hold for rotations only; anything else, e.g. 0, −I, 2 Rz, a rank-1 matrix or a reflection, would be
mapped to some rotation): 2⁻²⁶ ≈ 1.5e-8 in float64, 2⁻¹¹ ≈ 4.9e-4 in float32, about √ε, so that
a rotation rounded to the format, or computed by a few products of rotations, is accepted."""


def quaternion_scalar() -> sp.Expr:
    """e₀ = cos(φ/2) (eq 74, ν/ε simplified)."""
    return sp.cos(PHI / 2)


def quaternion_scalar_series(derivation: Derivation, n_terms: int) -> list[sp.Expr]:
    """Exact coefficients of e₀ = cos(φ(p)/2) in x = |p|², j < n_terms."""
    order = 2 * n_terms
    in_phi = coefficient_list(taylor_series(quaternion_scalar(), order), 0, order)
    return compose_even_in_x(in_phi, derivation.phi_of_p(order), n_terms)


def scale_expression(p: sp.Expr) -> sp.Expr:
    """σ(φ) = p(φ)/sin(φ/2) = 2/ν."""
    return p / sp.sin(PHI / 2)


def scale_series(p: sp.Expr, n_terms: int) -> list[sp.Expr]:
    """Exact Taylor coefficients of σ in t = φ² (σ is even in φ), j < n_terms."""
    order = 2 * n_terms
    return coefficient_list(taylor_series(scale_expression(p), order), 0, order)[0::2]


def scale_in_e0(p: sp.Expr) -> sp.Expr | None:
    """σ as an algebraic function of e₀ = cos(φ/2) ∈ (0, 1], or None.

    With φ = 2θ, θ = acos e₀ ∈ [0, π/2]: expand multiple angles, replace the half angles of θ
    by their (positive) radicals, substitute θ = acos e₀ and simplify (time-bounded).

    Only for p whose calls of φ are all trigonometric: any other call (a hyperbolic, inverse or
    exponential function of φ, the real cube root of eq 35) leaves a transcendental function of
    acos e₀ in σ. The reduction found no algebraic σ for any of the 210 such p among the corpus, the
    default hypothesis sample, the seed-2028 held-out sample and the named parameterizations (284
    functions; up to 3.2 s each, 54 s in all, measured one at a time), so it is not attempted.
    """
    if any(not isinstance(call, TrigonometricFunction) for call in p.atoms(sp.Function)):
        return None
    theta = sp.Symbol("theta", positive=True)
    half = theta / 2
    rules = {sp.sin: sp.sqrt((1 - sp.cos(theta)) / 2), sp.cos: sp.sqrt((1 + sp.cos(theta)) / 2),
             sp.tan: sp.sin(theta) / (1 + sp.cos(theta))}

    def reduce() -> sp.Expr:
        e = sp.expand_trig(scale_expression(p).subs(PHI, 2 * theta))
        e = e.replace(lambda z: type(z) in rules and z.args[0] == half, lambda z: rules[type(z)])
        return sp.factor(sp.simplify(e.subs(theta, sp.acos(E0))))

    reduced: sp.Expr | None = bounded(4, None, reduce)
    if reduced is None or reduced.free_symbols - {E0}:
        return None
    if any(isinstance(a, sp.Function) for a in sp.preorder_traversal(reduced)):
        return None
    at_identity = reduced.subs(E0, 1)
    if not (at_identity.is_finite and at_identity.is_positive):
        return None
    return reduced


def e0_min(phi_max: sp.Expr) -> float | None:
    """from_quaternion is valid iff e₀ > e0_min; None when every rotation is representable."""
    if bool(phi_max > sp.pi):
        return None
    return float(sp.cos(phi_max / 2))
