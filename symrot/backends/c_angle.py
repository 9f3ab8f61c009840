"""The angle φ of the C functions of one plan in one precision: :class:`AngleWriter`.

* φ from s = |p|: the plan's closed inverse, or its safeguarded Newton iteration (a helper function
  with the plan's fixed iteration count, bracket and Taylor-safe ratio and slope branches, started
  from the reverted series or the far-field Chebyshev start of :mod:`symrot.plan.newton_start`);
* λ, the Newton angle below φ's last bit, and λ/2 for the half-angle sine and cosine
  (``EvaluationPlan.angle_correction``);
* ``angle`` needs |p| itself, accurately down to the smallest subnormal: below x = 2⁻⁶⁰⁰ (2⁻¹⁰⁰
  in float) the norm is computed on p scaled by an exact power of two (:meth:`AngleWriter.norm`).

The coefficients and public functions built on it are :mod:`symrot.backends.c_writer`'s.
"""

from __future__ import annotations

import math
from functools import cached_property
from typing import Any

import sympy as sp

from symrot.backends.c_functions import P
from symrot.backends.c_printer import Precision, horner
from symrot.backends.c_statements import (
    HALF_LOW,
    PHI_SYMBOL,
    PLAN_LABEL,
    S_SYMBOL,
    T_SYMBOL,
    TINY_X,
    X_SYMBOL,
    PlanWriter,
    Statement,
    ops_of,
)
from symrot.backends.subexpressions import common_subexpressions
from symrot.core.parsing import PHI
from symrot.plan.algebraic import S
from symrot.plan.forms import half_angle
from symrot.plan.ir import (
    ANGLE_CORRECTION_GROWTH,
    ANGLE_CORRECTION_LIMIT,
    Branch,
    ClosedAngle,
    NewtonAngle,
)
from symrot.plan.newton_start import CHANGE, EDGE_STEP, FarStart, edge_floor, edge_step


class AngleWriter(PlanWriter):
    """The φ and λ helpers of one plan in one precision, and |p|."""

    # -- φ ---------------------------------------------------------------------------------------
    def branch_value(self, branch: Branch, variable: sp.Symbol, target: str) -> Statement:
        """if (t < threshold) target = Horner(t) else target = closed(phi) (phi > 0 there)."""
        closed = branch.closed.subs(PHI, PHI_SYMBOL)
        replacements, (reduced,) = common_subexpressions([closed], f"{target}_w")
        otherwise = [self.let(str(symbol), value) for symbol, value in replacements]
        otherwise.append(self.set(target, reduced))
        return {"kind": "if", "condition": f"{variable} < {self.printer.literal(branch.threshold)}",
                "then": [self.set(target, horner(branch.horner, variable))], "otherwise": otherwise}

    def angle_function(self) -> dict[str, Any]:
        """The helper φ(s), s = |p| ≥ 0: the closed inverse or the safeguarded Newton iteration."""
        angle = self.precision_plan.angle
        extra = f", {self.ctype} d" if self.plan.complement is not None else ""
        signature = f"{self.ctype} {self.angle_helper}({self.ctype} s{extra})"
        if isinstance(angle, ClosedAngle):
            expression = angle.expression.subs(S, S_SYMBOL)
            statements: list[Statement] = [{"kind": "return", "value": self.c(expression),
                                            "ops": sp.count_ops(expression)}]
            note = f"phi = {sp.sstr(angle.expression)} (closed inverse of p(phi))"
        else:
            statements = self.newton(angle)
            note = (f"phi by {angle.iterations} safeguarded Newton steps on phi*g(phi^2) = s, residual "
                    f"(phi*g(0) - s) + phi*(g - g(0)), from the "
                    f"reverted series, bracket [0, {angle.phi_max:.17g}]")
        return {"c_name": self.angle_helper, "summary": "internal: phi from s = |p|", "equation": "11",
                "notes": [note], "ops": ops_of(statements), "signature": signature,
                "statements": statements, "batch_signature": None, "output": None}

    def newton(self, angle: NewtonAngle) -> list[Statement]:
        s2 = sp.Symbol("s2", real=True)
        start = S_SYMBOL * horner(angle.start, s2)
        body: list[Statement] = [
            self.let("t", PHI_SYMBOL**2),
            {"kind": "declare", "type": self.ctype,
             "names": ["ratio", "slope", "tail", "residual", "step", *(["value"] if angle.reciprocal else []),
                       *(["change"] if angle.edge else [])]},
            self.branch_value(angle.ratio, T_SYMBOL, "ratio"),
            self.branch_value(angle.slope, T_SYMBOL, "slope"),
            *self.residual(angle, declared=True),
            {"kind": "if", "condition": "residual > 0", "then": [self.set("high", "phi")],
             "otherwise": [self.set("low", "phi")]},
            *self.newton_step(angle),
        ]
        phi_max = self.printer.literal(angle.phi_max)
        start_top = self.printer.literal(min(angle.phi_max, angle.fold_top))  # NewtonAngle.fold_top
        far = angle.far
        y, b1, b2 = (sp.Symbol(n, real=True) for n in ("y", "b1", "b2"))
        degree = len(far.chebyshev) - 1
        literals = ", ".join(self.printer.literal(sp.Float(c, 17)) for c in far.chebyshev)
        # Σ c_j T_j(y) by Clenshaw's recurrence (the monomial form is unstable in float)
        clenshaw: list[Statement] = [
            {"kind": "let", "type": self.ctype, "name": f"far_chebyshev[{degree + 1}]",
             "value": f"{{{literals}}}"},
            {"kind": "declare", "type": self.ctype, "names": ["b0", "b1 = 0", "b2 = 0"]},
            {"kind": "declare", "type": "int", "names": ["j"]},
            {"kind": "loop", "header": f"j = {degree}; j >= 1; --j", "times": degree,
             "body": [self.set("b0", sp.Symbol("far_chebyshev[j]", real=True) + 2 * y * b1 - b2),
                      self.set("b2", "b1"), self.set("b1", "b0")]},
        ]
        far_value = sp.Float(far.chebyshev[0], 17) + y * b1 - b2
        return [
            self.let("s2", S_SYMBOL**2),
            {"kind": "let", "type": self.ctype, "name": "v", "value": self.far_variable(far), "ops": 4},
            self.let("y", 2 * sp.Symbol("v", real=True) - 1),
            *clenshaw,
            {"kind": "declare", "type": self.ctype,
             "names": [f"phi = s < {self.printer.literal(far.switch)} ? {self.c(start)} : "
                       f"{self.c(far_value)}",
                       "low = 0", f"high = {phi_max}"],
             "ops": 1 + max(sp.count_ops(start), sp.count_ops(far_value))},
            {"kind": "declare", "type": "int", "names": ["k"]},
            *([{"kind": "let", "type": self.ctype, "name": "s_or_one", "value": "s > 0 ? s : 1", "ops": 1}]
              if angle.reciprocal else []),
            {"kind": "if", "condition": f"phi > {start_top}", "then": [self.set("phi", start_top)],
             "otherwise": []},
            {"kind": "loop", "header": f"k = 0; k < {angle.iterations}; ++k", "body": body,
             "times": angle.iterations},
            *([{"kind": "if", "condition": f"phi > {self.printer.literal(angle.fold_top)}", "otherwise": [],
                "then": [self.set("phi", self.printer.literal(angle.fold_top))]}]  # NewtonAngle.fold_top
              if math.isfinite(angle.fold_top) else []),
            {"kind": "return", "value": "phi"},
        ]

    def residual(self, angle: NewtonAngle, declared: bool) -> list[Statement]:
        """tail = φ·(g − g(0)), the residual (φ·g(0) − s) + tail where the tail's polynomial applies
        (the difference first, exact once φ is within a factor 2 of s) and φ·(g(0) + ratio) − s =
        φ·g − s above, and value = p(φ) for the reciprocal step (:class:`symrot.plan.ir.NewtonAngle`)."""
        head = "phi" if angle.leading == 1 else f"phi*{self.c(angle.leading)}"
        whole = "1" if angle.leading == 1 else self.c(angle.leading)
        switch = self.printer.literal(angle.split_below)
        values = [("tail", "phi*ratio", 1),
                  ("residual", f"t < {switch} ? ({head} - s) + tail : phi*({whole} + ratio) - s", 6),
                  *([("value", f"{head} + tail", 2)] if angle.reciprocal else [])]
        if declared:
            return [self.set(name, value, ops=ops) for name, value, ops in values]
        return [{"kind": "let", "type": self.ctype, "name": name, "value": value, "ops": ops}
                for name, value, ops in values]

    def newton_step(self, angle: NewtonAngle) -> list[Statement]:
        """The step of the safeguarded iteration and its acceptance: Newton in φ (on 1/p if
        reciprocal) or, with an edge exponent k, in w = (φ_max − φ)^k
        (:attr:`symrot.plan.ir.NewtonAngle.edge`); a rejected step bisects the bracket."""
        bisect = {"kind": "if", "condition": "", "then": [self.set("phi", "step")],
                  "otherwise": [self.set("phi", (sp.Symbol("low") + sp.Symbol("high")) / 2)]}
        if angle.edge is None:
            step = (self.set("step", "phi - residual / slope * (value / s_or_one)", ops=4) if angle.reciprocal
                    else self.set("step", PHI_SYMBOL - sp.Symbol("residual") / sp.Symbol("slope")))
            return [step, {**bisect,
                           "condition": "slope > 0 && isfinite(slope) && step >= low && step <= high"}]
        top = self.printer.literal(angle.phi_max)
        floor = self.printer.literal(sp.Float(edge_floor(angle.edge), 17))
        step = edge_step(angle.edge).xreplace({PHI: PHI_SYMBOL, EDGE_STEP: sp.Symbol("u", real=True),
                                               CHANGE: sp.Symbol("change", real=True)})
        return [
            self.set("change", "residual / slope", ops=1),
            {"kind": "let", "type": self.ctype, "name": "delta", "value": f"{top} - phi", "ops": 1},
            {"kind": "declare", "type": self.ctype, "ops": 4,  # not const: raised below
             "names": [f"u = delta > 0 ? {self.c(angle.edge)}*change/delta : 0"]},
            {"kind": "if", "condition": f"u < {floor}", "otherwise": [],  # raised u: c = u δ/k
             "then": [self.set("u", floor), self.set("change", f"u*delta/({self.c(angle.edge)})", ops=2)]},
            self.set("step", step),
            {**bisect,
             "condition": "slope > 0 && isfinite(slope) && delta > 0 && step >= low && step <= high"},
        ]

    # -- λ, the Newton angle below φ's last bit ---------------------------------------------------
    @cached_property
    def angle_correction(self) -> dict[str, str]:
        """``EvaluationPlan.angle_correction`` without a float closed angle's λ: that λ is float64's
        angle minus φ, and a header's float functions with closed angles stay free of double (a
        single-precision FPU emulates double; the named headers are checked for it)."""
        return {label: source for label, source in self.plan.angle_correction().items()
                if not (label == "float32" and isinstance(self.plan.precisions[label].angle, ClosedAngle))}

    @property
    def corrects_angle(self) -> bool:
        """Whether this precision's half-angle sine and cosine take λ."""
        return PLAN_LABEL[self.precision] in self.angle_correction

    def half_angle_corrected(self, expr: sp.Expr) -> sp.Expr:
        """``expr`` with sin(φ/2) → sin(φ/2) + (λ/2) cos(φ/2) and cos(φ/2) → cos(φ/2) − (λ/2) sin(φ/2)
        where the angle is a Newton iteration (see ``EvaluationPlan.angle_correction``), sin φ and
        cos φ written through them first (:func:`symrot.plan.forms.half_angle`)."""
        if not self.corrects_angle:
            return expr
        sine, cosine = sp.sin(PHI_SYMBOL / 2), sp.cos(PHI_SYMBOL / 2)
        halves = half_angle(expr.xreplace({PHI_SYMBOL: PHI})).xreplace({PHI: PHI_SYMBOL})
        return halves.xreplace({sine: sine + HALF_LOW * cosine, cosine: cosine - HALF_LOW * sine})

    def low_helper(self, precision: Precision) -> str:
        return f"symrot_{self.header}__phi_low{'' if precision == 'double' else '_f'}"

    @property
    def half_low_helper(self) -> str:
        return f"symrot_{self.header}__half_low{self.suffix}"

    def half_low_call(self, s_text: str, phi_text: str) -> str:
        return f"{self.half_low_helper}({s_text}, {phi_text})"

    @cached_property
    def angle_low_functions(self) -> list[dict[str, Any]]:
        """The helpers λ(s, φ) (one more Newton correction of φ; only in the precision whose ratio
        and slope serve, see ``EvaluationPlan.angle_correction``) and λ/2 for this precision, 0
        unless |λ| ≤ ``EvaluationPlan.angle_correction_bound`` φ."""
        correction = self.angle_correction
        label = PLAN_LABEL[self.precision]
        if label not in correction:
            return []
        t = self.ctype
        functions = []
        angle = self.precision_plan.angle
        if correction[label] == label and isinstance(angle, NewtonAngle):
            step = ("-residual / slope * (value / (s > 0 ? s : 1))" if angle.reciprocal
                    else "-residual / slope")
            growth = self.printer.literal(sp.Float(ANGLE_CORRECTION_GROWTH))
            signature = f"{t} {self.low_helper(self.precision)}({t} s, {t} phi)"
            statements: list[Statement] = [
                self.let("t", PHI_SYMBOL**2),
                {"kind": "declare", "type": t, "names": ["ratio", "slope"]},
                self.branch_value(angle.ratio, T_SYMBOL, "ratio"),
                self.branch_value(angle.slope, T_SYMBOL, "slope"),
                *self.residual(angle, declared=False),
                {"kind": "return", "value": f"phi * slope > {growth} * s ? {step} : 0", "ops": 7},
            ]
            functions.append({
                "c_name": self.low_helper(self.precision), "equation": "11",
                "summary": "internal: lambda, the Newton angle below the last bit of phi",
                "notes": ["One more Newton correction of phi where phi p'/p exceeds "
                           f"{ANGLE_CORRECTION_GROWTH:g} (0 elsewhere)."],
                "ops": ops_of(statements), "signature": signature,
                "statements": statements, "batch_signature": None, "output": None})
        source: Precision = "double" if correction[label] == "float64" else "float"
        bound = self.printer.literal(sp.Float(self.plan.angle_correction_bound(label), 17))
        f = "" if self.precision == "double" else "f"
        half = self.printer.literal(sp.Float(0.5))
        statements = [
            {"kind": "let", "type": t, "name": "correction", "ops": 0,
             "value": f"({t}){self.low_helper(source)}((double)s, (double)phi)" if source != self.precision
             else f"{self.low_helper(source)}(s, phi)"},
            {"kind": "return", "ops": 4,
             "value": f"fabs{f}(correction) <= {bound} * phi ? {half} * correction : 0"},
        ]
        functions.append({
            "c_name": self.half_low_helper, "equation": "11",
            "summary": "internal: lambda/2 for sin(phi/2) and cos(phi/2)",
            "notes": ["Half of the Newton angle below the last bit of phi, 0 unless within "
                      f"{ANGLE_CORRECTION_LIMIT} units of",
                      "roundoff: sin(phi/2) + cos(phi/2) lambda/2 is accurate next to 2 pi."],
            "ops": ops_of(statements), "signature": f"{t} {self.half_low_helper}({t} s, {t} phi)",
            "statements": statements, "batch_signature": None, "output": None})
        return functions

    def far_variable(self, far: FarStart) -> str:
        """v(s) of the far-field Newton start (symrot.plan.newton_start), as C."""
        f = "" if self.precision == "double" else "f"
        ratio = f"s / {self.printer.literal(far.scale)}"
        if far.kind == "fold":
            inner = f"fmax{f}(1 - {ratio}, 0)"
            root = {2: f"sqrt{f}({inner})", 3: f"cbrt{f}({inner})"}.get(
                far.order, f"pow{f}({inner}, {self.printer.literal(sp.Rational(1, far.order))})")
            return f"1 - {root}"
        if far.kind == "linear":
            return f"fmin{f}({ratio}, 1)"
        return f"s / (s + {self.printer.literal(far.scale)})"

    def norm(self) -> list[Statement]:
        """s = |p| without underflow (x = |p|² is already computed)."""
        small, scale = TINY_X[self.precision]
        q = [sp.Symbol(f"q{i}", real=True) for i in range(3)]
        scaled = [self.let(f"q{i}", P[i] * scale) for i in range(3)]
        scaled.append(self.set("s", sp.sqrt(q[0] ** 2 + q[1] ** 2 + q[2] ** 2) / scale))
        return [{"kind": "declare", "type": self.ctype, "names": ["s"]},
                {"kind": "if", "condition": f"x < {self.printer.literal(small)}", "then": scaled,
                 "otherwise": [self.set("s", sp.sqrt(X_SYMBOL))]}]
