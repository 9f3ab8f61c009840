"""NumPy backend: prints an ``EvaluationPlan`` (``symrot.plan``) as a self-contained module.

The module (NumPy only) exposes, for p of shape (..., 3): ``angle`` (φ), ``rotation_matrix`` (R,
eq 16), ``tangent`` (H, ω = H ṗ, eq 20), ``tangent_inverse`` (H⁻¹, eq 26), ``tangent_det`` (det H,
eq 24), ``root_matrix`` (G, eq 81), ``root_tangent`` (K, eq 83), ``pdot`` (ṗ = H⁻¹ ω, eq 25) and
``omega`` (ω = H ṗ).  float32 input is evaluated with the float32 plan, anything else as float64.
Outside the validity range |p| < p_max every output is NaN.
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
import sympy as sp
from sympy.printing.numpy import NumPyPrinter

from ..parsing import PHI
from ..plan import (
    Algebraic,
    Branch,
    ClosedAngle,
    Constant,
    EvaluationPlan,
    NewtonAngle,
    S,
    X,
    evaluation_plan,
)
from .templating import render

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


def _branch_lines(branch: Branch, variable: str, phi: str) -> list[str]:
    """Statements computing ``result`` from ``variable`` (t) and ``phi`` for one Branch."""
    lines = [f"small = {variable} < {branch.threshold!r}"]
    if len(branch.horner) > 1:
        lines.append(f"t = numpy.where(small, {variable}, 0.0).astype({variable}.dtype)")
    lines.append(f"phi = numpy.where(small, {branch.safe_phi!r}, {phi}).astype({variable}.dtype)")
    lines.append(f"series = {_literal(branch.horner[-1])}")
    for c in reversed(branch.horner[:-1]):
        lines.append(f"series = {_literal(c)} + t * series" if c != 0 else "series = t * series")
    horner = "series"
    closed = branch.closed.subs(PHI, sp.Symbol("phi"))
    replacements, (reduced,) = sp.cse([closed], symbols=sp.numbered_symbols("w"))
    for symbol, value in replacements:
        lines.append(f"{symbol} = {print_expression(value)}")
    lines.append(f"closed = {print_expression(reduced)}")
    lines.append(f"return numpy.where(small, {horner}, closed)")
    return lines


def _angle_lines(angle: ClosedAngle | NewtonAngle) -> list[str]:
    if isinstance(angle, ClosedAngle):
        expression = angle.expression.subs(S, sp.Symbol("s"))
        return [f"return {print_expression(expression)} + 0.0 * s"]
    start_lines = [f"start = {_literal(angle.start[-1])}"]
    start_lines += [f"start = {_literal(c)} + s2 * start" for c in reversed(angle.start[:-1])]
    return [
        "s2 = s * s",
        *start_lines,
        f"phi = numpy.clip(s * start, 0.0, {angle.phi_max!r}).astype(s.dtype)",
        "low = numpy.zeros_like(s)",
        f"high = numpy.full_like(s, {angle.phi_max!r})",
        f"for _ in range({angle.iterations}):",
        "    residual = phi * _ratio(phi * phi) - s",
        "    high = numpy.where(residual > 0, phi, high)",
        "    low = numpy.where(residual <= 0, phi, low)",
        "    slope = _slope(phi * phi, phi)",
        "    safe = slope > 0",
        "    step = phi - residual / numpy.where(safe, slope, 1.0)",
        "    inside = safe & (step >= low) & (step <= high)",
        "    phi = numpy.where(inside, step, 0.5 * (low + high)).astype(s.dtype)",
        "return phi",
    ]


def module_context(plan: EvaluationPlan) -> dict[str, Any]:
    functions: list[dict[str, Any]] = []
    for label, precision in plan.precisions.items():
        functions.extend(module_context_functions(precision, SUFFIX[label]))
    p_max = plan.p_max
    return {"name": plan.name, "p_text": str(plan.p), "functions": functions,
            "names": list(plan.precisions["float64"].coefficients),
            "p_max": repr(p_max) if np.isfinite(p_max) else None, "phi_max": repr(plan.phi_max)}


def module_context_functions(precision: Any, suffix: str) -> list[dict[str, Any]]:
    functions = []
    for name, coefficient in precision.coefficients.items():
        if isinstance(coefficient, Constant):
            body = [f"return numpy.full_like(x, {_literal(coefficient.value)})"]
        elif isinstance(coefficient, Algebraic):
            expression = coefficient.expression.subs(X, sp.Symbol("x"))
            # float64 intermediates: powers such as (x + 16)**4 must not overflow float32
            body = ["x = x.astype(numpy.float64)" if suffix == "32" else "x = numpy.asarray(x)",
                    f"return (({print_expression(expression)}) + 0.0 * x).astype("
                    f"numpy.float{suffix})"]
        else:
            body = _branch_lines(coefficient, "x", "phi")
        functions.append({"name": f"_{name}_{suffix}", "args": "x, phi", "body": body})
    angle = precision.angle
    if isinstance(angle, NewtonAngle):
        for helper, branch in (("_ratio", angle.ratio), ("_slope", angle.slope)):
            functions.append({"name": f"{helper}_{suffix}", "args": "t, phi",
                              "body": _branch_lines(branch, "t", "phi")})
    angle_body = [line.replace("_ratio(phi * phi)", f"_ratio_{suffix}(phi * phi, phi)")
                  .replace("_slope(", f"_slope_{suffix}(") for line in _angle_lines(angle)]
    functions.append({"name": f"_angle_{suffix}", "args": "s", "body": angle_body})
    return functions


def module_source(plan: EvaluationPlan) -> str:
    source = render("numpy_module.py.j2", **module_context(plan))
    if any(len(line) > 110 for line in source.splitlines()):
        source = "# ruff: noqa: E501  (printed closed forms exceed the line length)\n" + source
    return source


def emit(derivation: Any, name: str, out: Path) -> list[Path]:
    """Write ``out/NAME.py`` for ``derivation``; return the written paths."""
    out.mkdir(parents=True, exist_ok=True)
    path = out / f"{name}.py"
    path.write_text(module_source(evaluation_plan(derivation, name)), encoding="utf-8")
    return [path]
