"""The symbolic core of issue 19 (symrot/core/derivatives.py): ∂(T a)/∂p derived, and the slopes dc/dx.

* the core's form of ∂(T a)/∂p is SymPy's Jacobian (a polynomial identity in p, a, c_k, c_k′) and its
  basis is independent, so the form is determined;
* the slopes c_k′ = dc_k/dx have the exact series of the parents' (term by term), checked against
  the closed form dc/dφ / (2 p p′) at 60 digits;
* with the core's coefficients and slopes, ∂(T a)/∂p δp is d/dt T(p + t δp) a at t = 0 (60 digits,
  mpmath.diff of the core's closed forms at φ = p⁻¹(|p|) from the independent reference's inverse).
"""

from __future__ import annotations

import random
from typing import Any

import mpmath
import pytest
import sympy as sp

from symrot.api import derive
from symrot.core.derivatives import (
    SLOPES,
    VALUES,
    basis,
    check_tensor_derivative,
    rate_vector,
    slope_name,
    tensor_derivative,
)
from symrot.core.functions import mpmath_namespace
from symrot.core.parsing import PHI

from .reference import GeneratingFunction, skew


def test_derived_form_is_the_jacobian() -> None:
    """The structure found by linear algebra is exactly SymPy's Jacobian, and reads as documented."""
    assert check_tensor_derivative()
    c0, c1, c2 = VALUES
    d0, d1, d2 = SLOPES
    assert tensor_derivative().terms == {
        d0: {"a*p": 2}, d1: {"(p x a)*p": 2}, d2: {"(p x (p x a))*p": 2},
        c1: {"[a x]": -1}, c2: {"[(p x a) x]": -1, "[p x][a x]": -1}}
    assert c0 not in tensor_derivative().terms  # a constant c0 I contributes nothing


def test_basis_is_independent() -> None:
    """The coefficients on the basis are unique (else the derived form would not be determined)."""
    p = sp.Matrix([sp.Rational(3, 7), -2, sp.Rational(5, 3)])
    a = sp.Matrix([1, sp.Rational(-4, 5), 2])
    stacked = sp.Matrix([[*m] for m in basis(p, a).values()])
    assert stacked.rank() == len(basis(p, a))


@pytest.mark.parametrize("expression", ["phi", "sinh(phi)"])
def test_slope_series_is_the_derivative_of_the_closed_form(expression: str) -> None:
    """The series of H_2′ (from the parent's series) against the 50-digit closed form dc/dφ / (2 p p′)."""
    derivation = derive(expression).derivation
    for name in ("H_2", "R_1", "H_inverse_2", "G_1", "K_2"):
        series = derivation.series_in_x(slope_name(name), 12)
        with mpmath.workdps(60):
            phi = mpmath.mpf("0.05")
            x = _mp(derivation.p, phi) ** 2
            value = mpmath.polyval([mpmath.mpf(sp.N(c, 70)) for c in reversed(series)], x)
            closed = derivation.evaluate(slope_name(name), phi, digits=60)
            assert abs(value - closed) <= mpmath.mpf(10) ** -25 * max(1, abs(closed)), (name, value, closed)


def _mp(expr: sp.Expr, phi: mpmath.mpf) -> mpmath.mpf:
    return sp.lambdify(PHI, expr, modules=[mpmath_namespace(), "mpmath"])(phi)


@pytest.mark.parametrize("expression", ["2*sin(phi/2)", "sinh(phi)"])
def test_core_derivative_is_the_directional_derivative(expression: str) -> None:
    """∂(T a)/∂p δp from the core's coefficients and slopes equals d/dt T(p + t δp) a at t = 0 (60
    digits, mpmath.diff), T in R, H, H⁻¹ (planned) and G, K (derived only) with the core's closed
    forms at φ = p⁻¹(|p|)."""
    derivation = derive(expression).derivation
    function = GeneratingFunction(expression)
    rng = random.Random(19)
    expressions = {**derivation.planned_expressions(),
                   **{name: raw for name, (_, raw) in derivation.root_slopes.items()}}
    closed = {n: sp.lambdify(PHI, e, modules=[mpmath_namespace(), "mpmath"]) for n, e in expressions.items()}
    with mpmath.workdps(60):
        def tensor(q: list[Any], name: str, slopes: bool = False) -> Any:
            s = mpmath.sqrt(sum(v * v for v in q))
            phi = function.inverse(s)
            suffix = "_x" if slopes else ""
            return [closed[f"{name}_{k}{suffix}"](phi) for k in range(3)]

        p = [mpmath.mpf(rng.uniform(-0.6, 0.6)) for _ in range(3)]
        a = [mpmath.mpf(rng.uniform(-1, 1)) for _ in range(3)]
        direction = [mpmath.mpf(rng.uniform(-1, 1)) for _ in range(3)]
        for name in ("R", "H", "H_inverse", "G", "K"):
            def image(t: Any, name: str = name) -> Any:
                q = [p[i] + t * direction[i] for i in range(3)]
                c = tensor(q, name)
                m = c[0] * mpmath.eye(3) + c[1] * skew(q) + c[2] * skew(q) * skew(q)
                return m * mpmath.matrix(a)

            expected = mpmath.matrix([mpmath.diff(lambda t, i=i: image(t)[i], 0) for i in range(3)])
            values = dict(zip(VALUES, tensor(p, name), strict=True))
            values.update(zip(SLOPES, tensor(p, name, slopes=True), strict=True))
            derived = tensor_derivative().matrix(sp.Matrix(p), sp.Matrix(a), values)
            got = derived * sp.Matrix(direction)
            error = max(abs(mpmath.mpf(sp.N(got[i], 60)) - expected[i]) for i in range(3))
            assert error < mpmath.mpf(10) ** -40, (name, error)


def test_rate_vector_is_the_derivative_applied_to_pdot() -> None:
    """Ḣ ṗ = [∂(T a)/∂p]_(a = ṗ) ṗ reads 2 (p·ṗ)(c0′ ṗ + c1′ p×ṗ + c2′ p×(p×ṗ)) − c2 (p×ṗ)×ṗ."""
    c2 = VALUES[2]
    d0, d1, d2 = SLOPES
    assert rate_vector() == {d0: {"a (p.a)": 2}, d1: {"(p x a) (p.a)": 2}, d2: {"(p x (p x a)) (p.a)": 2},
                             c2: {"(p x a) x a": -1}}


def test_slopes_of_g_and_k_are_derived_but_not_planned() -> None:
    """G's and K's slopes (Appendix B) exist with their parents and exact series, are not among the
    planned expressions (no emitted function reads them), and Derivation.derivative_values gives ∂(G a)/∂p:
    for the rotation vector, G = R(p/2) (eq 76), so ∂(G a)/∂p = ½ ∂(R a)/∂p at p/2, checked at a
    rational point at 40 digits."""
    derivation = derive("rotation_vector").derivation
    assert set(derivation.root_slopes) == {slope_name(f"{t}_{k}") for t in ("G", "K") for k in range(3)}
    assert not set(derivation.root_slopes) & set(derivation.planned_expressions())
    assert derivation.slope_parent("K_2_x") == "K_2" and derivation.slope_parent("K_2") is None
    assert derivation.series_in_x("G_1_x", 2) == [sp.Rational(-1, 48), sp.Rational(1, 1920)]
    p = sp.Matrix([sp.Rational(3, 10), sp.Rational(-1, 5), sp.Rational(2, 5)])
    a = sp.Matrix([1, sp.Rational(1, 3), -2])
    angle = sp.sqrt((p.T * p)[0, 0])

    def at(values: dict[sp.Symbol, sp.Expr], phi: sp.Expr) -> dict[sp.Symbol, sp.Expr]:
        return {symbol: value.subs(PHI, phi) for symbol, value in values.items()}

    root = tensor_derivative().matrix(p, a, at(derivation.derivative_values("G"), angle))
    half = tensor_derivative().matrix(p / 2, a, at(derivation.derivative_values("R"), angle / 2)) / 2
    assert max(abs(sp.N(v, 40)) for v in root - half) < 1e-35
