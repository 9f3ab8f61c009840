"""Array-framework backends (JAX, PyTorch): print an ``EvaluationPlan`` as a branch-free module.

One printer and one template (``symrot/backends/templates/array_module.py.j2``) serve both frameworks; the
thin adapters :mod:`symrot.backends.jax_backend` and :mod:`symrot.backends.torch_backend` only
choose the framework's prelude.  Unlike the NumPy module, which evaluates each branch on its own
lanes, every ``Branch`` here is evaluated on all lanes and selected with ``where``, each side on
*safe* arguments (the "double where"): the Horner polynomial sees t = 0 where the closed form
applies, the closed form sees the branch's own switch (``safe_phi`` and the t at it) where the
polynomial applies, so that neither the value nor any derivative of the unused side is NaN or
infinite.  Shapes never depend on data, nothing is synchronized with the host, and the Newton
angle has a fixed iteration count whose derivative comes from the implicit function theorem
(dφ/ds = 1/p′(φ)), not from differentiating through the iterations.

The switch of every branch is ``Branch.threshold`` (the C backend's, with its longer polynomial):
both sides are evaluated anyway, so the polynomial costs next to nothing, and it keeps the closed
form away from small φ, where the derivatives of its cancelling terms lose digits (R″ at φ = 1e-3
was 1200 ulp off with NumPy's smaller switch).  The closed form's safe arguments are its values at
that switch (``safe_phi``), where it is accurate and finite.
"""

from __future__ import annotations

import math
import re
from pathlib import Path
from typing import Any

import mpmath
import sympy as sp

from symrot.backends.numpy_backend import (
    SUFFIX,
    angle_low_helpers,
    complement_low,
    newton_low_lines,
    newton_residual_lines,
    newton_step_lines,
    print_expression,
    uses_phi,
)
from symrot.backends.runtime import runtime_text
from symrot.backends.series_tables import SeriesTables
from symrot.backends.subexpressions import alias_repeated, common_subexpressions
from symrot.backends.templating import render
from symrot.core.atomic import write_atomic
from symrot.core.parsing import PHI
from symrot.plan.algebraic import D, S, X
from symrot.plan.builder import evaluation_plan
from symrot.plan.forms import half_angle
from symrot.plan.ir import Algebraic, Branch, ClosedAngle, Constant, EvaluationPlan, NewtonAngle
from symrot.plan.newton_start import FarStart
from symrot.plan.quaternion import E0, ROTATION_TOLERANCE_POWER, QuaternionScale

FRAMEWORKS = ("jax", "torch")

# NumPy names of the printed functions → the module's own (defined per framework in the prelude)
_FUNCTIONS = {
    "sin": "_xp.sin", "cos": "_xp.cos", "tan": "_xp.tan", "sqrt": "_sqrt", "exp": "_xp.exp",
    "log": "_xp.log", "sinh": "_xp.sinh", "cosh": "_xp.cosh", "tanh": "_xp.tanh",
    "arcsin": "_xp.asin", "arccos": "_xp.acos", "arctan": "_xp.atan", "arcsinh": "_xp.asinh",
    "arccosh": "_xp.acosh", "arctanh": "_xp.atanh", "log1p": "_xp.log1p", "expm1": "_xp.expm1",
    "arctan2": "_atan2", "cbrt": "_cbrt", "sign": "_xp.sign",
}

SIN_HALF = sp.Symbol("sin_half")
COS_HALF = sp.Symbol("cos_half")


class UnsupportedExpression(ValueError):
    """A plan expression uses a function the array backends cannot print."""


def _numeric_constants(expr: sp.Expr) -> sp.Expr:
    """Every constant subexpression (sqrt(2), pi, …) as a 20-digit float: the printed code applies
    framework functions only to arrays (torch.sqrt(2) is an error)."""
    def is_constant(e: Any) -> bool:
        return bool(isinstance(e, sp.Expr) and not e.is_Rational and not e.free_symbols and e.is_number)
    return expr.replace(is_constant, lambda e: sp.Float(sp.N(e, 20), 20))


def print_array(expr: sp.Expr) -> str:
    """``expr`` as code for the array module: NumPy's printing with framework-neutral names."""
    text = print_expression(_numeric_constants(expr))

    def rename(match: re.Match[str]) -> str:
        name = match.group(1)
        if name not in _FUNCTIONS:
            raise UnsupportedExpression(f"numpy.{name} has no JAX/PyTorch counterpart here")
        return _FUNCTIONS[name]

    return re.sub(r"numpy\.(\w+)", rename, text)


def _literal(value: Any) -> str:
    return repr(float(value))


def _mp_float(expression: Any) -> str:
    """A constant computed with mpmath (deterministic on every machine, unlike libm)."""
    with mpmath.workdps(40):
        return repr(float(expression))


def branch_lines(branch: Branch, variable: str, complement: sp.Rational | None,
                 half_angles: bool = False, corrected: bool = False,
                 tables: SeriesTables | None = None, owner: str = "") -> list[str]:
    """Statements returning the Branch value from ``variable`` (t) and the state, branch-free.

    Polynomial below ``branch.threshold`` on t (t replaced by 0 above it), closed form above it on
    the state with the switch's own values substituted below it (double where). ``corrected``: sin φ
    and cos φ through the half angles, which carry λ (``EvaluationPlan.angle_correction``)."""
    switch, horner = branch.threshold, branch.horner
    threshold = switch
    lines = [f"small = {variable} < {switch!r}"]
    if len(horner) > 1:
        lines.append(f"t = _where(small, {variable}, 0.0)")
    if tables is not None and len(horner) > 1:  # the coefficients from the module's tuple
        table = tables.reference(owner, [_literal(c) for c in horner])
        lines.append(f"series = _horner({table}, {len(horner)}, t, {variable})")
    else:
        lines.append(f"series = {_literal(horner[-1])} + 0.0 * {variable}")
        for c in reversed(horner[:-1]):
            lines.append(f"series = {_literal(c)} + t * series" if c != 0 else "series = t * series")
    closed = half_angle(branch.closed) if corrected else branch.closed
    if half_angles:
        closed = closed.xreplace({sp.sin(PHI / 2): SIN_HALF, sp.cos(PHI / 2): COS_HALF})
    safe_phi = mpmath.mpf(branch.safe_phi)
    safe = {PHI: _literal(safe_phi), S: _mp_float(mpmath.sqrt(threshold)), X: _literal(threshold),
            SIN_HALF: _mp_float(mpmath.sin(safe_phi / 2)), COS_HALF: _mp_float(mpmath.cos(safe_phi / 2))}
    if complement is not None:
        safe[D] = _mp_float(mpmath.mpf(sp.Float(complement, 40)._to_mpmath(140)) - threshold)
    names = {PHI: "phi", S: "s", X: "x", D: "d", SIN_HALF: "sin_half", COS_HALF: "cos_half"}
    if variable != "x" and closed.has(X, S, D):
        raise UnsupportedExpression(f"a branch in {variable} has a closed form in x: {closed}")
    for symbol, value in safe.items():
        if closed.has(symbol):
            lines.append(f"{names[symbol]} = _where(small, {value}, {names[symbol]})")
    closed = closed.subs(PHI, sp.Symbol("phi"))
    replacements, (reduced,) = common_subexpressions([closed], "w")
    for symbol, value in replacements:
        lines.append(f"{symbol} = {print_array(value)}")
    lines.append(f"closed = {print_array(reduced)}")
    lines.append("return _where(small, series, closed)")
    return lines


def newton_lines(angle: NewtonAngle, suffix: str, tables: SeriesTables) -> list[str]:
    """The fixed-count safeguarded Newton iteration φ(s) (its derivative is the module's), from
    the start's and the far series' coefficients in the module's tuples."""
    ratio = f"_ratio_{suffix}(phi * phi, phi)"
    far = angle.far
    start = tables.reference("angle_start", [_literal(c) for c in angle.start])
    chebyshev = tables.reference("angle_far", [_literal(c) for c in far.chebyshev])
    start_lines = [f"start = _horner({start}, {len(angle.start)}, s2, s)"]
    far_lines = [f"v = {_far_variable(far)}", "y = 2.0 * v - 1.0", f"far = _clenshaw({chebyshev}, y)"]
    return [
        "s2 = s * s",
        *start_lines,
        *far_lines,
        f"phi = _where(s < {far.switch!r}, s * start, far)",
        f"phi = _xp.clip(phi, 0.0, {min(angle.phi_max, angle.fold_top)!r})",
        "low = 0.0 * s",
        f"high = low + {angle.phi_max!r}",
        f"for _ in range({angle.iterations}):",
        *("    " + line for line in newton_residual_lines(angle, ratio, _literal, "_where")),
        "    high = _where(residual > 0, phi, high)",
        "    low = _where(residual <= 0, phi, low)",
        f"    slope = _slope_{suffix}(phi * phi, phi)",
        "    safe = slope > 0",
        *newton_step_lines(angle, "_where", "_xp", print_array),
        "    phi = _where(inside, step, 0.5 * (low + high))",
        *([f"return _where(phi > {angle.fold_top!r}, {angle.fold_top!r}, phi)  # NewtonAngle.fold_top"]
          if math.isfinite(angle.fold_top) else ["return phi"]),
    ]


def angle_low_lines(angle: NewtonAngle, suffix: str) -> list[str]:
    """λ ≈ φ* − φ, one more Newton correction of the iterate φ where p grows fast enough for it to
    help (0 elsewhere); see ``EvaluationPlan.angle_correction``."""
    return [*newton_residual_lines(angle, f"_ratio_{suffix}(phi * phi, phi)", _literal, "_where"),
            f"slope = _slope_{suffix}(phi * phi, phi)", *newton_low_lines(angle, "_where")]


def _far_variable(far: FarStart) -> str:
    if far.kind == "fold":
        inner = f"_xp.clip(1.0 - s / {far.scale!r}, 0.0, None)"
        root = {2: f"_sqrt({inner})", 3: f"_cbrt({inner})"}.get(
            far.order, f"{inner} ** {1 / far.order!r}")
        return f"1.0 - {root}"
    if far.kind == "linear":
        return f"_xp.clip(s / {far.scale!r}, None, 1.0)"
    return f"s / (s + {far.scale!r})"


def _coefficient_lines(coefficient: Any, suffix: str, complement: sp.Rational | None,
                       corrected: bool, tables: SeriesTables, owner: str) -> list[str]:
    if isinstance(coefficient, Constant):
        return [f"return _xp.full_like(x, {_literal(coefficient.value)})"]
    if isinstance(coefficient, Algebraic):
        expression = coefficient.expression.subs(X, sp.Symbol("x"))
        # float32: float64 intermediates where the framework has them ((x + 16)**4 overflows)
        body = ["x = _wide(x)"] if suffix == "32" else []
        if expression.has(D) and suffix == "32":
            body.append("d = _wide(d)")
        value = print_array(expression)
        if not expression.has(X):
            value = f"({value}) + 0.0 * x"
        body.append(f"return _narrow({value}, s)" if suffix == "32" else f"return {value}")
        return body
    return branch_lines(coefficient, "x", complement, half_angles=True, corrected=corrected,
                        tables=tables, owner=owner)


def _scale_lines(scale: QuaternionScale, suffix: str, tables: SeriesTables) -> list[str]:
    """σ(e₀, |e|) with p = σ e on the hemisphere e₀ ≥ 0 (see symrot.plan.quaternion)."""
    if scale.algebraic is not None:
        expression = scale.algebraic.subs(E0, sp.Symbol("e0"))
        lines = ["e0 = _wide(e0)"] if suffix == "32" else []
        value = f"({print_array(expression)}) + 0.0 * e0"
        return [*lines, f"return _narrow({value}, e_norm)" if suffix == "32" else f"return {value}"]
    assert isinstance(scale.branch, Branch)
    lines = branch_lines(scale.branch, "t", None, tables=tables, owner="scale")
    if suffix == "64":
        return ["phi = 2.0 * _atan2(e_norm, e0)", "t = phi * phi", *lines]
    # float32: φ and σ wide, rounded once (as the NumPy backend's _scale_lines)
    assert lines[-1].startswith("return ")
    return ["phi = 2.0 * _atan2(_wide(e_norm), _wide(e0))", "t = phi * phi", *lines[:-1],
            f"return _narrow({lines[-1].removeprefix('return ')}, e0)"]


def module_context(plan: EvaluationPlan, framework: str) -> dict[str, Any]:
    if framework not in FRAMEWORKS:
        raise ValueError(f"unknown framework {framework!r}")
    functions: list[dict[str, Any]] = []
    newton: list[str] = []
    closed_angles: dict[str, list[str]] = {}
    tables = SeriesTables()
    for label, precision in plan.precisions.items():
        suffix = SUFFIX[label]
        for name, coefficient in precision.coefficients.items():
            functions.append({"name": f"_{name}_{suffix}", "args": "x, phi, s, d, sin_half, cos_half",
                              "body": _coefficient_lines(coefficient, suffix, plan.complement,
                                                         label in plan.angle_correction(), tables, name)})
        angle = precision.angle
        if isinstance(angle, NewtonAngle):
            for helper, branch in (("_ratio", angle.ratio), ("_slope", angle.slope)):
                functions.append({"name": f"{helper}_{suffix}", "args": "t, phi",
                                  "body": branch_lines(branch, "t", None, tables=tables, owner=helper[1:])})
            functions.append({"name": f"_newton_{suffix}", "args": "s",
                              "body": newton_lines(angle, suffix, tables)})
            if label in plan.angle_correction().values():
                functions.append({"name": f"_angle_low_{suffix}", "args": "s, phi",
                                  "body": angle_low_lines(angle, suffix)})
            newton.append(suffix)
        else:
            assert isinstance(angle, ClosedAngle)
            expression = angle.expression.subs(S, sp.Symbol("s"))
            closed_angles[suffix] = [f"return {print_array(expression)} + 0.0 * s"]
            if label in plan.angle_correction().values():  # a closed angle serving float32
                functions.append({"name": f"_angle_low_{suffix}", "args": "s, phi",
                                  "body": [f"return _angle_{suffix}(s, None) - phi"]})
        functions.append({"name": f"_scale_{suffix}", "args": "e0, e_norm",
                          "body": _scale_lines(precision.quaternion_scale, suffix, tables)})
    squared, inclusive = plan.boundary(53)
    finite_p_max = math.isfinite(plan.p_max)
    return {"framework": framework, "runtime": runtime_text("array_runtime"),
            "framework_runtime": runtime_text(f"{framework}_runtime"), "name": plan.name,
            "p_text": str(plan.p), "functions": alias_repeated(functions), "series_tables": tables.context(),
            "newton": newton, "closed_angles": closed_angles,
            "angle_low": angle_low_helpers(plan),
            "names": list(plan.precisions["float64"].coefficients),
            "across": repr(tuple(sorted(plan.across_tensors()))),
            "e0_min": repr(plan.e0_min) if plan.e0_min is not None else None,
            "p_max": repr(plan.p_max) if finite_p_max else None, "phi_max": repr(plan.phi_max),
            "complement": str(plan.complement) if plan.complement is not None else None,
            "complement_low": complement_low(plan),
            "p_max_squared": repr(squared) if math.isfinite(squared) else "math.inf",
            "p_max_squared_finite": math.isfinite(squared),
            "inclusive": inclusive,
            "x_limit": {SUFFIX[label]: repr(precision.x_limit)
                        for label, precision in plan.precisions.items()},
            "x_limit_power": {SUFFIX[label]: math.frexp(precision.x_limit)[1] - 1
                              for label, precision in plan.precisions.items()},
            "rotation_tolerance_power": {SUFFIX[label]: ROTATION_TOLERANCE_POWER[label]
                                         for label in plan.precisions},
            "uses_phi": {SUFFIX[label]: {n: uses_phi(c) for n, c in precision.coefficients.items()}
                         for label, precision in plan.precisions.items()}}


def module_source(plan: EvaluationPlan, framework: str) -> str:
    source = render("array_module.py.j2", **module_context(plan, framework))
    if any(len(line) > 110 for line in source.splitlines()):
        source = "# ruff: noqa: E501  (printed closed forms exceed the line length)\n" + source
    return source


def emit_framework(derivation: Any, name: str, out: Path, framework: str) -> list[Path]:
    """Write ``out/NAME.py`` for ``framework``; return the written paths."""
    out.mkdir(parents=True, exist_ok=True)
    path = out / f"{name}.py"
    write_atomic(path, module_source(evaluation_plan(derivation, name), framework))
    return [path]
