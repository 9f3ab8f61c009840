"""The base of the C writers: statements, their operation counts, and what every C function of one
plan in one precision shares (:class:`PlanWriter`): literals, the squared norm x = |p|², the
validity test on it, and the compensated complement d = p_max² − x of the sine family.

Statements are dicts that ``templates/c/statements.j2`` prints (``let``, ``declare``, ``set``,
``if``, ``loop``, ``call``, ``return``, ``comment``). ``/* ops: N */`` is the number of operations
on the longest path through a function (:func:`ops_of`), as counted by ``sympy.count_ops`` (a call
such as ``sin`` counts one; loops multiplied).
"""

from __future__ import annotations

import math
from typing import Any

import sympy as sp

from symrot.backends.c_functions import P
from symrot.backends.c_printer import MANTISSA_BITS, Precision, SymrotCPrinter
from symrot.backends.templating import macro
from symrot.core.errors import NonFiniteLiteral
from symrot.plan.ir import EvaluationPlan, PrecisionPlan

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



class PlanWriter:
    """What every C function of one plan in one precision shares."""

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

    def nan_fill(self, output: str, count: int) -> list[Statement]:
        """Every entry of ``output`` NaN: one loop for a 3×3 matrix (a line, not nine), the stores
        for a vector or a quaternion."""
        if count < 9:
            return [self.set(f"{output}[{i}]", self.nan) for i in range(count)]
        return [{"kind": "loop", "header": f"int i = 0; i < {count}; ++i",
                 "body": [self.set(f"{output}[i]", self.nan)], "times": count}]

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

    def validity_notes(self) -> list[str]:
        plan = self.plan
        if math.isfinite(plan.p_max):
            return [f"Valid for |p| < {plan.p_max:.17g} (|phi| < {plan.phi_max:.17g}); outside it, and for "
                    "non-finite p, every output is NaN."]
        bound = f"2^{math.frexp(self.precision_plan.x_limit)[1] - 1}"
        return [f"Valid for every p with |p|^2 < {bound} (|phi| < {plan.phi_max:.17g}), the largest power",
                "of two up to which every printed form was checked against 50+ digits; otherwise, and for",
                "non-finite p, every output is NaN."]

    def shared(self, function: str, *extra: str) -> dict[str, Any]:
        """Public ``function`` printed from its macro in ``templates/c/shared.h.j2``: a function
        whose text is the same in every header but for the prefix symrot_NAME and the precision
        (``extra``: the macro's further arguments). The header prints its ``source`` as it is."""
        f = "" if self.ctype == "double" else "f"
        source = macro("c/shared.h.j2", function, f"symrot_{self.header}", self.suffix, self.ctype, f,
                       self.nan, *extra)
        return {"c_name": f"symrot_{self.header}_{function}{self.suffix}", "source": source}
