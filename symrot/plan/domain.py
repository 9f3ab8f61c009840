"""The documented domain of generated code: the largest x = |p|² up to which every printed form is right.

Outside the validity range every output is NaN. When p is unbounded (p → ∞ at φ_max: the tangent
family, eqs 33–34, 36) the range is cut off at a large power of two instead, x < 2^600 in float64
and 2^100 in float32, so that x = |p|² itself never overflows. That is not enough: the *printed*
forms can overflow long before x does (Wiener–Milenkovic's H₂ = 128/(x + 16)² overflows for
x > 1.3·10¹⁵⁴, i.e. |p| ≳ 10⁷⁷, and gave 1.6·10⁻¹⁵⁹·I instead of NaN, issue 17).

:func:`domain_limit` therefore evaluates every printed coefficient (algebraic forms, the closed side
of branches, the closed angle) in the target precision with the ideal-libm model of
:mod:`symrot.plan.evaluation`, at x = 2^k and 1.3·2^k (:data:`OFF_POWER`) for k = :data:`FIRST_POWER` …
top, against mpmath at a precision that resolves φ next to φ_max, and returns the largest 2^k
below which all of them are finite and within :data:`WRONG_ULP` of the output they feed
(:func:`_weight_and_scale`).
Backends print that bound as the edge of the domain. A form that is merely less accurate (a few
ulp) does not move the bound: the error model chose it; this sweep catches overflow, underflow and
cancellation that make a result wrong, not imprecise.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from functools import lru_cache
from typing import Any

import mpmath
import numpy as np
import sympy as sp

from symrot.core.functions import mpmath_namespace
from symrot.core.parsing import PHI
from symrot.plan.algebraic import D, S, X
from symrot.plan.angle_solve import angle_of_length
from symrot.plan.evaluation import model_function

TOP_POWER = {"float64": 600, "float32": 100}
"""x < 2^TOP_POWER: the cut-off of unbounded ranges (x itself must stay finite)."""
FIRST_POWER = 32
"""The sweep starts at x = 2^32: below it the plan's own error model has measured every form."""
OFF_POWER = 1.3
"""The second point of each octave, x = 2^k·1.3 (not √2, whose square is 2): at x = 2^k itself
16/(x + 16), its square and a power-of-two multiple are often exact, which hides the rounding of a
form that underflows (the tangent's H₂ = (16/(x + 16))²/8 of Wiener–Milenkovic is subnormal from
x = 2^514 in float64)."""
WRONG_ULP = 64.0
"""A relative error beyond this many ulp is a wrong result, not an imprecise one."""
CHUNK = 16
"""Points of the sweep whose forms are evaluated in one call of each model: most ranges end within
the first few octaves, and the references of a chunk's points past the first wrong one are wasted."""


def domain_limit(coefficients: Mapping[str, tuple[str, Any]], references: Mapping[str, sp.Expr],
                 p: sp.Expr, inverse: sp.Expr | None, phi_max: float, p_max: float, dtype: type) -> float:
    """The largest 2^k ≤ 2^TOP_POWER with every form right for x < 2^k (module docstring).

    ``coefficients``: name → (kind, expression) with kind "algebraic" (in x, d) or "closed" (in φ,
    s, d), as printed; ``references``: name → c(φ) for every coefficient (also those not swept:
    a tensor's scale needs all three of its coefficients)."""
    label = "float64" if dtype is np.float64 else "float32"
    top = TOP_POWER[label]
    if math.isfinite(p_max) and p_max * p_max < 2.0**FIRST_POWER:
        return 2.0**top
    models = {name: model_function(expression, [X, PHI, S, D])
              for name, (_, expression) in coefficients.items()}
    exact = _reference_function(tuple(references.items()))
    angle_of = _angle_function(p, inverse, phi_max)
    complement = p_max * p_max if math.isfinite(p_max) else math.inf
    floors = _floors(exact, references, math.isfinite(p_max))
    points = [(x, k, edge) for k in range(FIRST_POWER, top + 1)
              for x, edge in ((2.0**k, 2.0 ** (k - 1)), (2.0**k * OFF_POWER, 2.0**k))]
    for start in range(0, len(points), CHUNK):
        chunk = points[start:start + CHUNK]
        wrong = _first_wrong(chunk, models, exact, angle_of, complement, dtype, floors)
        if wrong is not None:  # every point before it is below p_max² (_first_wrong stops there)
            edge = chunk[wrong][2]
            return edge if edge >= 2.0**FIRST_POWER else 2.0**FIRST_POWER
        if chunk[-1][0] >= complement:  # the sweep reached p_max² with every form right
            return 2.0**top
    return 2.0**top


def _floors(exact: Callable[[mpmath.mpf], dict[str, mpmath.mpf]], references: Mapping[str, sp.Expr],
            bounded: bool) -> dict[str, float]:
    """Scales below which a scalar is judged absolutely: det H at p = 0 for det H when p is bounded.
    Then det H = μν² → 0 with ν at 2π, where it is ill conditioned in s (its form from φ̂ was 91 ulp
    off at φ = 6.24 for √(φ²/2 + 1) sinh(2φ)/2, an imprecise result, not a wrong one, and the range
    ended there, every output NaN up to 2π); the plan measures it against the same floor
    (:data:`symrot.plan.branches.OWN_SCALE`). Next to a pole (p unbounded) it keeps its relative accuracy."""
    if not bounded or "det_H" not in references:
        return {}
    with mpmath.workdps(40):
        return {"det_H": float(abs(exact(mpmath.mpf(10) ** -12)["det_H"]))}


def _first_wrong(points: list[tuple[float, int, float]], models: Mapping[str, Callable[..., Any]],
                 exact: Callable[[mpmath.mpf], dict[str, mpmath.mpf]],
                 angle_of: Callable[[float, int], mpmath.mpf],
                 complement: float, dtype: type, floors: Mapping[str, float]) -> int | None:
    """The index of the first of ``points`` (x, k, edge; 2^k ≤ x < 2^(k+1)) at which a printed
    form is not finite or not within :data:`WRONG_ULP` of its scale (:func:`_weight_and_scale`, at
    least ``floors``), or None. The references are computed point by point, up to the first that
    cannot be (and only below ``complement``); each model is evaluated once on all of them (the
    ideal-libm model is elementwise: one call per chunk, not one per point and form)."""
    epsilon = float(np.finfo(dtype).eps)
    tiny = float(np.finfo(dtype).tiny)
    exact_values: list[tuple[mpmath.mpf, dict[str, mpmath.mpf]] | None] = []
    columns: list[list[float]] = [[], [], [], []]
    for x, k, _ in points:
        if x >= complement:
            break
        digits = _digits(k)
        with mpmath.workdps(digits):
            s_exact = mpmath.sqrt(mpmath.mpf(x))
            try:
                phi = angle_of(x, digits)
                values = exact(phi)
            except (ZeroDivisionError, ValueError, OverflowError):
                # φ is indistinguishable from the pole at this precision (p ~ e^(1/(φ_max − φ)),
                # e.g. atanh): nothing beyond can be verified, so the domain ends here
                exact_values.append(None)
                break
        exact_values.append((s_exact, values))
        for column, value in zip(columns, (x, float(phi), float(s_exact),
                                           complement - x if math.isfinite(complement) else 0.0),
                                 strict=True):
            column.append(value)
    measured = len(columns[0])
    arguments: list[np.ndarray] = [np.asarray(column, dtype=dtype) for column in columns]
    printed = {name: np.broadcast_to(np.asarray(model(*arguments), dtype=np.float64), (measured,))
               for name, model in models.items()} if measured else {}
    for index, known in enumerate(exact_values):
        if known is None:
            return index
        s_exact, values = known
        tensor_scales: dict[str, float] = {}
        with mpmath.workdps(_digits(points[index][1])):
            for name in models:
                reference = values[name]
                if not mpmath.isfinite(reference):
                    continue
                value = float(printed[name][index])
                weight, scale = _weight_and_scale(name, values, s_exact, tensor_scales)
                scale = max(scale, floors.get(name, 0.0))
                allowed = WRONG_ULP * epsilon * max(scale, tiny)
                if not math.isfinite(value) or float(abs(mpmath.mpf(value) - reference) * weight) > allowed:
                    return index
    return None


def _digits(k: int) -> int:
    """The working digits at x ≥ 2^k: φ_max − φ ~ 1/√x must be resolved."""
    return 40 + k // 3


def _weight_and_scale(name: str, values: Mapping[str, mpmath.mpf], s: mpmath.mpf,
                      tensor_scales: dict[str, float] | None = None) -> tuple[mpmath.mpf, float]:
    """How an error in coefficient ``name`` shows in the output, and the output's scale
    (``tensor_scales``: the scales of the tensors at this point, filled as they are computed).

    A tensor coefficient c_k multiplies (p×)^k, of norm s^k: its error counts as |δc_k| s^k against
    the tensor's size max_j |c_j| s^j (the across-axis part t = c₀ − c₂ s² multiplies I, as the plan
    measures it: ``T_across`` as c_0) (so R₁ = sin φ/s next to a pole is judged on sin φ, and an
    H₂ that underflows to 0 while H₀ does too is caught). e₀ and ν s/2 are quaternion components
    (scale 1); every other scalar, and the angle, keeps its own relative accuracy."""
    if name == "e_0":  # before the tensors: "e_0" reads as coefficient 0 of a tensor "e"
        return mpmath.mpf(1), 1.0
    tensor, _, power = name.rpartition("_")
    if tensor and (power.isdigit() or power == "across") and f"{tensor}_0" in values:
        weight = s ** int(power) if power.isdigit() else mpmath.mpf(1)
        known = {} if tensor_scales is None else tensor_scales
        if tensor not in known:
            sizes = (abs(values.get(f"{tensor}_{j}", mpmath.mpf(0))) * s**j for j in range(3))
            known[tensor] = float(max(sizes))
        return weight, known[tensor]
    if name == "nu":
        return s / 2, 1.0
    return mpmath.mpf(1), float(abs(values[name]))


@lru_cache(maxsize=16)
def _reference_function(
        references: tuple[tuple[str, sp.Expr], ...]) -> Callable[[mpmath.mpf], dict[str, mpmath.mpf]]:
    """name → c(φ) for every reference at once, with common subexpressions evaluated once (``cse``):
    the references of one tensor share tan(φ/4), sin φ, … and evaluating each on its own at up to
    240 digits was 80 % of a plan's sweep time."""
    names = [name for name, _ in references]
    joint = sp.lambdify(PHI, [expression for _, expression in references],
                        modules=[mpmath_namespace(), "mpmath"], cse=True)

    def values(phi: mpmath.mpf) -> dict[str, mpmath.mpf]:
        return dict(zip(names, joint(phi), strict=True))

    return values


@lru_cache(maxsize=16)
def _angle_function(p: sp.Expr, inverse: sp.Expr | None,
                    phi_max: float) -> Callable[[float, int], mpmath.mpf]:
    """φ(√x) at ``digits`` digits: the closed inverse, or :func:`angle_of_length`. Memoized per
    (x, digits): a plan sweeps the same points four times (kinematic forms and slopes, two
    precisions), and the bisection was half of the sweep's time."""
    exact_inverse = (sp.lambdify(S, inverse, modules=[mpmath_namespace(), "mpmath"])
                     if inverse is not None else None)
    p_of = sp.lambdify(PHI, p, modules=[mpmath_namespace(), "mpmath"])
    slope_of = sp.lambdify(PHI, sp.diff(p, PHI), modules=[mpmath_namespace(), "mpmath"])

    @lru_cache(maxsize=4096)
    def angle(x: float, digits: int) -> mpmath.mpf:
        with mpmath.workdps(digits):
            s = mpmath.sqrt(mpmath.mpf(x))
            if exact_inverse is not None:
                return exact_inverse(s)
            return angle_of_length(p_of, slope_of, s, phi_max)

    return angle
