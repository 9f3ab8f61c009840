"""Symbolic core: everything the vectorial parameterization derives from a generating function.

Pure SymPy: no printing, no I/O. The tensors are *derived*, not copied from the paper:

* R from Euler's formula (1): R = I + sin φ U + (1 − cos φ) U², U = (u×).
* H from the angular velocity (10) with p = p(φ) u (eq 11): since φ̇ = μ u·ṗ (eq 21) and
  u̇ = −U² ṗ / p, ω = [μ I + ((1 − cos φ)/p) U + (μ − sin φ / p) U²] ṗ, which is eq (22).
* The m-th root G_(m) (76) and its tangent K_(m) (79, 80) the same way with φ/m in place of φ:
  K_(m) = (μ/m) I + ((1 − cos(φ/m))/p) U + (μ/m − sin(φ/m)/p) U²; H = K_(1), G = G_(2), K = K_(2).
* H⁻¹ by inversion in the axial-tensor algebra (:mod:`symrot.core.axial`), which gives eq (26).

The paper's printed forms (14), (22), (26), (81), (83) are then *checked* against these (tests,
audit). Scalars: p′, ν (15), ε (16), μ (21), det H (24) = μ ν².
"""

from __future__ import annotations

from dataclasses import dataclass, field
from functools import cached_property, lru_cache

import mpmath
import sympy as sp

from symrot.core.axial import AxialTensor
from symrot.core.budget import stage
from symrot.core.derivatives import (
    ROOT_DIFFERENTIATED,
    SLOPES,
    VALUES,
    slope_definitions,
    slope_name,
    slope_series,
)
from symrot.core.errors import InvalidGeneratingFunction
from symrot.core.parsing import PHI
from symrot.core.series import Series, coefficient_list, compose_even_in_x, revert, taylor_series
from symrot.core.simplify import simplest
from symrot.core.validation import ValidatedFunction, evaluate, validate

SCALAR_NAMES = ("p_prime", "nu", "epsilon", "mu", "det_H")
TENSOR_NAMES = ("R", "H", "H_inverse", "G", "K")
TENSOR_EQUATIONS = {"R": "14", "H": "22", "H_inverse": "26", "G": "81", "K": "83"}
CONSTANT_ORDER = 24
CONSTANT_CHECK_ANGLES = ("0.213", "0.577", "0.911", "1.307")
SCALAR_EQUATIONS = {"p_prime": "21", "nu": "15", "epsilon": "16", "mu": "21", "det_H": "24"}


def root_tensor(p: sp.Expr, m: int) -> AxialTensor:
    """G_(m), the m-th root of R (eq 76), in the u-basis."""
    angle = PHI / m
    return AxialTensor(sp.S.One, sp.sin(angle), 1 - sp.cos(angle))


def root_tangent(p: sp.Expr, m: int) -> AxialTensor:
    """K_(m) with γ_(m) = K_(m) ṗ (eqs 79-80), in the u-basis; H = K_(1) (eq 22)."""
    mu = 1 / sp.diff(p, PHI)
    angle = PHI / m
    return AxialTensor(mu / m, (1 - sp.cos(angle)) / p, mu / m - sp.sin(angle) / p)


@dataclass(frozen=True)
class Tensor:
    """A derived tensor: its u-basis form and its coefficients on I, (p×), (p×)²."""

    name: str
    u_basis: AxialTensor
    coefficients: tuple[sp.Expr, sp.Expr, sp.Expr]
    """Raw (unsimplified) coefficients on I, (p×), (p×)²."""

    @cached_property
    def simplified(self) -> tuple[sp.Expr, sp.Expr, sp.Expr]:
        """The coefficients simplified (:func:`symrot.core.simplify.simplest`), on first use: a figure
        needs only the scalars, a plan only these and the planar entry, a derivation sheet all."""
        with stage("derivation"):
            a, b, c = (simplest(c) for c in self.coefficients)
        return a, b, c

    @cached_property
    def canonical(self) -> sp.Matrix:
        """Simplified components in a canonical basis {u, v, w} (eqs 17, 23, 27), on first use."""
        real, imag = self.u_basis.planar
        with stage("derivation"):
            return sp.Matrix([[simplest(self.u_basis.a), 0, 0],
                              [0, simplest(real), -simplest(imag)],
                              [0, simplest(imag), simplest(real)]])

    def coefficient_names(self) -> tuple[str, str, str]:
        return (f"{self.name}_0", f"{self.name}_1", f"{self.name}_2")

    @property
    def across_name(self) -> str:
        """Name of c₀ − c₂|p|², the coefficient of I in T = (c₀ − c₂|p|²) I + c₁ (p×) + c₂ p pᵀ."""
        return f"{self.name}_across"

    @property
    def across(self) -> sp.Expr:
        """c₀ − c₂|p|² in φ (raw): the real part of T's eigenvalues across the axis, a − c in the
        u-basis (the planar entry of eqs 17, 23, 27). Planned as a coefficient of its own: next to
        2π, c₀ and c₂|p|² nearly cancel (ν → 0) and their difference is what ω across the axis is."""
        return self.u_basis.planar[0]

    @property
    def eigenvalues(self) -> tuple[sp.Expr, sp.Expr, sp.Expr]:
        axial = self.canonical[0, 0]
        real, imag = self.canonical[1, 1], self.canonical[2, 1]
        return axial, real + sp.I * imag, real - sp.I * imag


@dataclass
class Derivation:
    """All derived quantities of one generating function (Section 3.1, Appendix B)."""

    function: ValidatedFunction
    scalars_raw: dict[str, sp.Expr]
    scalars: dict[str, sp.Expr]
    tensors: dict[str, Tensor]
    slopes: dict[str, tuple[str, sp.Expr]] = field(default_factory=dict)
    """Slopes dc/dx of R, H, H⁻¹'s coefficients (:mod:`symrot.core.derivatives`): name → (parent, raw)."""
    root_slopes: dict[str, tuple[str, sp.Expr]] = field(default_factory=dict)
    """Slopes of G's and K's coefficients, the same way: derived (series, closed forms,
    :meth:`derivative_values`) but not among :meth:`planned_expressions`."""
    _series_cache: dict[tuple[str, int], list[sp.Expr]] = field(default_factory=dict, repr=False)
    _constants: dict[str, sp.Expr | None] = field(default_factory=dict, repr=False)
    _slopes_simplified: dict[str, sp.Expr] = field(default_factory=dict, repr=False)

    @property
    def p(self) -> sp.Expr:
        return self.function.expression

    @property
    def kappa(self) -> sp.Expr:
        return self.function.kappa

    def coefficient_expressions(self) -> dict[str, sp.Expr]:
        """Every scalar coefficient c(φ) the backends evaluate, raw, by stable name."""
        out = dict(self.scalars_raw)
        for tensor in self.tensors.values():
            out.update(zip(tensor.coefficient_names(), tensor.coefficients, strict=True))
        return out

    def simplified_coefficients(self) -> dict[str, sp.Expr]:
        out = dict(self.scalars)
        for tensor in self.tensors.values():
            out.update(zip(tensor.coefficient_names(), tensor.simplified, strict=True))
        return out

    def across_expressions(self) -> dict[str, sp.Expr]:
        """c₀ − c₂|p|² of every tensor (:attr:`Tensor.across`), raw, by name (``R_across`` …)."""
        return {tensor.across_name: tensor.across for tensor in self.tensors.values()}

    def planned_expressions(self) -> dict[str, sp.Expr]:
        """The coefficients, their across-axis combinations and the slopes of :mod:`symrot.core.derivatives`:
        everything a plan evaluates."""
        return {**self.coefficient_expressions(), **self.across_expressions(),
                **{n: raw for n, (_, raw) in self.slopes.items()}}

    def expression(self, name: str) -> sp.Expr:
        """The raw expression of a planned quantity or of a slope of G or K."""
        if name in self.root_slopes:
            return self.root_slopes[name][1]
        return self.planned_expressions()[name]

    def slope_parent(self, name: str) -> str | None:
        """The coefficient whose slope ``name`` is, None when it is not a slope."""
        found = self.slopes.get(name) or self.root_slopes.get(name)
        return None if found is None else found[0]

    def derivative_values(self, tensor: str) -> dict[sp.Symbol, sp.Expr]:
        """The scalars of :meth:`symrot.core.derivatives.TensorDerivative.matrix` for one of the five
        tensors (R, H, H⁻¹, G or K): its coefficients c_k and their slopes c_k′ = dc_k/dx as
        simplified closed forms in φ = φ(|p|); ``tensor_derivative().matrix(p, a,
        d.derivative_values("G"))`` is ∂(G a)/∂p (eqs 81, 83)."""
        values: dict[sp.Symbol, sp.Expr] = {}
        for k, name in enumerate(self.tensors[tensor].coefficient_names()):
            values[VALUES[k]] = self.simplified_form(name)
            values[SLOPES[k]] = self.simplified_form(slope_name(name))
        return values

    def simplified_form(self, name: str) -> sp.Expr:
        """The simplified form of one planned expression; a slope is the derivative of its parent's
        simplified form over dx/dφ = 2 p p′ with common factors pulled out (``factor_terms``): no
        time-bounded step, so that the printed form cannot depend on how loaded the machine is."""
        across = {t.across_name: t for t in self.tensors.values()}
        if name in across:
            return across[name].canonical[1, 1]
        parent_name = self.slope_parent(name)
        if parent_name is None:
            for tensor in self.tensors.values():  # simplify only the tensor that holds it
                if name in tensor.coefficient_names():
                    return tensor.simplified[tensor.coefficient_names().index(name)]
            return self.scalars[name]
        if name not in self._slopes_simplified:
            parent = self.simplified_coefficients()[parent_name]
            quotient = sp.diff(parent, PHI) / (2 * self.p * self.scalars["p_prime"])
            self._slopes_simplified[name] = sp.factor_terms(quotient)
        return self._slopes_simplified[name]

    # -- series -----------------------------------------------------------------------------
    def taylor_in_phi(self, name: str, order: int) -> list[sp.Expr]:
        """Exact Taylor coefficients of coefficient ``name`` in φ (index k ↔ φ^k)."""
        series: Series = taylor_series(self.expression(name), order)
        if not series.is_zero and series.shift < 0:
            raise InvalidGeneratingFunction(f"coefficient {name} has a pole at phi = 0")
        return coefficient_list(series, 0, order)

    def phi_of_p(self, order: int) -> list[sp.Expr]:
        """φ as a series in p (reversion of p(φ)), exact through p^(order-1)."""
        key = ("__phi_of_p__", order)
        if key not in self._series_cache:
            p_series = coefficient_list(taylor_series(self.p, order), 0, order)
            self._series_cache[key] = revert(p_series, order)
        return self._series_cache[key]

    def series_in_x(self, name: str, n_terms: int) -> list[sp.Expr]:
        """Exact Taylor coefficients d_j of coefficient ``name`` in x = |p|², j < n_terms."""
        key = (name, n_terms)
        if key not in self._series_cache:
            with stage("series expansion"):
                self._series_cache[key] = self._series_in_x(name, n_terms)
        return self._series_cache[key]

    def _series_in_x(self, name: str, n_terms: int) -> list[sp.Expr]:
        parent = self.slope_parent(name)
        if parent is not None:  # exact, term by term from the parent's series
            return slope_series(self.series_in_x(parent, n_terms + 1), n_terms)
        order = 2 * n_terms
        in_phi = self.taylor_in_phi(name, order)
        odd = [k for k in range(1, order, 2) if in_phi[k] != 0]
        if odd:
            raise InvalidGeneratingFunction(f"coefficient {name} is not even in phi")
        return compose_even_in_x(in_phi, self.phi_of_p(order), n_terms)

    def constant_value(self, name: str) -> sp.Expr | None:
        """The constant c if coefficient ``name`` is identically c, else None.

        Detected before any series/limit work (SymPy's ``series`` hangs on identically zero
        inputs such as (1/ε − 1/μ)/p² for 2 sin(φ/2)): either the bounded simplification already
        returned a number, or the exact Taylor series is constant through φ^(CONSTANT_ORDER−1)
        *and* the closed form equals that constant to 45 digits at four angles.
        """
        if name not in self._constants:
            self._constants[name] = self._find_constant(name)
        return self._constants[name]

    def _find_constant(self, name: str) -> sp.Expr | None:
        parent = self.slope_parent(name)
        if parent is not None and self.constant_value(parent) is not None:
            return sp.S.Zero
        simplified = self.simplified_form(name)
        if simplified.is_Number:
            return simplified
        in_phi = self.taylor_in_phi(name, CONSTANT_ORDER)
        if any(c != 0 for c in in_phi[1:]):
            return None
        constant = in_phi[0]
        tolerance = mpmath.mpf(10) ** -45
        for angle in CONSTANT_CHECK_ANGLES:
            value = self.evaluate(name, angle)
            if abs(value - mpmath.mpf(sp.N(constant, 60))) > tolerance * max(1, abs(value)):
                return None
        return constant

    # -- numeric evaluation -------------------------------------------------------------------
    def evaluate(self, name: str, angle: mpmath.mpf | str, digits: int = 50) -> mpmath.mpf:
        """Coefficient ``name`` at φ = angle to ``digits`` digits (raw closed form)."""
        return evaluate(self.expression(name), angle, digits)


def scalar_definitions(p: sp.Expr) -> dict[str, sp.Expr]:
    """p′, ν (15), ε (16), μ (21), det H = μ ν² (24) as raw expressions in φ."""
    p_prime = sp.diff(p, PHI)
    nu = 2 * sp.sin(PHI / 2) / p
    epsilon = 2 * sp.tan(PHI / 2) / p
    mu = 1 / p_prime
    return {"p_prime": p_prime, "nu": nu, "epsilon": epsilon, "mu": mu, "det_H": mu * nu**2}


def tensor_definitions(p: sp.Expr) -> dict[str, AxialTensor]:
    """R (1), H = K_(1) (10), H⁻¹, G = G_(2) (76), K = K_(2) (79) in the u-basis."""
    rotation = root_tensor(p, 1)
    tangent = root_tangent(p, 1)
    return {
        "R": rotation,
        "H": tangent,
        "H_inverse": tangent.inverse(),
        "G": root_tensor(p, 2),
        "K": root_tangent(p, 2),
    }


def _build_tensor(name: str, u_basis: AxialTensor, p: sp.Expr) -> Tensor:
    return Tensor(name, u_basis, u_basis.in_p_basis(p))


def derive_function(function: ValidatedFunction) -> Derivation:
    p = function.expression
    raw = scalar_definitions(p)
    scalars = {name: simplest(expr) for name, expr in raw.items()}
    tensors = {
        name: _build_tensor(name, u_basis, p) for name, u_basis in tensor_definitions(p).items()
    }
    coefficients = {n: c for t in tensors.values() for n, c in zip(t.coefficient_names(), t.coefficients,
                                                                  strict=True)}
    return Derivation(function, raw, scalars, tensors, slope_definitions(coefficients, p),
                      slope_definitions(coefficients, p, ROOT_DIFFERENTIATED))


def derive_expression(expr: sp.Expr, normalize: bool = False) -> Derivation:
    """Validate ``expr`` as p(φ) and derive everything; ``normalize`` divides p by κ.

    Cached: the API, the plan, the C and NumPy emitters and the figures derive the same p many
    times in one process (``make generate``); a Derivation is only ever extended by its own
    caches (series), never changed."""
    return _derive_cached(expr, normalize)


@lru_cache(maxsize=128)
def _derive_cached(expr: sp.Expr, normalize: bool) -> Derivation:
    with stage("validation"):
        function = validate(expr)
        if normalize and function.kappa != 1:
            function = validate(sp.expand(expr / function.kappa) if expr.is_Add else expr / function.kappa)
    with stage("derivation"):
        return derive_function(function)
