"""The ``_batch`` kernels of the C backend, written so that compilers vectorize them.

A kernel ``symrot_NAME_F_batch(n, p, T)`` evaluates the tensor function F (R, H, H⁻¹, G or K,
eqs 14, 22, 26, 81, 83) for n vectors. It prints the same plan as the single call
(:class:`~symrot.backends.c_writer.FunctionWriter`), in blocks of ``SYMROT_BATCH_BLOCK`` vectors
and four passes, so that the two expensive middle ones have no branch and no library call:

1. **scalar pass** (k < block length, branches allowed): x = |p|², and for vectors inside the
   validity range (and above the smallest threshold, when only closed forms need them) every
   operation a vectorizing compiler cannot handle: s = √x, d = p_max² − x (``__complement``), φ
   (the plan's closed inverse or Newton iteration) and each *scalar atom* u of the coefficient
   expressions, a maximal subexpression that is not arithmetic (√(x + 9), ∛(6(φ − sin φ)), ...).
   Other lanes, and lanes past n, get 0.
2. **candidate pass** (constant trip count): every closed form and every Horner polynomial, for
   every lane, stored. Nothing is conditional: under the default ``-ftrapping-math`` gcc moves an
   operation used on one side of a select into that side and then will not execute it
   speculatively, which blocks vectorization without AVX-512 masks. sin and cos of arguments c·φ
   with a bounded range come from the branch-free kernel of :mod:`symrot.backends.c_sincos` (one
   kernel gives both); any other trig call is a scalar atom.
3. **select pass** (constant trip count): polynomial below the coefficient's threshold, closed form
   above, NaN outside the validity range, between values loaded unconditionally. Both candidates
   are computed for every lane anyway, so the batch kernels take the plan's smallest accurate
   switch and shortest polynomial (``Branch.smallest_switch``), not the single call's switch, which
   is moved up to skip library calls.
4. **assembly** (k < block length): T = c0 I + c1 (p×) + c2 (p×)² entry by entry, as the single call.

The blocks, and the vectors of the assembly, run backward: with the output at the address of p
(in place, :mod:`symrot.backends.c_aliasing`) vector k's entries out[9k..9k+8] overwrite only the
p of vectors already done, or its own, read into locals first.

The values differ from the single call only by the rounding of the sin/cos kernel (≤ 1.5 ulp
where libm's is about 0.5); both are tested against mpmath. No valid input raises a
floating-point exception flag (tests/test_c_batch_flags.py): a lane that discards a closed form
(past n, out of the range, below the polynomials' threshold) computes it at a safe point, the
scalar pass's values at the largest threshold (:meth:`BatchWriter.safe_point`), and a polynomial
reads x only below its own threshold.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import sympy as sp

from symrot.backends.c_functions import (
    OUTPUT_NAMES,
    TENSOR_OF,
    CFunction,
    P,
    across_value,
    tensor_coefficients,
    tensor_entries,
)
from symrot.backends.c_printer import MANTISSA_BITS, MAX_EXPANDED_POWER, SymrotCPrinter, horner
from symrot.backends.c_sincos import TRIG, SinCosWriter
from symrot.backends.c_statements import HALF_LOW, PHI_SYMBOL, X_SYMBOL, Statement
from symrot.backends.c_writer import FunctionWriter
from symrot.backends.subexpressions import common_subexpressions
from symrot.core.functions import BoundedPower
from symrot.core.parsing import PHI
from symrot.plan.algebraic import D, S, X
from symrot.plan.ir import Algebraic, Branch, Coefficient, Constant

BLOCK = "SYMROT_BATCH_BLOCK"
DEFAULT_BLOCK = 32
"""Vectors per block: 8 (AVX2) or 4 (AVX-512) vector iterations per loop, 2–3 KB of stack."""
LANE = sp.Symbol("pk[0]"), sp.Symbol("pk[1]"), sp.Symbol("pk[2]")
XC = sp.Symbol("xc", real=True)
"""x as the branch forms read it: x, or the safe point where the lane discards them."""
VALUE = sp.Symbol("p0", real=True), sp.Symbol("p1", real=True), sp.Symbol("p2", real=True)
"""p of a vector read before its entries are written (in place, vector 0's p is out[0..2])."""


@dataclass
class Lanes:
    """The scalar atoms (expression → u{i}) and the kernel's trig arguments (argument → i)."""

    atoms: dict[sp.Expr, sp.Symbol] = field(default_factory=dict)
    trig: dict[sp.Expr, int] = field(default_factory=dict)


@dataclass
class Views:
    """What the candidate pass reads besides x, chosen by lane in the scalar pass (branches are
    allowed there) so that no lane computes on an argument that raises a flag: ``xc``, x as the
    branch forms read it (the safe point where the lane discards them); ``loaded``, the scalar
    inputs read as they are; ``guarded``, the inputs of the branch forms read through
    ``{input}_b`` (the safe point below ``smallest``), where an algebraic coefficient needs the
    true inputs on every lane; ``levels``, the polynomials' thresholds, each with ``xp{j}`` = x
    below it and 0 above (a polynomial of high degree would overflow far above its threshold)."""

    closed_x: bool
    loaded: list[sp.Symbol]
    guarded: list[sp.Symbol]
    smallest: float | None
    levels: list[float]


class VectorCPrinter(SymrotCPrinter):
    """Prints every small integer power as a product: ``pow`` is a library call (gcc folds only
    the square), and a call keeps the coefficient pass from being vectorized."""

    def _print_Pow(self, expr: sp.Pow) -> str:
        base, exponent = expr.base, expr.exp
        if exponent.is_Integer and 2 <= abs(int(exponent)) <= MAX_EXPANDED_POWER and not base.is_Symbol:
            product = "(" + "*".join([f"({self._print(base)})"] * abs(int(exponent))) + ")"
            return product if exponent > 0 else f"{self._print_Float(sp.Float(1))}/{product}"
        return super()._print_Pow(expr)


class BatchWriter:
    """Statements of the ``_batch`` kernels of one plan in one precision."""

    def __init__(self, writer: FunctionWriter) -> None:
        self.writer = writer
        self.t = writer.ctype
        self.f = "" if writer.precision == "double" else "f"
        self.printer = VectorCPrinter(writer.precision)
        self.sincos = SinCosWriter(writer.precision, self.printer, PHI_SYMBOL, writer.plan.phi_max)

    def c(self, expr: sp.Expr) -> str:
        return str(self.printer.doprint(expr))

    # -- analysis --------------------------------------------------------------------------------
    def split(self, expr: sp.Expr, lanes: Lanes) -> sp.Expr:
        """``expr`` with each maximal non-arithmetic subexpression replaced by a scalar atom."""
        if expr.is_Symbol or expr.is_Rational:
            return expr
        if expr.is_number:
            return sp.Float(expr.evalf(40), 40)
        if isinstance(expr, TRIG) and self.sincos.applies(expr.args[0]):
            return expr
        arithmetic = expr.is_Add or expr.is_Mul or isinstance(expr, BoundedPower)
        if arithmetic or (expr.is_Pow and expr.exp.is_Integer):
            return expr.func(*(self.split(arg, lanes) for arg in expr.args))
        if expr not in lanes.atoms:
            lanes.atoms[expr] = sp.Symbol(f"u{len(lanes.atoms)}", real=True)
        return lanes.atoms[expr]

    def vectorize(self, expr: sp.Expr, lanes: Lanes) -> sp.Expr:
        """Scalar atoms split off, kernel trig replaced by sin{i}/cos{i} symbols."""
        return self.sincos.replace(self.split(expr, lanes), lanes.trig)

    # -- the kernel ------------------------------------------------------------------------------
    def kernel(self, spec: CFunction) -> tuple[list[Statement], list[str]]:
        """Body of ``symrot_NAME_F_batch(size_t n, const T *p, T *OUT)`` for matrix function F, and
        the lines of its header comment."""
        writer = self.writer
        names = tensor_coefficients(TENSOR_OF[spec.name], writer.plan.across_tensors())
        plan = {name: writer.precision_plan.coefficients[name] for name in names}
        lanes = Lanes()
        closed: dict[str, sp.Expr] = {}
        for name, coefficient in plan.items():
            if isinstance(coefficient, Algebraic):
                closed[name] = self.vectorize(coefficient.expression.subs(X, X_SYMBOL), lanes)
            elif isinstance(coefficient, Branch):
                form = coefficient.closed.subs({PHI: PHI_SYMBOL, X: X_SYMBOL})
                closed[name] = self.vectorize(writer.half_angle_corrected(form), lanes)
        used: set[sp.Basic] = set().union(*(e.free_symbols for e in closed.values()))
        if lanes.trig:
            used.add(PHI_SYMBOL)
        inputs = [symbol for symbol in (S, D, PHI_SYMBOL, HALF_LOW, *lanes.atoms.values()) if symbol in used]
        branches = [name for name in names if isinstance(plan[name], Branch)]
        below, replacements, reduced_of, views = self.forms(plan, closed, inputs, lanes)
        lane_names = ["x", *(["xc"] if views.closed_x else []), *(str(s) for s in views.loaded),
                      *(f"{symbol}_b" for symbol in views.guarded),
                      *(f"xp{j}" for j in range(len(views.levels)))]
        arrays = [f"{name}_lanes[{BLOCK}]" for name in lane_names]
        arrays += [f"c_{name}_lanes[{BLOCK}]" for name in names]
        arrays += [f"poly_{name}_lanes[{BLOCK}]" for name in branches]
        notes = []
        scalar = [str(symbol) for symbol in inputs if symbol not in lanes.atoms.values()]
        scalar += [f"{symbol} = {sp.sstr(atom)}" for atom, symbol in lanes.atoms.items()]
        if scalar:
            notes.append("Scalar pass: " + ", ".join(scalar) + ".")
        if lanes.trig:
            notes.append(self.sincos.note())
        candidate_body = self.candidate_pass(plan, lanes, replacements, reduced_of, views)
        candidates: list[Statement] = [  # none when every coefficient is a constant (CGR's H^-1)
            {"kind": "comment", "text": "every candidate value, unconditionally"},
            {"kind": "loop", "header": f"k = 0; k < {BLOCK}; ++k", "times": 1, "body": candidate_body},
        ] if candidate_body else []
        return [
            {"kind": "declare", "type": self.t, "names": arrays},
            {"kind": "declare", "type": "size_t", "names": ["end", "start", "k"]},
            *self.safe_point(plan, lanes, inputs, views.closed_x),
            {"kind": "comment", "text": "the last block first, its last vector first: in place "
                                        "(the output at p), no entries overwrite a p not yet read"},
            {"kind": "loop", "header": "end = n; end > 0; end = start", "times": 1, "body": [
                {"kind": "set", "name": "start", "value": f"(end - 1) / {BLOCK} * {BLOCK}"},
                {"kind": "let", "type": "size_t", "name": "m", "value": "end - start"},
                *self.scalar_pass(lanes, inputs, below, views),
                *candidates,
                {"kind": "comment", "text": "select: polynomial below the threshold, NaN outside the range"},
                {"kind": "loop", "header": f"k = 0; k < {BLOCK}; ++k", "times": 1,
                 "body": self.select_pass(plan)},
                {"kind": "loop", "header": "k = m; k-- > 0;", "times": 1,
                 "body": self.assembly(spec, names)},
            ]},
        ], notes

    def forms(self, plan: dict[str, Coefficient], closed: dict[str, sp.Expr], inputs: list[sp.Symbol],
              lanes: Lanes) -> tuple[float | None, list[tuple[sp.Symbol, sp.Expr]], dict[str, sp.Expr],
                                     Views]:
        """The threshold below which the scalar pass skips the library calls, the common
        subexpressions and reduced forms of the coefficients (the branch forms on ``xc`` or on
        the guarded inputs, see :class:`Views`), and the views the passes read."""
        branches = [name for name in plan if isinstance(plan[name], Branch)]
        below = self.polynomial_below(plan, closed, inputs)
        guard = {symbol: sp.Symbol(f"{symbol}_b", real=True) for symbol in (X_SYMBOL, *inputs)} \
            if below is None and inputs and any(name in branches for name in closed) else {}
        if guard:  # the algebraic forms read every lane; the branch forms the safe point below
            algebraic = [name for name in closed if name not in branches]
            first, first_reduced = common_subexpressions([closed[n] for n in algebraic], "w")
            second, second_reduced = common_subexpressions(
                [closed[n].xreplace(guard) for n in closed if n in branches], "wb")
            replacements = [*first, *second]
            reduced_of = {**dict(zip(algebraic, first_reduced, strict=True)),
                          **dict(zip([n for n in closed if n in branches], second_reduced, strict=True))}
            lanes.trig = {argument.xreplace(guard): index for argument, index in lanes.trig.items()}
        else:  # below the smallest threshold the branch forms read the safe point (x from xc_lanes)
            forms = [closed[n].xreplace({X_SYMBOL: XC}) if n in branches else closed[n] for n in closed]
            replacements, reduced = common_subexpressions(forms, "w")
            reduced_of = dict(zip(closed, reduced, strict=True))
        free = set().union(*(e.free_symbols for e in [*reduced_of.values(), *(v for _, v in replacements)]),
                           *(argument.free_symbols for argument in lanes.trig))
        levels = sorted({c.smallest_switch[0] for c in plan.values()
                         if isinstance(c, Branch) and len(c.smallest_switch[1]) > 1})
        views = Views(closed_x=XC in free, loaded=[symbol for symbol in inputs if symbol in free],
                      guarded=[symbol for symbol, swapped in guard.items() if swapped in free],
                      smallest=min((c.smallest_switch[0] for c in plan.values() if isinstance(c, Branch)),
                                   default=None),
                      levels=levels)
        return below, replacements, reduced_of, views

    def candidate_pass(self, plan: dict[str, Coefficient], lanes: Lanes,
                       replacements: list[tuple[sp.Symbol, sp.Expr]], reduced: dict[str, sp.Expr],
                       views: Views) -> list[Statement]:
        """Closed forms into c_*_lanes, polynomials into poly_*_lanes, for every lane of the block.

        Nothing is conditional here: under the default -ftrapping-math a compiler will not
        speculate an arithmetic operation that the source only performs on one side of a branch
        (gcc sinks it there), and such a loop is not vectorized without masked instructions; the
        values that differ by lane are chosen in the scalar pass (:class:`Views`), so that no
        value computed here raises a floating-point flag on valid input.
        """
        closed = [*reduced.values(), *(value for _, value in replacements)]
        body: list[Statement] = []
        if any(X_SYMBOL in e.free_symbols for e in closed):
            body.append({"kind": "let", "type": self.t, "name": "x", "value": "x_lanes[k]"})
        names = [*(["xc"] if views.closed_x else []), *(str(symbol) for symbol in views.loaded),
                 *(f"{symbol}_b" for symbol in views.guarded)]
        body += [{"kind": "let", "type": self.t, "name": name, "value": f"{name}_lanes[k]"} for name in names]
        wanted = {str(symbol) for e in closed for symbol in e.free_symbols}
        body += self.sincos.statements(lanes.trig, wanted)
        body += [{"kind": "let", "type": self.t, "name": str(symbol), "value": self.c(value)}
                 for symbol, value in replacements]
        for name, coefficient in plan.items():
            if isinstance(coefficient, (Algebraic, Branch)):
                body.append({"kind": "set", "name": f"c_{name}_lanes[k]", "value": self.c(reduced[name])})
            if isinstance(coefficient, Branch):
                threshold, polynomial = coefficient.smallest_switch
                variable = f"xp{views.levels.index(threshold)}_lanes[k]" if len(polynomial) > 1 else "x"
                body.append({"kind": "set", "name": f"poly_{name}_lanes[k]",
                             "value": self.c(horner(polynomial, sp.Symbol(variable, real=True)))})
        return body

    def select_pass(self, plan: dict[str, Coefficient]) -> list[Statement]:
        """Selects between values already loaded (a blend; every load is unconditional, so that
        no compiler has to prove a conditional load safe)."""
        body: list[Statement] = [{"kind": "let", "type": self.t, "name": "x", "value": "x_lanes[k]"}]
        outside = self.writer.out_of_range()
        for name, coefficient in plan.items():
            value = f"closed_{name}"
            if isinstance(coefficient, Constant):
                value = self.c(sp.sympify(coefficient.value))
            else:
                body.append({"kind": "let", "type": self.t, "name": value, "value": f"c_{name}_lanes[k]"})
            if isinstance(coefficient, Branch):
                threshold = self.printer.literal(coefficient.smallest_switch[0])
                body.append({"kind": "let", "type": self.t, "name": f"poly_{name}",
                             "value": f"poly_{name}_lanes[k]"})
                body.append({"kind": "let", "type": self.t, "name": f"v_{name}",
                             "value": f"x < {threshold} ? poly_{name} : {value}"})
                value = f"v_{name}"
            body.append({"kind": "set", "name": f"c_{name}_lanes[k]",
                         "value": f"{outside} ? {self.writer.nan} : {value}"})
        return body

    def assembly(self, spec: CFunction, names: list[str]) -> list[Statement]:
        """T = t I + c1 (p×) + c2 p pᵀ for the vectors of the block, as in the single call."""
        first, b, c = (sp.Symbol(f"c_{name}_lanes[k]", real=True) for name in names)
        tensor = TENSOR_OF[spec.name]
        t_value = across_value(tensor, self.writer.plan.across_tensors(), first, c,
                               sp.Symbol("x_lanes[k]", real=True))
        across: list[Statement] = []
        if t_value != first:
            across.append({"kind": "let", "type": self.t, "name": "t", "value": self.c(t_value)})
            t_value = sp.Symbol("t", real=True)
        values = dict(zip(P, VALUE, strict=True))
        entries = [entry.xreplace(values) for entry in tensor_entries(t_value, b, c)]
        output = OUTPUT_NAMES[spec.name]
        return [
            {"kind": "let", "type": f"{self.t} *const", "name": "pk", "value": "p + 3 * (start + k)"},
            *({"kind": "let", "type": self.t, "name": str(v), "value": str(lane)}  # vector 0: out = pk
              for v, lane in zip(VALUE, LANE, strict=True)),
            *across,
            {"kind": "declare", "type": f"{self.t} *const", "names": [f"out = {output} + 9 * (start + k)"]},
            *({"kind": "set", "name": f"out[{i}]", "value": self.c(entry)}
              for i, entry in enumerate(entries)),
        ]

    @staticmethod
    def polynomial_below(plan: dict[str, Coefficient], closed: dict[str, sp.Expr],
                         inputs: list[sp.Symbol]) -> float | None:
        """The x below which every coefficient reading the scalar pass is its polynomial (so the
        scalar pass can skip φ and the atoms there, as the single call does), or None."""
        if any(isinstance(plan[name], Algebraic) and closed[name].free_symbols & set(inputs)
               for name in closed):
            return None
        thresholds = [c.smallest_switch[0] for c in plan.values() if isinstance(c, Branch)]
        return min(thresholds) if thresholds else None

    def safe_x(self, plan: dict[str, Coefficient]) -> float:
        """Where the closed forms are evaluated on lanes that discard them: the largest threshold
        of the coefficients' polynomials, above which every closed form is the plan's accurate
        (so finite) value, or inside the range where no coefficient has one."""
        thresholds = [c.smallest_switch[0] for c in plan.values() if isinstance(c, Branch)]
        if thresholds:
            return max(thresholds)
        return min(1.0, self.writer.bound / 4) if math.isfinite(self.writer.plan.p_max) else 1.0

    def safe_point(self, plan: dict[str, Coefficient], lanes: Lanes, inputs: list[sp.Symbol],
                   closed_x: bool) -> list[Statement]:
        """The scalar pass's values at :meth:`safe_x`, once per call: a lane whose closed forms are
        discarded (past n, out of the range, below the polynomials' threshold) computes them
        there, not at 0 (0/0 would raise the invalid-operation flag)."""
        if not inputs and not closed_x:
            return []
        writer = self.writer
        values = {X_SYMBOL: sp.Symbol("x_safe", real=True), S: sp.Symbol("s_safe", real=True),
                  PHI_SYMBOL: sp.Symbol("phi_safe", real=True), D: sp.Symbol("d_safe", real=True),
                  HALF_LOW: sp.Symbol("half_low_safe", real=True)}
        needs = self.needs(lanes, inputs)
        statements: list[Statement] = [
            {"kind": "comment", "text": "where the lanes that discard the closed forms compute them: no 0/0"},
            {"kind": "let", "type": self.t, "name": "x_safe",
             "value": self.printer.literal(self.safe_x(plan))}]
        if D in needs:
            high = self.printer.literal(writer.plan.complement_parts(MANTISSA_BITS[writer.precision])[0])
            statements.append({"kind": "let", "type": self.t, "name": "d_safe",
                               "value": f"{high} - x_safe"})
        if S in needs:
            statements.append({"kind": "let", "type": self.t, "name": "s_safe",
                               "value": f"sqrt{self.f}(x_safe)"})
        if PHI_SYMBOL in needs:
            extra = ", d_safe" if writer.plan.complement is not None else ""
            statements.append({"kind": "let", "type": self.t, "name": "phi_safe",
                               "value": f"{writer.angle_helper}(s_safe{extra})"})
        if HALF_LOW in needs:
            statements.append({"kind": "let", "type": self.t, "name": "half_low_safe",
                               "value": writer.half_low_call("s_safe", "phi_safe")})
        for atom, symbol in lanes.atoms.items():
            statements.append(writer.let(f"{symbol}_safe", atom.xreplace(values)))
        return statements

    def needs(self, lanes: Lanes, inputs: list[sp.Symbol]) -> set[sp.Basic]:
        """What the scalar pass computes: the inputs of the closed forms and what they stand on."""
        needs = set(inputs) | set().union(*(atom.free_symbols for atom in lanes.atoms))
        if lanes.trig or HALF_LOW in needs:
            needs.add(PHI_SYMBOL)
        if PHI_SYMBOL in needs:
            needs.add(S)
            if self.writer.plan.complement is not None:
                needs.add(D)
        return needs

    def below_levels(self, levels: list[float]) -> list[Statement]:
        """``xp{j}`` = x below the j-th threshold of the polynomials, 0 above."""
        return [{"kind": "set", "name": f"xp{j}_lanes[k]",
                 "value": f"x < {self.printer.literal(level)} ? x : 0"} for j, level in enumerate(levels)]

    def scalar_pass(self, lanes: Lanes, inputs: list[sp.Symbol], below: float | None,
                    views: Views) -> list[Statement]:
        """x for every vector of the block, and the library calls for those inside the range
        (and at or above ``below``, where a closed form is used); the safe point elsewhere; and
        the lanes of :class:`Views`."""
        writer = self.writer
        needs = self.needs(lanes, inputs)
        inside: list[Statement] = []
        if D in needs:
            inside.append({"kind": "let", "type": self.t, "name": "d",
                           "value": f"{writer.complement_helper}(pk, x)"})
        if S in needs:
            inside.append({"kind": "let", "type": self.t, "name": "s", "value": f"sqrt{self.f}(x)"})
        if PHI_SYMBOL in needs:
            inside.append({"kind": "let", "type": self.t, "name": "phi", "value": writer.angle_call("s")})
        if HALF_LOW in needs:
            inside.append({"kind": "let", "type": self.t, "name": "half_low",
                           "value": writer.half_low_call("s", "phi")})
        inside += [writer.let(str(symbol), atom) for atom, symbol in lanes.atoms.items()]
        closed = [*(["xc"] if views.closed_x else []), *(str(symbol) for symbol in views.loaded)]
        inside += [{"kind": "set", "name": f"{name}_lanes[k]", "value": "x" if name == "xc" else name}
                   for name in closed]
        safe = [{"kind": "set", "name": f"{name}_lanes[k]",
                 "value": "x_safe" if name == "xc" else f"{name}_safe"} for name in closed]
        if views.guarded:
            assert views.smallest is not None
            smallest = self.printer.literal(views.smallest)
            inside += [{"kind": "set", "name": f"{symbol}_b_lanes[k]",
                        "value": f"x < {smallest} ? {symbol}_safe : {symbol}"} for symbol in views.guarded]
            safe += [{"kind": "set", "name": f"{symbol}_b_lanes[k]", "value": f"{symbol}_safe"}
                     for symbol in views.guarded]
        x = writer.c(LANE[0] ** 2 + LANE[1] ** 2 + LANE[2] ** 2)
        body: list[Statement] = [
            {"kind": "let", "type": f"{self.t} *const", "name": "pk", "value": "p + 3 * (start + k)"},
            {"kind": "let", "type": self.t, "name": "x", "value": x},
            {"kind": "set", "name": "x_lanes[k]", "value": "x"},
            *self.below_levels(views.levels),
        ]
        if inputs or views.closed_x:
            condition = writer.out_of_range()
            if below is not None:
                condition += f" || x < {self.printer.literal(below)}"
            body.append({"kind": "if", "condition": condition, "then": safe, "otherwise": inside})
        tail: list[Statement] = [{"kind": "set", "name": "x_lanes[k]", "value": "0"},
                                 *({"kind": "set", "name": f"xp{j}_lanes[k]", "value": "0"}
                                   for j in range(len(views.levels))), *safe]
        return [
            {"kind": "loop", "header": "k = 0; k < m; ++k", "times": 1, "body": body},
            {"kind": "loop", "header": f"; k < {BLOCK}; ++k", "times": 1, "body": tail},
        ]


__all__ = ["BLOCK", "DEFAULT_BLOCK", "BatchWriter"]
