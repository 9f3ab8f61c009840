"""NumPy backend: prints an ``EvaluationPlan`` (``symrot.plan.builder``) as a self-contained module.

The module (NumPy only) exposes, for p of shape (..., 3): ``angle`` (φ), ``rotation_matrix`` (R,
eq 16), ``tangent`` (H, ω = H ṗ, eq 20), ``tangent_inverse`` (H⁻¹, eq 26), ``tangent_det`` (det H,
eq 24), ``root_matrix`` (G, eq 81), ``root_tangent`` (K, eq 83), ``pdot`` (ṗ = H⁻¹ ω, eq 25) and
``omega`` (ω = H ṗ), and the operations on rotations of any size ``to_quaternion``,
``from_quaternion``, ``from_rotation_matrix``, ``compose`` (R(p3) = R(p2) R(p1)) and ``rescale``
(eqs 18–19, 40–47, 61–65, 74–75), and the derivatives of issue 19 (``rotation_derivative``,
``tangent_derivative``, … ``angular_acceleration``, ``compose_jacobians``, ``rescale_jacobian``;
:mod:`symrot.backends.numpy_derivatives`).  float32 input is evaluated with the float32 plan, anything else
as float64.  Outside the validity range |p| < p_max (|p|² < 2⁶⁰⁰ when p is unbounded) every output
is NaN.  Tensors are written in place into the (..., 3, 3) result: up to 64 vectors in one pass
(entries gathered by index), more in blocks of 4096 (temporaries of 32 KiB, under glibc's mmap
threshold).  A block whose lanes are all inside the range on one side of a coefficient's switch
takes that branch on every lane; otherwise each coefficient's Horner polynomial and closed form
run only on the lanes where they apply.  sin(φ/2), cos(φ/2) are computed once per block for all
the coefficients that need them, and only when some lane needs them.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
import sympy as sp
from sympy.printing.numpy import NumPyPrinter

from symrot.backends.numpy_derivatives import derivative_lines, rate_lines
from symrot.backends.runtime import runtime_text
from symrot.backends.series_tables import SeriesTables
from symrot.backends.subexpressions import alias_repeated, common_subexpressions
from symrot.backends.templating import render
from symrot.core.atomic import write_atomic
from symrot.core.parsing import PHI
from symrot.plan.algebraic import D, S, X
from symrot.plan.builder import evaluation_plan
from symrot.plan.forms import half_angle
from symrot.plan.ir import (
    ANGLE_CORRECTION_GROWTH,
    Algebraic,
    Branch,
    ClosedAngle,
    Constant,
    EvaluationPlan,
    NewtonAngle,
    uses_angle,
)
from symrot.plan.newton_start import FarStart, edge_floor, edge_step
from symrot.plan.quaternion import E0, ROTATION_TOLERANCE_POWER, QuaternionScale

TENSORS = ("R", "H", "H_inverse", "G", "K")
SUFFIX = {"float64": "64", "float32": "32"}


class SymrotNumPyPrinter(NumPyPrinter):
    """NumPyPrinter with the real cube root and exact rationals printed as float literals."""

    def _print_RealCbrt(self, expr: Any) -> str:
        return f"{self._module_format('numpy.cbrt')}({self._print(expr.args[0])})"

    def _print_Rational(self, expr: sp.Rational) -> str:
        return repr(float(expr))

    def _print_Half(self, expr: sp.Rational) -> str:
        return "0.5"

    def _print_BoundedPower(self, expr: Any) -> str:
        """(b)**n of :class:`symrot.core.functions.BoundedPower`, never bⁿ's expansion."""
        base, exponent = expr.args
        text = f"({self._print(base)})"
        return text if exponent == 1 else f"{text}**{self._print(exponent)}"


def _printer() -> SymrotNumPyPrinter:
    return SymrotNumPyPrinter({"fully_qualified_modules": True, "inline": True})


def print_expression(expr: sp.Expr) -> str:
    return _printer().doprint(expr)


def numpy_function(expr: sp.Expr) -> Callable[[Any], Any]:
    """φ ↦ expr(φ) evaluated by the same printer (used by the plan's error model)."""
    source = f"def f(phi):\n    return {print_expression(expr)}\n"
    namespace: dict[str, Any] = {"numpy": np}
    exec(compile(source, "<symrot numpy>", "exec"), namespace)
    return namespace["f"]


def _literal(value: sp.Expr) -> str:
    return repr(float(value))


SIN_HALF = sp.Symbol("sin_half")
COS_HALF = sp.Symbol("cos_half")


def branch_switch(coefficient: Any) -> float:
    """The x (or t) at which the NumPy module leaves a Branch's polynomial for its closed form
    (0 for the other coefficients: no polynomial)."""
    return coefficient.smallest_switch[0] if isinstance(coefficient, Branch) else 0.0


def _branch_lines(branch: Branch, variable: str, phi: str, half_angles: bool = False,
                  corrected: bool = False, tables: SeriesTables | None = None, owner: str = "") -> list[str]:
    """Statements returning the Branch value from ``variable`` (t) and ``phi``: the Horner
    polynomial on the lanes with t < threshold, the closed form on the others (each computed on
    its own lanes only, so neither can divide by zero and no work is wasted). The switch is the
    smallest the accuracy allows: a second branch costs a masked pass over the arrays, more than
    a longer polynomial saves here (unlike in C, which uses ``branch.threshold``).

    With ``half_angles`` (the coefficient functions) the argument ``span`` = (min t, max t) of a
    block whose lanes are all inside the range (None otherwise, see the template's _span) lets a
    block on one side of the switch take its branch on all lanes, without masks or indexing.
    ``corrected``: the angle's half-angle sine and cosine carry λ (``EvaluationPlan.angle_correction``),
    and sin φ, cos φ are printed through them (:func:`symrot.plan.forms.half_angle`). ``tables``:
    the polynomial reads its coefficients from the module's tuples (``_horner``, named after
    ``owner``) instead of one statement per term."""
    threshold, horner = branch.smallest_switch
    closed = half_angle(branch.closed) if corrected else branch.closed
    if half_angles:  # sin(φ/2), cos(φ/2) come precomputed, shared by the coefficients of a tensor
        closed = closed.xreplace({sp.sin(PHI / 2): SIN_HALF, sp.cos(PHI / 2): COS_HALF})
    symbols = [symbol for symbol in (X, S, D, SIN_HALF, COS_HALF) if closed.has(symbol)]
    closed = closed.subs(PHI, sp.Symbol("phi"))
    replacements, (reduced,) = common_subexpressions([closed], "w")
    closed_lines = [f"{symbol} = {print_expression(value)}" for symbol, value in replacements]
    series_lines = [f"series = {_literal(horner[-1])}"]
    if tables is not None and len(horner) > 1:
        table = tables.reference(owner, [_literal(c) for c in horner])
        series_lines = [f"series = _horner({table}, {len(horner)}, t)"]
    else:
        for c in reversed(horner[:-1]):
            series_lines.append(f"series = {_literal(c)} + t * series" if c != 0 else "series = t * series")
    lines: list[str] = []
    if half_angles:
        # one Horner polynomial for both paths: on every lane (the block is below the switch) or on
        # the lanes below it, after the closed form on every lane (phi, sin and cos are there for
        # the whole block), where the closed form may be 0/0
        if len(horner) > 1:
            lines += [f"polynomial = span is not None and span[1] < {threshold!r}  # every lane on it",
                      "if polynomial:", f"    t = {variable}", "else:"]
        else:
            lines += [f"if span is not None and span[1] < {threshold!r}:  # every lane on the polynomial",
                      f"    return numpy.full_like({variable}, {_literal(horner[0])})"]
        body = list(closed_lines)
        if not reduced.free_symbols:
            body.append(f"out = numpy.full_like({variable}, {print_expression(reduced)})")
        else:
            copy = "array" if reduced.is_Symbol else "asarray"  # never write into an argument
            body.append(f"out = numpy.{copy}({print_expression(reduced)}, dtype={variable}.dtype)")
        body += [f"if span is not None and span[0] >= {threshold!r}:  # every lane on the closed form",
                 "    return out", f"small = {variable} < {threshold!r}"]
        if len(horner) > 1:
            body += ["if not small.any():", "    return out", f"t = {variable}[small]"]
            lines += ["    " + line for line in body]
            lines += series_lines
            lines += ["if polynomial:", f"    return numpy.asarray(series, dtype={variable}.dtype)",
                      "out[small] = series", "return out"]
        else:
            lines += body
            lines += ["if small.any():", *("    " + line for line in series_lines),
                      "    out[small] = series", "return out"]
        return lines
    lines += [f"small = {variable} < {threshold!r}", f"out = numpy.empty_like({variable})",
              "if small.any():"]
    if len(horner) > 1:
        lines.append(f"    t = {variable}[small]")
    lines += ["    " + line for line in series_lines]
    lines.append("    out[small] = series")
    lines += ["if not small.all():", "    big = ~small"]
    if closed.has(sp.Symbol("phi")):
        lines.append(f"    phi = {phi}[big]")
    for symbol in symbols:  # a closed form in x too (e.g. 2000/(x + 1))
        lines.append(f"    {symbol} = {symbol}[big]")
    lines += ["    " + line for line in closed_lines]
    lines.append(f"    out[big] = {print_expression(reduced)}")
    lines.append("return out")
    return lines


def _angle_lines(angle: ClosedAngle | NewtonAngle, tables: SeriesTables | None = None) -> list[str]:
    """φ(s): the closed inverse, or eq 35's Newton iteration from its start (the Taylor polynomial
    s·start(s²) below the far switch, a Chebyshev series above it). ``tables``: the start's and
    the far series' coefficients from the module's tuples (``_horner``, ``_clenshaw``)."""
    if isinstance(angle, ClosedAngle):
        expression = angle.expression.subs(S, sp.Symbol("s"))
        return [f"return {print_expression(expression)} + 0.0 * s"]
    far = angle.far
    if tables is not None:
        start = tables.reference("angle_start", [_literal(c) for c in angle.start])
        chebyshev = tables.reference("angle_far", [_literal(c) for c in far.chebyshev])
        start_lines = [f"start = _horner({start}, {len(angle.start)}, s2)"]
        far_lines = [f"v = {_far_variable(far)}", "y = 2.0 * v - 1.0", f"far = _clenshaw({chebyshev}, y)"]
    else:
        start_lines = [f"start = {_literal(angle.start[-1])}"]
        start_lines += [f"start = {_literal(c)} + s2 * start" for c in reversed(angle.start[:-1])]
        # Clenshaw's recurrence for Σ c_j T_j(y) (the monomial form loses every digit in float32)
        far_lines = [f"v = {_far_variable(far)}", "y = 2.0 * v - 1.0", "b1 = numpy.zeros_like(y)",
                     "b2 = numpy.zeros_like(y)"]
        far_lines += [f"b1, b2 = {c!r} + 2.0 * y * b1 - b2, b1" for c in far.chebyshev[:0:-1]]
        far_lines.append(f"far = {far.chebyshev[0]!r} + y * b1 - b2")
    return [
        "s2 = s * s",
        *start_lines,
        *far_lines,
        f"phi = numpy.where(s < {far.switch!r}, s * start, far)",
        f"phi = numpy.clip(phi, 0.0, {min(angle.phi_max, angle.fold_top)!r}).astype(s.dtype)",
        "low = numpy.zeros_like(s)",
        f"high = numpy.full_like(s, {angle.phi_max!r})",
        f"for _ in range({angle.iterations}):",
        *("    " + line for line in newton_residual_lines(angle, "_ratio(phi * phi)", _literal)),
        "    high = numpy.where(residual > 0, phi, high)",
        "    low = numpy.where(residual <= 0, phi, low)",
        "    slope = _slope(phi * phi, phi)",
        "    safe = slope > 0",
        *newton_step_lines(angle),
        "    phi = numpy.where(inside, step, 0.5 * (low + high)).astype(s.dtype)",
        *([f"return numpy.minimum(phi, {angle.fold_top!r}).astype(s.dtype)  # NewtonAngle.fold_top"]
          if math.isfinite(angle.fold_top) else ["return phi"]),
    ]


def newton_residual_lines(angle: NewtonAngle, ratio_call: str, literal: Callable[[sp.Expr], str],
                          where: str = "numpy.where") -> list[str]:
    """``tail`` = φ·(g − g(0)) and the residual of the Newton angle: (φ·g(0) − s) + tail where the
    tail's polynomial applies (the difference first: exact once φ is within a factor 2 of s), and
    φ·(g(0) + tail's ratio) − s = φ·g − s above (:class:`symrot.plan.ir.NewtonAngle`); ``value`` =
    p(φ) where the reciprocal step needs it. ``ratio_call`` prints g − g(0)."""
    head = "phi" if angle.leading == 1 else f"phi * {literal(angle.leading)}"
    whole = "1.0" if angle.leading == 1 else literal(angle.leading)
    return [f"ratio = {ratio_call}", "tail = phi * ratio",
            f"residual = {where}(phi * phi < {angle.split_below!r}, ({head} - s) + tail, "
            f"phi * ({whole} + ratio) - s)",
            *([f"value = {head} + tail"] if angle.reciprocal else [])]


def newton_low_lines(angle: NewtonAngle, where: str) -> list[str]:
    """λ = −residual/p′ where φ p′ > ANGLE_CORRECTION_GROWTH·s, 0 elsewhere (after
    :func:`newton_residual_lines` and ``slope``): one more Newton correction of φ."""
    return [
        f"useful = phi * slope > {ANGLE_CORRECTION_GROWTH!r} * s",
        f"low = -residual / {where}(useful, slope, 1.0)"
        + (f" * (value / {where}(s > 0, s, 1.0))" if angle.reciprocal else ""),
        f"return {where}(useful, low, 0.0)",
    ]


def newton_step_lines(angle: NewtonAngle, where: str = "numpy.where", module: str = "numpy",
                      printer: Callable[[sp.Expr], str] | None = None) -> list[str]:
    """``step`` and ``inside`` of the safeguarded iteration: Newton in φ (on 1/p if reciprocal) or,
    with an edge exponent k, in w = (φ_max − φ)^k (:func:`symrot.plan.newton_start.edge_step`); every
    operand is safe on every lane (the array backends pass their own ``where``, ``module`` and
    printer)."""
    finite = f"    safe = safe & {module}.isfinite(slope)"  # p′ = ∞: a zero step would stay
    if angle.edge is None:
        return [finite,
                f"    step = phi - residual / {where}(safe, slope, 1.0)"
                + (f" * (value / {where}(s > 0, s, 1.0))" if angle.reciprocal else ""),
                "    inside = safe & (step >= low) & (step <= high)"]
    floor = edge_floor(angle.edge)
    return [
        finite,
        f"    change = residual / {where}(safe, slope, 1.0)",
        f"    delta = {angle.phi_max!r} - phi",
        f"    u = {float(angle.edge)!r} * change / {where}(delta > 0, delta, 1.0)",
        f"    change = {where}(u < {floor!r}, {floor!r} * delta / {float(angle.edge)!r}, change)",
        f"    u = {where}(u < {floor!r}, {floor!r}, u)",
        "    defined = delta > 0",
        f"    u = {where}(defined, u, 0.0)",
        f"    step = {(printer or print_expression)(edge_step(angle.edge))}",
        "    inside = safe & defined & (step >= low) & (step <= high)",
    ]


def _angle_low_lines(angle: NewtonAngle) -> list[str]:
    """λ ≈ φ* − φ, one more Newton correction of the iterate φ where p grows fast enough for it to
    help (0 elsewhere); see ``EvaluationPlan.angle_correction``."""
    lines = [*newton_residual_lines(angle, "_ratio(phi * phi)", _literal), "slope = _slope(phi * phi, phi)",
             *newton_low_lines(angle, "numpy.where")]
    return [*lines[:-1], lines[-1] + ".astype(s.dtype)"]


def _far_variable(far: FarStart) -> str:
    """v(s) of the far-field Newton start (symrot.plan.newton_start)."""
    if far.kind == "fold":
        power = f"numpy.power({{}}, {1 / far.order!r})"
        root = {2: "numpy.sqrt({})", 3: "numpy.cbrt({})"}.get(far.order, power)
        return "1.0 - " + root.format(f"numpy.maximum(1.0 - s / {far.scale!r}, 0.0)")
    if far.kind == "linear":
        return f"numpy.minimum(s / {far.scale!r}, 1.0)"
    return f"s / (s + {far.scale!r})"


def module_context(plan: EvaluationPlan) -> dict[str, Any]:
    functions: list[dict[str, Any]] = []
    tables = SeriesTables()
    for label, precision in plan.precisions.items():
        functions.extend(module_context_functions(precision, SUFFIX[label], angle_low_helpers(plan), tables))
    p_max = plan.p_max
    e0_min = repr(plan.e0_min) if plan.e0_min is not None else None
    squared, inclusive = plan.boundary(53)  # float32 x compares exactly against the double bound
    return {"name": plan.name, "p_text": str(plan.p), "functions": alias_repeated(functions),
            "e0_min": e0_min,
            "names": list(plan.precisions["float64"].coefficients),
            "across": repr(tuple(sorted(plan.across_tensors()))),
            "p_max": repr(p_max) if np.isfinite(p_max) else None, "phi_max": repr(plan.phi_max),
            "complement": str(plan.complement) if plan.complement is not None else None,
            "complement_low": complement_low(plan),
            "p_max_squared": repr(squared) if np.isfinite(squared) else "numpy.inf",
            "p_max_squared_finite": bool(np.isfinite(squared)),
            "inclusive": inclusive,
            "x_limit": {SUFFIX[label]: repr(precision.x_limit)
                        for label, precision in plan.precisions.items()},
            "derivative_x_limit": {SUFFIX[label]: repr(precision.derivative_x_limit)
                                   for label, precision in plan.precisions.items()},
            "x_limit_power": {SUFFIX[label]: math.frexp(precision.x_limit)[1] - 1
                              for label, precision in plan.precisions.items()},
            "rotation_tolerance_power": {SUFFIX[label]: ROTATION_TOLERANCE_POWER[label]
                                         for label in plan.precisions},
            "derivative_lines": derivative_lines(), "rate_lines": rate_lines(),
            "runtime": runtime_text("numpy_runtime") + "\n\n" + runtime_text("numpy_operations"),
            "series_tables": tables.context(),
            "angle_low": angle_low_helpers(plan),
            "uses_phi": {SUFFIX[label]: {n: uses_phi(c) for n, c in precision.coefficients.items()}
                         for label, precision in plan.precisions.items()},
            "switch": {SUFFIX[label]: {n: branch_switch(c) for n, c in precision.coefficients.items()
                                       if uses_phi(c)}
                       for label, precision in plan.precisions.items()}}


def angle_low_helpers(plan: EvaluationPlan) -> dict[str, dict[str, str]]:
    """{suffix: {"helper": its _angle_low function, "bound": the largest |λ|/φ applied}}
    (``EvaluationPlan.angle_correction``, ``angle_correction_bound``)."""
    return {SUFFIX[label]: {"helper": f"_angle_low_{SUFFIX[source]}",
                            "bound": repr(plan.angle_correction_bound(label))}
            for label, source in plan.angle_correction().items()}


def uses_phi(coefficient: Any) -> bool:
    """Whether the coefficient's code needs the angle φ (``plan_ir.uses_angle``)."""
    return uses_angle(coefficient)


def module_context_functions(precision: Any, suffix: str, angle_low: dict[str, dict[str, str]],
                             tables: SeriesTables) -> list[dict[str, Any]]:
    functions = []
    for name, coefficient in precision.coefficients.items():
        if isinstance(coefficient, Constant):
            body = [f"return numpy.full_like(x, {_literal(coefficient.value)})"]
        elif isinstance(coefficient, Algebraic):
            expression = coefficient.expression.subs(X, sp.Symbol("x"))
            # float64 intermediates: powers such as (x + 16)**4 must not overflow float32
            body = ["x = x.astype(numpy.float64)"] if suffix == "32" else []
            if expression.has(D) and suffix == "32":
                body.append("d = d.astype(numpy.float64)")
            value = print_expression(expression)
            if not coefficient.expression.has(X):
                value = f"({value}) + 0.0 * x"
            body.append(f"return numpy.asarray({value}).astype(numpy.float{suffix}, copy=False)")
        else:
            body = _branch_lines(coefficient, "x", "phi", half_angles=True, corrected=suffix in angle_low,
                                 tables=tables, owner=name)
        functions.append({"name": f"_{name}_{suffix}",
                          "args": "x, phi, s, d, sin_half, cos_half, span=None", "body": body})
    angle = precision.angle
    if isinstance(angle, NewtonAngle):
        for helper, branch in (("_ratio", angle.ratio), ("_slope", angle.slope)):
            functions.append({"name": f"{helper}_{suffix}", "args": "t, phi",
                              "body": _branch_lines(branch, "t", "phi", tables=tables, owner=helper[1:])})
    def helpers(lines: list[str]) -> list[str]:
        return [line.replace("_ratio(phi * phi)", f"_ratio_{suffix}(phi * phi, phi)")
                .replace("_slope(", f"_slope_{suffix}(") for line in lines]

    functions.append({"name": f"_angle_{suffix}", "args": "s, d",
                      "body": helpers(_angle_lines(angle, tables))})
    if any(low["helper"] == f"_angle_low_{suffix}" for low in angle_low.values()):
        body = (helpers(_angle_low_lines(angle)) if isinstance(angle, NewtonAngle)
                else [f"return _angle_{suffix}(s, None) - phi"])  # a closed angle serving float32
        functions.append({"name": f"_angle_low_{suffix}", "args": "s, phi", "body": body})
    functions.append({"name": f"_scale_{suffix}", "args": "e0, e_norm",
                      "body": _scale_lines(precision.quaternion_scale, suffix, tables)})
    return functions


def _scale_lines(scale: QuaternionScale, suffix: str, tables: SeriesTables) -> list[str]:
    """σ(e₀, |e|) with p = σ e on the hemisphere e₀ ≥ 0 (see symrot.plan.quaternion)."""
    if scale.algebraic is not None:
        expression = scale.algebraic.subs(E0, sp.Symbol("e0"))
        return ["e0 = e0.astype(numpy.float64)",
                f"return (({print_expression(expression)}) + 0.0 * e0).astype(numpy.float{suffix})"]
    assert isinstance(scale.branch, Branch)
    lines = _branch_lines(scale.branch, "t", "phi", tables=tables, owner="scale")
    if suffix == "64":
        return ["phi = (2.0 * numpy.arctan2(e_norm, e0)).astype(e0.dtype)", "t = phi * phi", *lines]
    # float32: φ and σ in float64, rounded once. Next to a pole at φ_max, rounding φ to float32
    # costs more than the rounding of e does (3 cosh(2φ) atanh(φ/3) at φ = 3 − 10⁻⁶: 5.8·10⁴ ulp,
    # more than 4 κ on one machine and less on another; tests/test_plan_user_functions.py)
    assert lines[-1] == "return out"
    return ["phi = 2.0 * numpy.arctan2(e_norm.astype(numpy.float64), e0.astype(numpy.float64))",
            "t = phi * phi", *lines[:-1], "return out.astype(numpy.float32)"]


def complement_low(plan: EvaluationPlan) -> str | None:
    """The float64 literal of what p_max² − fl(p_max²) leaves (:meth:`EvaluationPlan.complement_parts`),
    the start of the compensated sum's low part; None when p_max² is a float64 (the named families)."""
    if plan.complement is None:
        return None
    _high, low = plan.complement_parts(53)
    return repr(float(low)) if low != 0 else None


def module_source(plan: EvaluationPlan) -> str:
    source = render("numpy_module.py.j2", **module_context(plan))
    if any(len(line) > 110 for line in source.splitlines()):
        source = "# ruff: noqa: E501  (printed closed forms exceed the line length)\n" + source
    return source


def emit(derivation: Any, name: str, out: Path) -> list[Path]:
    """Write ``out/NAME.py`` for ``derivation``; return the written paths."""
    out.mkdir(parents=True, exist_ok=True)
    path = out / f"{name}.py"
    write_atomic(path, module_source(evaluation_plan(derivation, name)))
    return [path]
