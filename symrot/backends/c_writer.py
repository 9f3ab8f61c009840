"""The statements of the C functions of one plan in one precision: the layer under the C backend.

:class:`FunctionWriter` turns the evaluation plan of :mod:`symrot.plan.builder` into statements (dicts that
``templates/c/header.h.j2`` prints) with :class:`~symrot.backends.c_printer.SymrotCPrinter`; the
header (:mod:`symrot.backends.c_backend`), the ``_batch`` kernels (:mod:`symrot.backends.c_batch`)
and the operations (:mod:`symrot.backends.c_operations`) build on it. It stands on
:class:`~symrot.backends.c_angle.AngleWriter` (φ, λ and |p|), which stands on
:class:`~symrot.backends.c_statements.PlanWriter` (statements, literals, the validity test). How a
plan becomes C:

* x = |p|² once; outside the validity range (``!(x < p_max²)``, or ``!(x < x_limit)`` (the plan's
  x_limit, at most 2^600, 2^100 in float) when p is unbounded, which also catches inf and NaN)
  every output is NaN; for the sine family also d = p_max² − x with fma-exact products and TwoSum
  (``__complement``), which the plan's expressions use instead of k² − x
  (:mod:`symrot.backends.c_statements`);
* coefficients (this module): a :class:`~symrot.plan.ir.Constant` is folded into the output
  expressions, an :class:`~symrot.plan.ir.Algebraic` one is a single expression in x (no branch,
  no trig); the :class:`~symrot.plan.ir.Branch` ones of a function share one
  ``if (x < smallest threshold)``: below it every coefficient is its Horner polynomial, above it φ
  is computed once, the closed forms share common subexpressions (``sympy.cse``, inside that
  branch only, where x > 0) and a coefficient whose own threshold is larger still takes its
  polynomial (sin and cos are libm's here, ≈ 0.5 ulp; the ``_batch`` kernels of
  :mod:`symrot.backends.c_batch` use the vectorizable kernel of :mod:`symrot.backends.c_sincos`
  instead);
* φ: the plan's closed inverse, or its safeguarded Newton iteration (:mod:`symrot.backends.c_angle`);
* tensors T = c0 I + c1 (p×) + c2 (p×)² entry by entry
  (:func:`~symrot.backends.c_functions.tensor_entries`), vectors as t v + c1 p×v + c2 (p·v) p with
  t = c0 − c2 |p|² (:func:`~symrot.backends.c_functions.applied_entries`).

``/* ops: N */`` is the number of operations on the longest path through the function, as
counted by ``sympy.count_ops`` (a call such as ``sin`` counts one; Newton iterations multiplied).
"""

from __future__ import annotations

from typing import Any

import sympy as sp

from symrot.backends.c_angle import AngleWriter
from symrot.backends.c_functions import (
    OUTPUT_NAMES,
    TENSOR_OF,
    VECTOR_NAMES,
    CFunction,
    across_value,
    applied_entries,
    tensor_coefficients,
    tensor_entries,
)
from symrot.backends.c_printer import horner
from symrot.backends.c_statements import HALF_LOW, PHI_SYMBOL, X_SYMBOL, Statement, ops_of
from symrot.backends.subexpressions import common_subexpressions
from symrot.core.parsing import PHI
from symrot.plan.algebraic import S, X
from symrot.plan.ir import Algebraic, Branch, Constant


class FunctionWriter(AngleWriter):
    """Statements of the C functions of one plan in one precision."""

    # -- coefficients ----------------------------------------------------------------------------
    def coefficients(self, names: list[str]) -> tuple[list[Statement], dict[str, sp.Expr]]:
        """Statements computing ``names`` and the expression standing for each in the outputs. Each
        statement is marked ``block: coefficients`` with the names it leaves: where functions of a
        header compute the same block, :func:`symrot.backends.c_shared.share_coefficients` prints
        it once, as a helper they call."""
        statements, values = self.coefficient_statements(names)
        computed = [f"c_{name}" for name in names if isinstance(values[name], sp.Symbol)]
        marked = [{**statement, "block": "coefficients", "computed": computed} for statement in statements]
        return marked, values

    def coefficient_statements(self, names: list[str]) -> tuple[list[Statement], dict[str, sp.Expr]]:
        """The statements of :meth:`coefficients`, unmarked."""
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
            nan = [*self.nan_fill(output, 9), {"kind": "return", "value": ""}]
            outputs = [self.set(f"{output}[{i}]", entry)
                       for i, entry in enumerate(tensor_entries(t_value, b, c))]
            batch = f"void {name}_batch(size_t n, const {t} *p, {t} *{output})"
        else:
            given, output = VECTOR_NAMES[spec.name]
            signature = f"void {name}(const {t} p[3], const {t} {given}[3], {t} {output}[3])"
            nan = [*self.nan_fill(output, 3), {"kind": "return", "value": ""}]
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
