"""The statements of the C functions of one plan in one precision: the layer under the C backend.

:class:`FunctionWriter` turns the evaluation plan of :mod:`symrot.plan.builder` into statements (dicts that
``templates/c/header.h.j2`` prints) with :class:`~symrot.backends.c_printer.SymrotCPrinter`; the
header (:mod:`symrot.backends.c_backend`), the ``_batch`` kernels (:mod:`symrot.backends.c_batch`)
and the operations (:mod:`symrot.backends.c_operations`) build on it. How a plan becomes C:

* x = |p|² once; outside the validity range (``!(x < p_max²)``, or ``!(x < x_limit)`` (the plan's
  x_limit, at most 2^600, 2^100 in float) when p is unbounded, which also catches inf and NaN)
  every output is NaN; for the sine family also d = p_max² − x with fma-exact products and TwoSum
  (``__complement``), which the plan's expressions use instead of k² − x;
* coefficients: a :class:`~symrot.plan.ir.Constant` is folded into the output expressions, an
  :class:`~symrot.plan.ir.Algebraic` one is a single expression in x (no branch, no trig); the
  :class:`~symrot.plan.ir.Branch` ones of a function share one ``if (x < smallest threshold)``:
  below it every coefficient is its Horner polynomial, above it φ is computed once, the closed
  forms share common subexpressions (``sympy.cse``, inside that branch only, where x > 0) and a
  coefficient whose own threshold is larger still takes its polynomial (sin and cos are libm's
  here, ≈ 0.5 ulp; the ``_batch`` kernels of :mod:`symrot.backends.c_batch` use the vectorizable
  kernel of :mod:`symrot.backends.c_sincos` instead);
* φ: the plan's closed inverse, or its safeguarded Newton iteration (a helper function with the
  plan's fixed iteration count, bracket and Taylor-safe ratio and slope branches). ``angle`` needs
  |p| itself, accurately down to the smallest subnormal: below x = 2⁻⁶⁰⁰ (2⁻¹⁰⁰ in float) the
  norm is computed on p scaled by an exact power of two;
* tensors T = c0 I + c1 (p×) + c2 (p×)² entry by entry
  (:func:`~symrot.backends.c_functions.tensor_entries`), vectors as t v + c1 p×v + c2 (p·v) p with
  t = c0 − c2 |p|² (:func:`~symrot.backends.c_functions.applied_entries`).

``/* ops: N */`` is the number of operations on the longest path through the function, as
counted by ``sympy.count_ops`` (a call such as ``sin`` counts one; Newton iterations multiplied).
"""

from __future__ import annotations

import math
from functools import cached_property
from typing import Any

import sympy as sp

from symrot.backends.c_functions import (
    OUTPUT_NAMES,
    TENSOR_OF,
    VECTOR_NAMES,
    CFunction,
    P,
    across_value,
    applied_entries,
    tensor_coefficients,
    tensor_entries,
)
from symrot.backends.c_printer import MANTISSA_BITS, Precision, SymrotCPrinter, horner
from symrot.backends.subexpressions import common_subexpressions
from symrot.core.errors import NonFiniteLiteral
from symrot.core.parsing import PHI
from symrot.plan.algebraic import S, X
from symrot.plan.forms import half_angle
from symrot.plan.ir import (
    ANGLE_CORRECTION_GROWTH,
    ANGLE_CORRECTION_LIMIT,
    Algebraic,
    Branch,
    ClosedAngle,
    Constant,
    EvaluationPlan,
    NewtonAngle,
    PrecisionPlan,
)
from symrot.plan.newton_start import CHANGE, EDGE_STEP, FarStart, edge_floor, edge_step

# -- statements ------------------------------------------------------------------------------------
Statement = dict[str, Any]
TINY_X = {"double": (sp.Integer(2) ** -600, sp.Integer(2) ** 600),
          "float": (sp.Integer(2) ** -100, sp.Integer(2) ** 100)}
"""Below x = first, |p| is computed on q = p · second (an exact power of two): for every p with
|p|² < first, down to the smallest subnormal, q² is a normal number and cannot overflow."""
LARGEST = {"double": sp.Float("1.7976931348623157e308", 20), "float": sp.Float("3.4028234663852886e38", 20)}
PLAN_LABEL = {"double": "float64", "float": "float32"}
MANTISSA = {"double": 53, "float": 24}
X_SYMBOL = sp.Symbol("x", real=True)
S_SYMBOL = sp.Symbol("s", real=True)
PHI_SYMBOL = sp.Symbol("phi", real=True)
T_SYMBOL = sp.Symbol("t", real=True)
HALF_LOW = sp.Symbol("half_low", real=True)
"""λ/2, half the part of the Newton angle below φ's last bit (``EvaluationPlan.angle_correction``)."""


def ops_of(statements: list[Statement]) -> int:
    """Operations on the longest path through ``statements`` (see the module docstring)."""
    total = 0
    for statement in statements:
        total += int(statement.get("ops", 0))
        if statement["kind"] == "if":
            total += 1 + max(ops_of(statement["then"]), ops_of(statement["otherwise"]))
        elif statement["kind"] == "loop":
            total += int(statement["times"]) * ops_of(statement["body"])
    return total


class FunctionWriter:
    """Statements of the C functions of one plan in one precision."""

    def __init__(self, plan: EvaluationPlan, header: str, precision: Precision) -> None:
        self.plan = plan
        self.header = header
        self.precision = precision
        self.ctype = precision
        self.suffix = "" if precision == "double" else "_f"
        self.printer = SymrotCPrinter(precision)
        self.precision_plan: PrecisionPlan = plan.precisions[PLAN_LABEL[precision]]

    # -- small helpers ---------------------------------------------------------------------------
    @property
    def nan(self) -> str:
        """NaN of this precision: C99's ``NAN`` is a float, so double code casts it (no silent
        promotion: the header compiles cleanly with -Wdouble-promotion)."""
        return "NAN" if self.precision == "float" else "(double)NAN"

    @property
    def infinity(self) -> str:
        """+∞ of this precision (``INFINITY`` is a float in C99, cast like :attr:`nan`)."""
        return "INFINITY" if self.precision == "float" else "(double)INFINITY"

    def c(self, expr: sp.Expr) -> str:
        return str(self.printer.doprint(expr))

    def named(self, name: str, value: sp.Expr) -> str:
        """``value`` as C; a non-finite constant is refused naming the variable it was for."""
        try:
            return self.c(value)
        except NonFiniteLiteral as error:
            message = f"cannot emit {name} of {self.header} in {self.precision}: {error}"
            raise NonFiniteLiteral(message) from None

    def let(self, name: str, value: sp.Expr) -> Statement:
        return {"kind": "let", "type": self.ctype, "name": name, "value": self.named(name, value),
                "ops": sp.count_ops(value)}

    def set(self, name: str, value: sp.Expr | str, ops: int | None = None) -> Statement:
        text = value if isinstance(value, str) else self.named(name, value)
        count = ops if ops is not None else (0 if isinstance(value, str) else sp.count_ops(value))
        return {"kind": "set", "name": name, "value": text, "ops": count}

    @property
    def angle_helper(self) -> str:
        return f"symrot_{self.header}__phi{self.suffix}"

    def squared_norm(self) -> Statement:
        return self.let("x", P[0] ** 2 + P[1] ** 2 + P[2] ** 2)

    @property
    def bound(self) -> float:
        """p_max² rounded to this precision (see ``EvaluationPlan.boundary``)."""
        return self.plan.boundary(MANTISSA[self.precision])[0]

    @property
    def inside_operator(self) -> str:
        """``<=`` when the rounded p_max² lies below the exact one (x equal to it is inside), else ``<``."""
        return "<=" if self.plan.boundary(MANTISSA[self.precision])[1] else "<"

    def prologue(self) -> list[Statement]:
        """x = |p|², and d = p_max² − x (compensated) when the plan uses the fold complement."""
        statements = [self.squared_norm()]
        if self.plan.complement is not None:
            statements.append({"kind": "let", "type": self.ctype, "name": "d",
                               "value": f"{self.complement_helper}(p, x)", "ops": 20})
        return statements

    @property
    def complement_helper(self) -> str:
        return f"symrot_{self.header}__complement{self.suffix}"

    def angle_call(self, s_text: str) -> str:
        extra = ", d" if self.plan.complement is not None else ""
        return f"{self.angle_helper}({s_text}{extra})"

    def complement_function(self) -> dict[str, Any]:
        """d = p_max² − |p|²: for x ≤ p_max²/4 plainly (then x ≤ d/3, and the rounding error of x,
        at most 3 units of roundoff of x, stays below one ulp of d), else with exact products (fma)
        and error-free sums, then one rounding.

        The sums are Fast2Sum (3 operations, not TwoSum's 6): inside the range each running value
        high = p_max² − p₀² − … is at least the next square p_i² (the remaining squares and d are
        not negative), and where its rounding puts it below p_i² the two are within a factor 2, so
        high − p_i² is exact (Sterbenz) and the error term 0 is right. Every error term is then the
        exact one that TwoSum gives, and d has the same bits (tests/test_c_complement.py). Outside
        the range d is garbage, and every output is NaN by the test on x."""
        t = self.ctype
        fma = "fma" if t == "double" else "fmaf"
        assert self.plan.complement is not None
        complement = sp.Rational(self.plan.complement)  # 16/9 for (4/3) sin(3φ/4): not an integer
        high, tail = self.plan.complement_parts(MANTISSA_BITS[self.precision])
        k2 = self.printer.literal(high)  # exact in the type: the literal of p_max² rounded
        near = {"kind": "if", "condition": f"x <= {self.printer.literal(complement / 4)}",
                "then": [{"kind": "return", "value": f"{k2} - x", "ops": 1}], "otherwise": [], "ops": 0}
        low = self.printer.literal(tail) if tail != 0 else "0"
        start = {"kind": "declare", "type": t, "names": [f"high = {k2}", f"low = {low}"]}
        statements: list[Statement] = [near, start, {"kind": "declare", "type": "int", "names": ["i"]}]
        body: list[Statement] = [
            {"kind": "let", "type": t, "name": "square", "value": "p[i] * p[i]", "ops": 1},
            {"kind": "let", "type": t, "name": "error", "value": f"{fma}(p[i], p[i], -square)", "ops": 1},
            {"kind": "let", "type": t, "name": "total", "value": "high - square", "ops": 1},
            {"kind": "set", "name": "low", "value": "low + (((high - total) - square) - error)", "ops": 4},
            {"kind": "set", "name": "high", "value": "total", "ops": 0},
        ]
        statements.append({"kind": "loop", "header": "i = 0; i < 3; ++i", "body": body, "times": 3})
        statements.append({"kind": "return", "value": "high + low", "ops": 1})
        return {"c_name": self.complement_helper, "summary": "internal: d = p_max^2 - |p|^2, compensated",
                "equation": "31-32, 36", "ops": ops_of(statements),
                "notes": ["Accurate to a few ulp of d even at the fold |p| -> p_max, where x = |p|^2",
                          "rounded would leave no correct digit of p_max^2 - x (error-free products by",
                          "fma; Fast2Sum, exact here: inside the range each running p_max^2 - p_0^2 - ...",
                          "is at least the next square, or within a factor 2 of it); for x <= p_max^2/4",
                          "(x <= d/3) plainly p_max^2 - x, whose error from the rounding of x stays",
                          "below one ulp of d."],
                "signature": f"{t} {self.complement_helper}(const {t} p[3], {t} x)", "statements": statements,
                "batch_signature": None, "output": None}

    def out_of_range(self, x: str = "x") -> str:
        """The C condition (as text) on the squared norm ``x`` under which every output is NaN: the
        one validity test of every function, also applied to the results of the operations."""
        if math.isfinite(self.plan.p_max):
            return f"!({x} {self.inside_operator} {self.printer.literal(self.bound)})"
        return f"!({x} < {self.printer.literal(sp.Float(self.precision_plan.x_limit))})"

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

    # -- coefficients ----------------------------------------------------------------------------
    def coefficients(self, names: list[str]) -> tuple[list[Statement], dict[str, sp.Expr]]:
        """Statements computing ``names`` and the expression standing for each in the outputs."""
        plan = self.precision_plan.coefficients
        values: dict[str, sp.Expr] = {}
        statements: list[Statement] = []
        branches = {n: plan[n] for n in names if isinstance(plan[n], Branch)}
        for name in names:
            coefficient = plan[name]
            if isinstance(coefficient, Constant):
                values[name] = sp.sympify(coefficient.value)
            elif isinstance(coefficient, Algebraic):
                statements.append(self.let(f"c_{name}", coefficient.expression.subs(X, X_SYMBOL)))
                values[name] = sp.Symbol(f"c_{name}")
        if not branches:
            return statements, values
        for name in branches:
            values[name] = sp.Symbol(f"c_{name}")
        statements.append({"kind": "declare", "type": self.ctype, "names": [f"c_{n}" for n in branches]})
        smallest = min(b.threshold for b in branches.values())  # type: ignore[union-attr]
        below = [self.set(f"c_{n}", horner(b.horner, X_SYMBOL)) for n, b in branches.items()]  # type: ignore[union-attr]
        closed = [self.half_angle_corrected(b.closed.subs(PHI, PHI_SYMBOL))  # type: ignore[union-attr]
                  for b in branches.values()]
        replacements, reduced = common_subexpressions(closed, "w")
        above: list[Statement] = []
        if any(b.closed.has(PHI) for b in branches.values()):  # type: ignore[union-attr]
            above.append({"kind": "let", "type": self.ctype, "name": "phi",
                          "value": self.angle_call(self.c(sp.sqrt(X_SYMBOL))),
                          "ops": 2 + ops_of(self.angle_function()["statements"])})
        corrected = any(c.has(HALF_LOW) for c in closed)
        if corrected or any(b.closed.has(S) for b in branches.values()):  # type: ignore[union-attr]
            above.append(self.let("s", sp.sqrt(X_SYMBOL)))
        if corrected:
            above.append({"kind": "let", "type": self.ctype, "name": "half_low",
                          "value": self.half_low_call("s", "phi"),
                          "ops": sum(ops_of(f["statements"]) for f in self.angle_low_functions)})
        above += [self.let(str(symbol), value) for symbol, value in replacements]
        for (name, branch), value in zip(branches.items(), reduced, strict=True):
            assert isinstance(branch, Branch)
            if branch.threshold > smallest:
                polynomial = horner(branch.horner, X_SYMBOL)
                text = (f"x < {self.printer.literal(branch.threshold)} ? {self.c(polynomial)} : "
                        f"{self.c(value)}")
                above.append(self.set(f"c_{name}", text,
                                      1 + max(sp.count_ops(polynomial), sp.count_ops(value))))
            else:
                above.append(self.set(f"c_{name}", value))
        statements.append({"kind": "if", "condition": f"x < {self.printer.literal(smallest)}",
                           "then": below, "otherwise": above})
        return statements, values

    # -- the public functions --------------------------------------------------------------------
    def validity_notes(self) -> list[str]:
        plan = self.plan
        if math.isfinite(plan.p_max):
            return [f"Valid for |p| < {plan.p_max:.17g} (|phi| < {plan.phi_max:.17g}); outside it, and for "
                    "non-finite p, every output is NaN."]
        bound = f"2^{math.frexp(self.precision_plan.x_limit)[1] - 1}"
        return [f"Valid for every p with |p|^2 < {bound} (|phi| < {plan.phi_max:.17g}), the largest power",
                "of two up to which every printed form was checked against 50+ digits; otherwise, and for",
                "non-finite p, every output is NaN."]

    def coefficient_notes(self, names: list[str]) -> list[str]:
        notes = []
        for name in names:
            c = self.precision_plan.coefficients[name]
            if isinstance(c, Constant):
                notes.append(f"{name} = {sp.sstr(c.value)} (constant)")
            elif isinstance(c, Algebraic):
                notes.append(f"{name} = {sp.sstr(c.expression)} (algebraic in x)")
            else:
                notes.append(f"{name}: Horner degree {len(c.horner) - 1} in x below x = {c.threshold:.6g}, "
                             f"else {sp.sstr(c.closed)}")
        return notes

    def function(self, spec: CFunction) -> dict[str, Any]:
        name = f"symrot_{self.header}_{spec.name}{self.suffix}"
        t = self.ctype
        statements: list[Statement] = self.prologue()
        notes = self.validity_notes()
        if spec.kind == "scalar":
            signature = f"{t} {name}(const {t} p[3])"
            statements.append({"kind": "if", "condition": self.out_of_range(),
                               "then": [{"kind": "return", "value": self.nan}], "otherwise": []})
            if spec.name == "angle":
                statements += self.norm()
                statements.append({"kind": "return", "value": self.angle_call("s"),
                                   "ops": ops_of(self.angle_function()["statements"])})
                notes.append(self.angle_function()["notes"][0])
            else:
                body, values = self.coefficients(["det_H"])
                statements += body
                statements.append({"kind": "return", "value": self.c(values["det_H"]), "ops": 0})
                notes += self.coefficient_notes(["det_H"])
            return self.context(spec, name, signature, statements, notes, None, None)
        tensor = TENSOR_OF[spec.name]
        across = self.plan.across_tensors()
        names = tensor_coefficients(tensor, across)
        body, values = self.coefficients(names)
        first, b, c = (values[n] for n in names)
        t_value = across_value(tensor, across, first, c, X_SYMBOL)
        if t_value != first:  # t = c0 - c2 x once, not in each diagonal entry
            body.append(self.let("t", t_value))
            t_value = sp.Symbol("t", real=True)
        if spec.kind == "matrix":
            output = OUTPUT_NAMES[spec.name]
            signature = f"void {name}(const {t} p[3], {t} {output}[9])"
            nan = [self.set(f"{output}[{i}]", self.nan) for i in range(9)] + [{"kind": "return", "value": ""}]
            outputs = [self.set(f"{output}[{i}]", entry)
                       for i, entry in enumerate(tensor_entries(t_value, b, c))]
            batch = f"void {name}_batch(size_t n, const {t} *p, {t} *{output})"
        else:
            given, output = VECTOR_NAMES[spec.name]
            signature = f"void {name}(const {t} p[3], const {t} {given}[3], {t} {output}[3])"
            nan = [self.set(f"{output}[{i}]", self.nan) for i in range(3)] + [{"kind": "return", "value": ""}]
            v = tuple(sp.Symbol(f"{given}[{i}]", real=True) for i in range(3))
            w = tuple(sp.Symbol(f"w{i}", real=True) for i in range(3))
            dot = sp.Symbol("p_dot_v", real=True)
            cross, p_dot_v, entries = applied_entries(t_value, b, c, v, w, dot)
            used = set().union(*(sp.sympify(entry).free_symbols for entry in entries))
            outputs = [self.let(f"w{i}", cross[i]) for i in range(3) if w[i] in used]
            outputs += [self.let("p_dot_v", p_dot_v)] if dot in used else []  # c2 = 0: no p p^T part
            outputs += [self.set(f"{output}[{i}]", entry) for i, entry in enumerate(entries)]
            batch = None
        statements.append({"kind": "if", "condition": self.out_of_range(), "then": nan, "otherwise": []})
        statements += body + outputs
        notes += self.coefficient_notes(names)
        return self.context(spec, name, signature, statements, notes, batch, output)

    def context(self, spec: CFunction, name: str, signature: str, statements: list[Statement],
                notes: list[str], batch: str | None, output: str | None) -> dict[str, Any]:
        return {"c_name": name, "summary": spec.summary, "equation": spec.equation, "notes": notes,
                "ops": ops_of(statements), "signature": signature, "statements": statements,
                "batch_signature": batch, "output": output}
