"""Where and against what the plan measures candidate forms (:mod:`symrot.plan.builder`).

The grid of angles (log-spaced towards 0, plus points approaching φ_max), the inputs the backends
have there (x = |p|² rounded, s = √x, the angle φ̂ they compute from s, the fold complement d),
the exact angle θ of each rounded input, and the 60-digit reference values of a coefficient at
those angles. Forms are evaluated on these inputs by :mod:`symrot.plan.evaluation`; the error model
that turns the errors into switches and degrees is :func:`symrot.plan.branches.plan_branch`.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from functools import lru_cache
from typing import Any, NamedTuple

import mpmath
import numpy as np
import sympy as sp

from symrot.core.functions import mpmath_namespace
from symrot.core.parsing import PHI
from symrot.plan.algebraic import S, X
from symrot.plan.evaluation import log_grid

GRID_POINTS = 56
EDGE_POINTS = 12
JITTER = 0.0137
JITTER_SAMPLES = 6
REFERENCE_DIGITS = 60
EQUAL_SUM_OPS = 80
"""Largest sum (``count_ops``) compared with p by :func:`_with_equal_sums`: a size cap for ``cancel``."""
OFF_GRID = mpmath.mpf("0.37")
"""Where between two neighbouring angles of the format the measured inputs lie: an angle that the
format holds exactly would hide the rounding of φ̂ (θ of its rounded x is within 10⁻¹² of it
where p′ is large)."""


@lru_cache(maxsize=16)
def angle_grid(phi_max: float) -> np.ndarray:
    """Log grid towards 0 plus points approaching the edge of the range (φ_max − 10⁻ᵏ φ_max);
    computed once per φ_max (every form of every coefficient is measured there), read-only."""
    end = min(phi_max, 4 * np.pi)
    edge = end * (1 - log_grid(0.25, 1e-6, EDGE_POINTS))
    grid = np.unique(np.concatenate([log_grid(1e-7, end * (1 - 1e-6), GRID_POINTS), edge]))
    grid.setflags(write=False)
    return grid


class MeasuredInputs(NamedTuple):
    """Where a coefficient's forms are measured, per grid angle (:func:`angle_grid`): the rounded
    angles φ̂ the backends compute, the exact angles θ of the reference (mpmath numbers) and x = p²,
    s = √x, d = k² − x (the fold complement, 0 without one) as the backends have them."""

    angles: tuple[np.ndarray, ...]
    exact: tuple[tuple[object, ...], ...]
    squares: tuple[np.ndarray, ...]
    lengths: tuple[np.ndarray, ...]
    complements: tuple[np.ndarray, ...]


@lru_cache(maxsize=16)
def measured_inputs(argument: sp.Expr, phi_max: float, dtype: type,
                    complement: sp.Rational | None = None) -> MeasuredInputs:
    """The points of :class:`MeasuredInputs` for a coefficient of s = ``argument``(φ).

    Each grid angle contributes a few nearby arguments (JITTER): rounding errors fluctuate from one
    argument to the next, and a cancellation must not hide behind one lucky grid point. At each,
    x = p(φ)² rounded is the input; the reference is taken at the exact θ with p(θ) = √x, and
    every form gets φ̂ = θ rounded, as the backends compute it from s: the input's own rounding is
    not charged to a form, the rounding of φ̂ is (near an edge where p′ → ∞, √(1 − φ²/4) from φ̂
    loses every digit; cos(s/2) none). For ``argument`` = φ (Newton's ratio and slope, the
    quaternion scale) the input is the angle itself."""
    epsilon = float(np.finfo(dtype).eps)
    p_of = sp.lambdify(PHI, argument, modules=[mpmath_namespace(), "mpmath"])
    slope_of = sp.lambdify(PHI, sp.diff(argument, PHI), modules=[mpmath_namespace(), "mpmath"])
    from_length = argument != PHI
    k2 = mpmath.mpf(complement.p) / complement.q if complement is not None else None
    angles: list[np.ndarray] = []
    exact: list[tuple[object, ...]] = []
    squares: list[np.ndarray] = []
    complements: list[np.ndarray] = []
    with mpmath.workdps(40):
        for angle in angle_grid(phi_max):
            samples: np.ndarray = np.unique(np.asarray(angle * (1 - JITTER * np.arange(JITTER_SAMPLES)),
                                                       dtype=dtype))
            samples = samples[samples.astype(np.float64) < phi_max * (1 - 2 * epsilon)]  # rounded inside
            kept_phi, kept_theta, kept_x, kept_d = [], [], [], []
            for sample in samples:
                phi = mpmath.mpf(float(sample))
                if from_length:  # an angle between two numbers of the format, as from a generic p
                    phi += OFF_GRID * mpmath.mpf(float(np.spacing(sample)))
                value = p_of(phi)
                square = dtype(float(value**2)) if mpmath.isfinite(value) else dtype(np.inf)
                theta = _exact_angle(p_of, slope_of, phi, square) if from_length else phi
                if theta is None:
                    continue
                kept_phi.append(dtype(float(theta)))
                kept_theta.append(theta)
                kept_x.append(square)
                kept_d.append(dtype(float(k2 - mpmath.mpf(float(square)))) if k2 is not None else dtype(0))
            angles.append(np.asarray(kept_phi, dtype=dtype))
            exact.append(tuple(kept_theta))
            squares.append(np.asarray(kept_x, dtype=dtype))
            complements.append(np.asarray(kept_d, dtype=dtype))
    with np.errstate(all="ignore"):
        lengths = tuple(np.sqrt(x) for x in squares)
    return MeasuredInputs(tuple(angles), tuple(exact), tuple(squares), lengths, tuple(complements))


def _exact_angle(p_of: Callable[..., Any], slope_of: Callable[..., Any], phi: Any, square: Any) -> Any:
    """θ with p(θ) = √x by Newton from φ (x is p(φ)² rounded, so θ is within a few ulp of φ: four
    steps reach 40 digits), or None when x is not finite and positive or Newton does not converge
    (no real θ: past a fold)."""
    if not np.isfinite(square) or square <= 0:
        return None
    target, theta = mpmath.sqrt(mpmath.mpf(float(square))), phi
    for _ in range(4):
        slope = slope_of(theta)
        if not mpmath.isfinite(slope) or slope == 0:
            return None
        theta = theta - (p_of(theta) - target) / slope
    residual = p_of(theta) - target
    if not mpmath.isfinite(residual) or abs(residual) > mpmath.mpf(10) ** -30 * target:
        return None
    return theta


def with_length(expr: sp.Expr, argument: sp.Expr) -> sp.Expr:
    """``expr`` with p(φ) (and p's non-constant factor g, p = c·g) written as s = |p| and p² as x,
    which the backends have as rounded input: 4 atanh(φ/4) recomputed from φ̂ cancels near φ = 4."""
    if argument == PHI:
        return expr
    expr = _with_same_calls(expr, argument)
    coefficient, rest = argument.as_coeff_Mul()
    if argument.is_Add:  # sin(φ)/2 + sinh(φ)/2 = (sin φ + sinh φ)/2
        coefficient, rest = argument.as_content_primitive()
    rules: dict[sp.Expr, sp.Expr] = {argument**2: X, argument**-2: 1 / X, argument: S}
    if rest != argument and rest.has(PHI) and coefficient != 0:
        rules.update({rest**2: X / coefficient**2, rest**-2: coefficient**2 / X, rest: S / coefficient})
    written = expr.xreplace(rules)
    if argument.is_Mul and len(argument.args) > 1 and written.has(*argument.args):
        # p = sinh(φ) cosh(φ): 1/p² is the factors sinh⁻² cosh⁻² of a larger product, no subtree
        # that xreplace could match; subs matches such sub-products (an exact substitution still)
        written = written.subs([(argument**2, X), (argument, S)])
        written = _with_product_length(written, argument)
    if argument.is_Add and written.has(*argument.atoms(sp.Function)):
        written = _with_equal_sums(written, argument)
        factored = _factored(argument)
        if factored.is_Mul:
            written = _with_product_length(written, factored)
    return written


def _with_same_calls(expr: sp.Expr, argument: sp.Expr) -> sp.Expr:
    """``expr`` with every call of p's outer function on an argument that expands to p's own,
    written as p itself: the simplified tensors of eq 35 hold cbrt(6(φ − sin φ)) where p is
    cbrt(6φ − 6 sin φ), which no structural match finds (H⁻¹₀ = 2(1 − cos φ)/p² stayed a form in φ
    with a 16-term polynomial where 4 sin²(φ/2)/x needs 5)."""
    if not (isinstance(argument, sp.Function) and len(argument.args) == 1):
        return expr
    inner = sp.expand(argument.args[0])

    def same_call(node: sp.Expr) -> bool:
        return (node.func == argument.func and node != argument and len(node.args) == 1
                and sp.expand(node.args[0]) == inner)

    return expr.replace(same_call, lambda node: argument)


def _with_equal_sums(expr: sp.Expr, argument: sp.Expr) -> sp.Expr:
    """``expr`` with every sum that is a constant multiple c·p of the sum p, written otherwise (the
    simplified coefficients of φ cosh(3φ/2)/2 + 2 atan(φ/4)/(φ²/2 + 1) hold
    φ cosh(3φ/2)/2 + 4 atan(φ/4)/(φ² + 2)), as c·s, and s² as x: G₂ = 2 sin²(φ/4)/p² recomputed
    p from φ̂, 7 ulp next to 2π (hypothesis row 22). A sum qualifies when it has p's function calls
    and (sum − c·p) cancels to 0 for c its ratio to p at one angle."""
    calls = argument.atoms(sp.Function)

    def is_multiple(node: sp.Expr) -> bool:
        return (isinstance(node, sp.Add) and node.atoms(sp.Function) == calls
                and sp.count_ops(node) <= EQUAL_SUM_OPS and _ratio(node, argument) is not None)

    written = expr.replace(is_multiple, lambda node: _ratio(node, argument) * S)
    return written.xreplace({S**2: X, S**-2: 1 / X}) if written != expr else expr


@lru_cache(maxsize=4096)
def _ratio(node: sp.Expr, argument: sp.Expr) -> sp.Rational | None:
    """The rational c with node = c·argument identically, or None (the ratio is read at φ = 1/7,
    inside every range, and proved by ``cancel``)."""
    value = sp.nsimplify(sp.N((node / argument).subs(PHI, sp.Rational(1, 7)), 30), rational=True)
    if not value.is_Rational or value == 0 or sp.cancel(sp.together(node - value * argument)) != 0:
        return None
    return value


def _with_product_length(expr: sp.Expr, argument: sp.Expr) -> sp.Expr:
    """``expr`` with every power p^k (k ≠ 0 an integer) of a product p = c·∏ f_i^(e_i) of two or
    more factors in φ that a product of ``expr`` holds, written as (s/c)^k, (x/c²)^(k/2) for even k.
    ``subs`` misses p⁻¹ in 3 sin(φ)/(4 cosh(3φ/4) asin(3φ/4)) for p = 4 cosh(3φ/4) asin(3φ/4)/3
    (the constant differs): R₁ then recomputed asin(3φ̂/4) next to its edge at φ = 4/3, where
    the rounding of φ̂ costs 500 ulp (73 ulp of R at 4/3 − 10⁻⁵)."""
    constant, rest = argument.as_independent(PHI, as_Add=False)
    factors = rest.as_powers_dict()
    if len(factors) < 2 or constant == 0 or any(exponent.is_negative for exponent in factors.values()):
        # a factor of p's denominator vanishes at a pole, which symrot.plan.pole writes through s: for
        # φ/cos(φ/4) this rewrite displaced the forms it measured best (float32 `rescale` and
        # `compose` then missed 4 κ, 1.9·10⁶ ulp at 2π − 10⁻⁶; they met it before)
        return expr

    by_primitive = {_primitive(base)[1]: base for base in factors}

    def holds_a_power(term: sp.Expr) -> bool:
        return isinstance(term, sp.Mul) and all(base in _rescaled_bases(term, by_primitive).as_powers_dict()
                                                 for base in factors)

    def factor_out(term: sp.Expr) -> sp.Expr:
        term = _rescaled_bases(term, by_primitive)
        powers = term.as_powers_dict()
        ratios = [powers[base] / exponent for base, exponent in factors.items()]
        if not all(r.is_Rational and r * ratios[0] > 0 for r in ratios):
            return term
        k = int(min(ratios, key=abs))  # the largest whole power of p in the product
        if k == 0:
            return term
        length = (X / constant**2) ** (k // 2) if k % 2 == 0 else (S / constant) ** k
        return term * rest ** -k * length

    return expr.replace(holds_a_power, factor_out)


@lru_cache(maxsize=16)
def _factored(argument: sp.Expr) -> sp.Expr:
    """p with its terms' common factors taken out, once per p (every candidate form of a plan asks):
    13φ³cosh(φ/2)/3 + φ cosh(φ/2) = φ(13φ²/3 + 1) cosh(φ/2)."""
    return sp.factor_terms(argument)


def _primitive(base: sp.Expr) -> tuple[sp.Rational, sp.Expr]:
    """(c, b) with base = c·b, c a positive rational and b a sum with coprime integer coefficients
    (φ²/2 + 1 = ½ (φ² + 2)); (1, base) for anything else."""
    content, primitive = base.as_content_primitive() if base.is_Add else (sp.S.One, base)
    return (content, primitive) if content.is_Rational and content > 0 else (sp.S.One, base)


def _rescaled_bases(term: sp.Expr, by_primitive: dict[sp.Expr, sp.Expr]) -> sp.Expr:
    """``term`` with each power g^e of a base g = (c_g/c_f)·f, a positive multiple of a base f of p,
    written (c_g/c_f)^e f^e (``by_primitive``: p's bases f by their primitive parts): simplification
    writes p = √(φ²/2 + 1) sinh(2φ)/2 squared as (φ² + 2) sinh²(2φ)/8, whose sum is no base of p
    (hypothesis row 53: G₂ recomputed sinh(2φ̂)², 12 ulp of G in float32 next to 2π)."""
    replaced = {}
    for base, exponent in term.as_powers_dict().items():
        content, primitive = _primitive(base)
        own = by_primitive.get(primitive)
        if own is not None and own != base:
            replaced[base**exponent] = (content / _primitive(own)[0]) ** exponent * own**exponent
    return term.xreplace(replaced) if replaced else term


@lru_cache(maxsize=8)
def reference_values(forms: tuple[sp.Expr, ...], argument: sp.Expr, phi_max: float, dtype: type,
                      complement: sp.Rational | None) -> tuple[np.ndarray, ...]:
    """The coefficient at the exact angles of :func:`measured_inputs` at REFERENCE_DIGITS (float64
    of the result), from the first of ``forms`` that is not 0/0 there (NaN if none): 60 digits are
    enough for forms that cancel 40 near φ = 10⁻⁷ (slopes of K), so one reference serves every
    equivalent form of a coefficient."""
    inputs = measured_inputs(argument, phi_max, dtype, complement)
    with mpmath.workdps(REFERENCE_DIGITS):
        functions = [sp.lambdify(PHI, form, modules=[mpmath_namespace(), "mpmath"], cse=True)
                     for form in forms]
        values = []
        for thetas in inputs.exact:
            row = []
            for theta in thetas:
                row.append(math.nan)
                for function in functions:
                    try:
                        row[-1] = float(function(theta))
                        break
                    except ZeroDivisionError:
                        continue
            values.append(np.asarray(row, dtype=np.float64))
    return tuple(values)
