"""C functions for rotations of any size (issue 6): quaternion conversion, composition, rescaling.

Printed from the same evaluation plan as the rest of the header (:mod:`symrot.plan.builder`, with the
quaternion entries of :mod:`symrot.plan.quaternion`); quaternions are scalar first, matrices
row-major. Every function that can fail returns an ``int`` status: 0 on success, 1 when an input
is outside the validity range or not finite, or when the resulting rotation cannot be represented
by this parameterization (|φ| ≥ φ_max with φ_max ≤ π), or when the computed **p** fails the validity
test of ``angle``/``rotation_matrix`` (|p|² against p_max², or against the plan's x_limit when p is
unbounded, e.g. Cayley–Gibbs–Rodrigues p = tan(φ/2) e/|e| for e₀ → 0); the output is then NaN.
A status 0 therefore promises that every function of the header accepts the result.

* ``to_quaternion`` (eqs 74–75): e₀ = cos(φ/2) (the plan coefficient ``e_0``), **e** = (ν/2) **p**;
* ``from_quaternion``: normalizes e (``hypot``), takes the hemisphere e₀ ≥ 0 (|φ| ≤ π: this is
  rescaling, eqs 40–47) and returns **p** = σ **e** with σ = p(φ)/sin(φ/2) from the plan (trig-free
  in e₀ when possible, otherwise φ = 2 atan2(|**e**|, e₀) and a Taylor-safe branch in φ²);
* ``from_rotation_matrix``: Shepperd's largest pivot (eqs 61–65); the selected row is 4 e_k e, so
  no square root is needed before the normalization of ``from_quaternion``. Eqs 61–65 hold for
  rotations only, so R is first checked: max |RᵀR − I| ≤ 2⁻²⁶ (2⁻¹¹ in float) and det R > 0
  (:data:`~symrot.plan.quaternion.ROTATION_TOLERANCE_POWER`), otherwise status 1;
* ``compose`` (eqs 18–19, 67): p₃ with R(p₃) = R(p₂) R(p₁), p₁ applied first: e₃ = e₂ ∘ e₁;
* ``rescale``: **p** itself when e₀ ≥ 0, otherwise ``from_quaternion`` of −e.
"""

from __future__ import annotations

from typing import Any

import sympy as sp

from symrot.backends.c_statements import LARGEST, PHI_SYMBOL, PLAN_LABEL, T_SYMBOL, Statement, ops_of
from symrot.backends.c_writer import FunctionWriter
from symrot.core.parsing import PHI
from symrot.plan.ir import Branch
from symrot.plan.quaternion import E0, ROTATION_TOLERANCE_POWER

E_SYMBOL = sp.Symbol("c0", real=True)


class OperationWriter(FunctionWriter):
    """The operation functions of one plan in one precision."""

    @property
    def helper(self) -> str:
        return f"symrot_{self.header}__from_quaternion{self.suffix}"

    def name(self, operation: str) -> str:
        return f"symrot_{self.header}_{operation}{self.suffix}"

    def nan_out(self, output: str, count: int, status: bool = True) -> list[Statement]:
        statements: list[Statement] = self.nan_fill(output, count)
        statements.append({"kind": "return", "value": "1" if status else ""})
        return statements

    def entry(self, name: str, summary: str, equation: str, signature: str, statements: list[Statement],
              notes: list[str]) -> dict[str, Any]:
        return {"c_name": name, "summary": summary, "equation": equation, "notes": notes,
                "ops": ops_of(statements), "signature": signature, "statements": statements,
                "batch_signature": None, "output": None}

    # -- to_quaternion ---------------------------------------------------------------------------
    def to_quaternion(self) -> dict[str, Any]:
        t = self.ctype
        statements: list[Statement] = [*self.prologue(),
                                       {"kind": "if", "condition": self.out_of_range(),
                                        "then": self.nan_out("e", 4, status=False), "otherwise": []}]
        body, values = self.coefficients(["e_0", "nu"])
        statements += body
        half_nu = values["nu"] / 2
        statements.append(self.let("half_nu", half_nu))
        statements.append(self.set("e[0]", values["e_0"]))
        statements += [self.set(f"e[{i + 1}]", sp.Symbol("half_nu") * sp.Symbol(f"p[{i}]")) for i in range(3)]
        notes = self.validity_notes() + self.coefficient_notes(["e_0", "nu"])
        return self.entry(self.name("to_quaternion"), "Euler-Rodrigues parameters e = (e0, e1, e2, e3), "
                          "e0 = cos(phi/2) = nu/epsilon, (e1, e2, e3) = (nu/2) p", "74-75",
                          f"void {self.name('to_quaternion')}(const {t} p[3], {t} e[4])", statements, notes)

    # -- from_quaternion (internal helper and public function) -----------------------------------
    def scale_statements(self) -> tuple[list[Statement], str]:
        """Statements leaving σ in ``sigma`` from ``c0`` = |e₀|/|e| (normalized) or, for the branch in
        φ², from φ = 2 atan2(|**e**|, |e₀|) (scale-free)."""
        scale = self.precision_plan.quaternion_scale
        if scale.algebraic is not None:
            expression = scale.algebraic.subs(E0, E_SYMBOL)
            return [self.let("sigma", expression)], f"sigma = {sp.sstr(scale.algebraic)} (trig-free in e0)"
        branch = scale.branch
        assert isinstance(branch, Branch)
        statements: list[Statement] = [
            # atan2 does not need the quaternion normalized
            self.let("phi", 2 * sp.atan2(sp.Symbol("e_norm", real=True), sp.Abs(sp.Symbol("e0", real=True)))),
            self.let("t", PHI_SYMBOL ** 2),
            {"kind": "declare", "type": self.ctype, "names": ["sigma"]},
            self.branch_value(branch, T_SYMBOL, "sigma"),
        ]
        note = (f"sigma: Horner degree {len(branch.horner) - 1} in t = phi^2 below {branch.threshold:.6g}, "
                f"else {sp.sstr(branch.closed.subs(PHI, sp.Symbol('phi')))}, phi = 2 atan2(|e|, e0)")
        return statements, note

    def from_quaternion_helper(self) -> dict[str, Any]:
        t = self.ctype
        p_lit = self.printer.literal
        e1, e2, e3 = (sp.Symbol(f"e{i}", real=True) for i in (1, 2, 3))
        # after the scaling below, max |e_i| lies in [2^-500, 2^500] ([2^-60, 2^60] in float): no
        # square that matters can underflow or overflow, so plain sums of squares are safe
        e_norm_statements: list[Statement] = [self.let("y", e1**2 + e2**2 + e3**2)]
        if self.precision_plan.quaternion_scale.algebraic is None:  # the branch in φ² needs |e|
            e_norm_statements.append(self.let("e_norm", sp.sqrt(sp.Symbol("y", real=True))))
        f = "" if t == "double" else "f"
        low, high = (("2^-500", "2^500") if t == "double" else ("2^-60", "2^60"))
        low_lit = p_lit(sp.Integer(2) ** (-500 if t == "double" else -60))
        high_lit = p_lit(sp.Integer(2) ** (500 if t == "double" else 60))
        scaling: list[Statement] = [
            {"kind": "comment", "text": f"exact power-of-two scaling when max |e_i| is outside "
                                        f"[{low}, {high}]"},
            {"kind": "let", "type": t, "name": "big",
             "value": f"fmax{f}(fmax{f}(fabs{f}(e0), fabs{f}(e1)), fmax{f}(fabs{f}(e2), fabs{f}(e3)))",
             "ops": 7},
            {"kind": "if",
             "condition": f"big > 0 && big < {self.infinity} && (big < {low_lit} || big > {high_lit})",
             "then": [{"kind": "declare", "type": "int", "names": ["k"]},
                      {"kind": "call", "value": f"(void)frexp{f}(big, &k)"}]
             + [{"kind": "set", "name": v, "value": f"ldexp{f}({v}, -k)", "ops": 1}
                for v in ("e0", "e1", "e2", "e3")],
             "otherwise": []},
        ]
        statements: list[Statement] = scaling + e_norm_statements + [
            self.let("n", sp.sqrt(sp.Symbol("e0", real=True) ** 2 + sp.Symbol("y", real=True))),
            {"kind": "if", "condition": f"!(n > 0) || !(n <= {p_lit(LARGEST[self.precision])})",
             "then": self.nan_out("p", 3), "otherwise": []},
            {"kind": "let", "type": t, "name": "f", "value": "(e0 < 0 ? -1 : 1) / n", "ops": 2},
        ]
        if self.plan.e0_min is not None or self.precision_plan.quaternion_scale.algebraic is not None:
            statements.append({"kind": "let", "type": t, "name": "c0",
                               "value": self.c(sp.Abs(sp.Symbol("e0")) / sp.Symbol("n")), "ops": 2})
        if self.plan.e0_min is not None:
            statements.append({"kind": "if", "condition": f"!(c0 > {p_lit(self.plan.e0_min)})",
                               "then": self.nan_out("p", 3), "otherwise": []})
        scale, note = self.scale_statements()
        statements += scale
        statements += [self.set(f"p[{i}]", sp.Symbol("sigma") * (sp.Symbol(f"e{i + 1}") * sp.Symbol("f")))
                       for i in range(3)]
        # the result must pass the validity test of angle/rotation_matrix (p_max or x_limit): a
        # status 0 promises that every function of the header accepts p
        squared = "(p[0] * p[0]) + (p[1] * p[1]) + (p[2] * p[2])"  # as x in every function
        statements.append({"kind": "if", "condition": self.out_of_range(squared),
                           "then": self.nan_out("p", 3), "otherwise": []})
        statements.append({"kind": "return", "value": "0"})
        signature = f"int {self.helper}({t} e0, {t} e1, {t} e2, {t} e3, {t} p[3])"
        return self.entry(self.helper, "internal: p from a quaternion of any norm and sign",
                          "75", signature, statements, [note])

    def from_quaternion(self) -> dict[str, Any]:
        t = self.ctype
        call = f"{self.helper}(e[0], e[1], e[2], e[3], p)"
        statements: list[Statement] = [{"kind": "return", "value": call}]
        notes = ["e is normalized; e and -e give the same p: the hemisphere e0 >= 0 is taken (|phi| <= pi),",
                 "which is the rescaling of eqs 40-47. Returns 0, or 1 with p = NaN when e is not finite or",
                 "zero, or the rotation is not representable (" + self.representable_note() + ")."]
        return self.entry(self.name("from_quaternion"), "parameter vector from Euler-Rodrigues parameters "
                          "(scalar first)", "75",
                          f"int {self.name('from_quaternion')}(const {t} e[4], {t} p[3])",
                          statements, notes)

    def representable_note(self) -> str:
        if self.plan.e0_min is None:
            return "every rotation is, for this parameterization"
        return f"needs |phi| < {self.plan.phi_max:.17g}, i.e. e0 > {self.plan.e0_min:.17g}"

    # -- from_rotation_matrix and rescale: the same in every header (templates/c/shared.h.j2) -------
    def from_rotation_matrix(self) -> dict[str, Any]:
        """Shepperd's largest pivot (eqs 61–65) after the check of R: max |RᵀR − I| ≤ 2^power and
        det R > 0 (:data:`~symrot.plan.quaternion.ROTATION_TOLERANCE_POWER`); NaN fails every
        comparison, so non-finite R and R whose products overflow are refused too."""
        power = ROTATION_TOLERANCE_POWER[PLAN_LABEL[self.precision]]
        return self.shared("from_rotation_matrix", self.printer.literal(sp.Integer(2) ** power), str(power))

    # -- compose and rescale ---------------------------------------------------------------------
    def compose(self) -> dict[str, Any]:
        t = self.ctype
        to_q = self.name("to_quaternion")
        product = ("a[0] * b[0] - (a[1] * b[1] + a[2] * b[2] + a[3] * b[3]), "
                   "a[0] * b[1] + b[0] * a[1] + (b[2] * a[3] - b[3] * a[2]), "
                   "a[0] * b[2] + b[0] * a[2] + (b[3] * a[1] - b[1] * a[3]), "
                   "a[0] * b[3] + b[0] * a[3] + (b[1] * a[2] - b[2] * a[1])")
        statements: list[Statement] = [
            {"kind": "declare", "type": t, "names": ["a[4]", "b[4]"]},
            {"kind": "call", "value": f"{to_q}(p1, a)"},
            {"kind": "call", "value": f"{to_q}(p2, b)"},
            {"kind": "return", "value": f"{self.helper}({product}, p3)", "ops": 28},
        ]
        notes = ["Convention: R(p3) = R(p2) R(p1), i.e. p1 is applied first, then p2 (eqs 18-19);",
                 "quaternions: e3 = e2 o e1 (eq 67). The result is rescaled (|phi3| <= pi). Returns 0, or 1",
                 "with p3 = NaN when p1 or p2 is out of range or the result is not representable (",
                 self.representable_note() + ")."]
        return self.entry(self.name("compose"), "composition of two rotations", "18-19",
                          f"int {self.name('compose')}(const {t} p1[3], const {t} p2[3], {t} p3[3])",
                          statements, notes)

    def rescale(self) -> dict[str, Any]:
        """**p** itself when e₀ ≥ 0, otherwise ``from_quaternion`` of −e."""
        return self.shared("rescale")

    def all(self) -> list[dict[str, Any]]:
        """Helper first, then the public functions (C needs declaration before use)."""
        return [self.to_quaternion(), self.from_quaternion_helper(), self.from_quaternion(),
                self.from_rotation_matrix(), self.compose(), self.rescale()]
