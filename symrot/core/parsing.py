"""Safe parsing of untrusted generating-function expressions.

User strings never reach ``sympify``/``parse_expr`` (both evaluate Python). The text is parsed
by :func:`ast.parse` (which only builds a tree), every node is checked against a whitelist, and
the SymPy expression is built directly from the checked tree. Caps on length, depth, node count,
literal size and exponents keep both parsing and SymPy's automatic evaluation fast.

Every literal form counts towards the literal caps (decimal, hex, octal, binary, scientific).
Before SymPy builds a node, the size of that node *fully expanded* is estimated (see
:class:`Size`): the number of terms ``sympy.expand`` would produce, the combined exponent of
nested powers and the bit length of the numbers powers and products create. ``((1+phi)**64)**64``
or ``(10**30)**64`` are rejected here, before SymPy evaluates them or a later ``expand`` does.

Grammar: numbers, ``phi`` (or ``φ``), ``pi`` (or ``π``), ``+ - * / **`` (``^`` is accepted
as ``**``, with the same precedence), parentheses, and calls of one argument to the
functions in :data:`FUNCTIONS`.
``cbrt`` is the real (odd) cube root, see :mod:`symrot.core.functions`.
"""

from __future__ import annotations

import ast
import difflib
import importlib
import math
import unicodedata
from collections.abc import Callable, Iterable
from dataclasses import dataclass
from fractions import Fraction
from typing import Any

import sympy as sp
from sympy.core import random as sympy_random

from symrot.core.errors import ParseError
from symrot.core.functions import RealCbrt

DUMMY_BASE = 5_000_000
"""SymPy numbers its ``Dummy`` symbols from a base drawn at random per process; their hashes order
the sets its algorithms iterate, and so the forms they return. Fixed when symrot is imported, so
that equal input gives equal forms (with a fixed ``PYTHONHASHSEED``, see :mod:`symrot.entry`)."""
sp.Dummy._base_dummy_index = DUMMY_BASE
_SYMPY_ASSUMPTIONS: Any = importlib.import_module("sympy.core.assumptions")  # not sympy.core.assumptions()
_SYMPY_ASSUMPTIONS.shuffle = lambda facts: None
"""SymPy's assumptions system tries its facts in an order shuffled by a generator seeded from the OS
at import, and the order decides whether a sign query answers or gives up; so ``factor`` and
``cancel`` returned different sign arrangements in different processes (the base-angle reduction of
K₂ of sinh φ: −(2 sin(φ/2) cosh φ − sinh φ)/… or (−2 sin(φ/2) cosh φ + sinh φ)/…, complexity 17
or 18), and ``derive 'sinh(phi)' --emit numpy`` wrote one of two modules. SymPy shuffles only to
expose order-dependence in its own tests; symrot keeps the facts in their listed order."""
sympy_random.seed(0)
"""SymPy's other generator (numeric checks such as ``equals``; Wang's factorization) is seeded from
the OS too; :func:`symrot.core.timeouts.bounded` seeds it for its steps, this for the others."""

PHI = sp.Symbol("phi", real=True)
"""The rotation angle symbol used throughout symrot."""

MAX_LENGTH = 400
MAX_DEPTH = 32
MAX_FUNCTION_NESTING = 4
"""Functions applied to functions: tan nested 31 times ran into the 60 s budget in the series
engine and the validity analysis, and 5 levels still do (> 20 s CPU); the corpus needs 2."""
MAX_NODES = 160
MAX_LITERAL_DIGITS = 30
MAX_EXPONENT = 64
MAX_EXPONENT_DENOMINATOR = 64
MAX_LITERAL_BITS = 256
"""A literal's numerator and denominator have at most this many bits (about 77 digits)."""
MAX_NUMBER_BITS = 512
"""Numbers created by powers and products stay below 2**512 (floats reach 2**1024)."""
MAX_EXPANDED_TERMS = 5000
"""Terms ``sympy.expand`` would produce for one node (about 2 s of SymPy at this size)."""
MAX_DEGREE = 1024
"""Combined exponent of nested powers, e.g. ``(phi**64)**16``."""

FUNCTIONS: dict[str, Callable[[sp.Expr], sp.Expr]] = {
    "sin": sp.sin,
    "cos": sp.cos,
    "tan": sp.tan,
    "asin": sp.asin,
    "acos": sp.acos,
    "atan": sp.atan,
    "sinh": sp.sinh,
    "cosh": sp.cosh,
    "tanh": sp.tanh,
    "asinh": sp.asinh,
    "acosh": sp.acosh,
    "atanh": sp.atanh,
    "exp": sp.exp,
    "log": sp.log,
    "sqrt": sp.sqrt,
    "cbrt": RealCbrt,
}

_VARIABLES = {"phi": PHI, "φ": PHI}
_CONSTANTS = {"pi": sp.pi, "π": sp.pi}
_BINARY = (ast.Add, ast.Sub, ast.Mult, ast.Div, ast.Pow)


def parse_expression(text: object, extra_names: dict[str, sp.Expr] | None = None) -> sp.Expr:
    """Parse ``text`` into a SymPy expression in :data:`PHI`, or raise :class:`ParseError`.

    ``extra_names`` adds identifiers (e.g. ``nu``, ``mu`` in ``symrot solve`` properties).
    """
    if not isinstance(text, str):
        raise ParseError("expression must be a string")
    if len(text) > MAX_LENGTH:
        raise ParseError(f"expression is too long ({len(text)} characters, at most {MAX_LENGTH})")
    if "\x00" in text:
        raise ParseError("expression contains a NUL character")
    stripped = unicodedata.normalize("NFKC", text).strip()
    if not stripped:
        raise ParseError("expression is empty")
    if "\n" in stripped or "\r" in stripped or ";" in stripped:
        raise ParseError("expression must be a single line with a single expression")
    # '^' means power with the precedence of '**' (Python's XOR would bind looser than '+').
    # No string literals are allowed, so a textual replacement cannot change a literal.
    stripped = stripped.replace("^", "**")
    depth = _bracket_depth(stripped)
    if depth > MAX_DEPTH:
        raise ParseError(f"expression is nested too deeply (depth {depth}, at most {MAX_DEPTH})")
    try:
        tree = ast.parse(stripped, mode="eval")
    except (SyntaxError, ValueError, RecursionError, MemoryError) as exc:
        msg = exc.msg if isinstance(exc, SyntaxError) else type(exc).__name__
        raise ParseError(f"not a valid expression: {msg}") from None
    nodes = sum(1 for _ in ast.walk(tree))
    if nodes > MAX_NODES:
        raise ParseError(f"expression is too large ({nodes} syntax nodes, at most {MAX_NODES})")
    builder = _Builder(stripped, extra_names or {})
    expr, _ = builder.build(tree.body, 0)
    if expr.has(sp.zoo, sp.oo, -sp.oo, sp.nan):
        raise ParseError("expression evaluates to an infinity or NaN (division by zero?)")
    if expr.has(sp.I):
        raise ParseError("expression is not real")
    return expr


def _bracket_depth(text: str) -> int:
    depth = deepest = 0
    for ch in text:
        if ch in "([{":
            depth += 1
            deepest = max(deepest, depth)
        elif ch in ")]}":
            depth -= 1
    return deepest



def _did_you_mean(word: str, choices: Iterable[str]) -> str:
    """"; did you mean X?" for the closest of ``choices``, or ""."""
    close = difflib.get_close_matches(word[:40], list(choices), n=1, cutoff=0.6)
    return f"; did you mean {close[0]}?" if close else ""
@dataclass(frozen=True)
class Size:
    """An upper estimate of a node's size once fully expanded, computed before SymPy builds it.

    ``terms``: terms of ``sympy.expand`` (a product multiplies, a power n of t terms gives the
    multinomial count C(n + t - 1, t - 1)); ``degree``: the combined exponent of nested powers;
    ``bits``: the bit length of the largest number that products and powers create.
    """

    terms: int = 1
    degree: int = 0
    bits: int = 0

    def plus(self, other: Size) -> Size:
        return Size(self.terms + other.terms, max(self.degree, other.degree),
                    max(self.bits, other.bits) + 1)

    def times(self, other: Size) -> Size:
        return Size(self.terms * other.terms, self.degree + other.degree, self.bits + other.bits)

    def power(self, exponent: sp.Rational) -> Size:
        magnitude = abs(exponent)
        whole = int(magnitude)  # expand multiplies out the integer part only
        terms = math.comb(whole + self.terms - 1, self.terms - 1) if whole else 1
        multinomial_bits = math.ceil(whole * math.log2(self.terms)) if self.terms > 1 else 0
        return Size(min(terms, MAX_EXPANDED_TERMS + 1), math.ceil(self.degree * magnitude),
                    math.ceil(self.bits * magnitude) + multinomial_bits)

    def check(self) -> Size:
        """Raise :class:`ParseError` when the estimate exceeds a cap; else return self."""
        if self.terms > MAX_EXPANDED_TERMS:
            raise ParseError(f"expression expands to too many terms (more than {MAX_EXPANDED_TERMS})")
        if self.degree > MAX_DEGREE:
            raise ParseError(f"powers combine to a degree above {MAX_DEGREE} ({self.degree})")
        if self.bits > MAX_NUMBER_BITS:
            raise ParseError(f"expression creates a number beyond 2**{MAX_NUMBER_BITS} "
                             f"(about {self.bits} bits)")
        return self


_ATOM = Size(1, 1, 0)


class _Builder:
    """Turns a whitelisted AST into SymPy, rejecting everything else with a clear message."""

    def __init__(self, source: str, extra_names: dict[str, sp.Expr]) -> None:
        self.source = source
        self.extra_names = extra_names
        self.calls = 0
        """Function calls enclosing the node being built."""

    def build(self, node: ast.AST, depth: int) -> tuple[sp.Expr, Size]:
        """The SymPy expression of ``node`` and its expanded :class:`Size` (checked)."""
        if depth > MAX_DEPTH:
            raise ParseError(f"expression is nested too deeply (more than {MAX_DEPTH} levels)")
        if isinstance(node, ast.Constant):
            return self._number(node)
        if isinstance(node, ast.Name):
            return self._name(node), _ATOM
        if isinstance(node, ast.UnaryOp) and isinstance(node.op, ast.UAdd | ast.USub):
            operand, size = self.build(node.operand, depth + 1)
            return (-operand if isinstance(node.op, ast.USub) else operand), size
        if isinstance(node, ast.BinOp) and isinstance(node.op, _BINARY):
            return self._binary(node, depth)
        if isinstance(node, ast.Call):
            return self._call(node, depth)
        raise ParseError(f"'{_describe(node)}' is not allowed in an expression")

    def _number(self, node: ast.Constant) -> tuple[sp.Expr, Size]:
        value = node.value
        if isinstance(value, bool) or not isinstance(value, int | float):
            raise ParseError(f"literal {value!r} is not a real number")
        literal = ast.get_source_segment(self.source, node) or repr(value)
        if any(ch in literal for ch in "jJ"):
            raise ParseError("complex literals are not allowed")
        if _literal_digits(literal) > MAX_LITERAL_DIGITS:
            raise ParseError(f"number literal has too many digits (at most {MAX_LITERAL_DIGITS})")
        if isinstance(value, int):
            exact = Fraction(value)
        else:
            _, _, exponent = literal.lower().replace("_", "").partition("e")
            if exponent and (not exponent.lstrip("+-").isdigit() or abs(int(exponent)) > 400):
                raise ParseError(f"number literal {literal[:40]!r} is out of range")
            try:
                exact = Fraction(literal.replace("_", ""))
            except (ValueError, ZeroDivisionError):
                raise ParseError(f"number literal {literal[:40]!r} is not valid") from None
        bits = max(abs(exact.numerator).bit_length(), exact.denominator.bit_length())
        if bits > MAX_LITERAL_BITS:
            raise ParseError(f"number literal {literal[:40]!r} is out of range "
                             f"(at most {MAX_LITERAL_BITS} bits)")
        return sp.Rational(exact.numerator, exact.denominator), Size(1, 0, bits)

    def _name(self, node: ast.Name) -> sp.Expr:
        if node.id in _VARIABLES:
            return _VARIABLES[node.id]
        if node.id in _CONSTANTS:
            return _CONSTANTS[node.id]
        if node.id in self.extra_names:
            return self.extra_names[node.id]
        if node.id in FUNCTIONS:
            raise ParseError(f"function '{node.id}' must be called with one argument")
        names = sorted(_VARIABLES) + sorted(_CONSTANTS) + sorted(self.extra_names)
        raise ParseError(f"unknown name '{node.id[:40]}'{_did_you_mean(node.id, names)} "
                         f"(allowed names: {', '.join(names)})")

    def _binary(self, node: ast.BinOp, depth: int) -> tuple[sp.Expr, Size]:
        left, left_size = self.build(node.left, depth + 1)
        right, right_size = self.build(node.right, depth + 1)
        if isinstance(node.op, ast.Add | ast.Sub):
            size = left_size.plus(right_size).check()
            return (left + right if isinstance(node.op, ast.Add) else left - right), size
        if isinstance(node.op, ast.Mult):
            return left * right, left_size.times(right_size).check()
        if isinstance(node.op, ast.Div):
            if right.is_zero:
                raise ParseError("division by zero")
            return left / right, left_size.times(right_size).check()
        exponent = self._exponent(right)
        return self._power(left, exponent, left_size.power(exponent).check())

    @staticmethod
    def _exponent(exponent: sp.Expr) -> sp.Rational:
        if exponent.has(PHI) or not exponent.is_Rational:
            raise ParseError("exponents must be rational constants such as 2, -1 or 1/3")
        exp_rational = sp.Rational(exponent)
        if abs(exp_rational.p) > MAX_EXPONENT * exp_rational.q:
            raise ParseError(f"exponent {exp_rational} is too large (|exponent| <= {MAX_EXPONENT})")
        if exp_rational.q > MAX_EXPONENT_DENOMINATOR:
            raise ParseError(f"exponent {exp_rational} has too large a denominator")
        return exp_rational

    @staticmethod
    def _power(base: sp.Expr, exp_rational: sp.Rational, size: Size) -> tuple[sp.Expr, Size]:
        if base.is_zero and exp_rational.is_negative:
            raise ParseError("division by zero")
        if base.is_Number and base.is_negative and exp_rational.q != 1:
            raise ParseError("a fractional power of a negative number is not real (use cbrt)")
        return sp.Pow(base, exp_rational), size

    def _call(self, node: ast.Call, depth: int) -> tuple[sp.Expr, Size]:
        if not isinstance(node.func, ast.Name):
            raise ParseError(f"'{_describe(node.func)}' cannot be called")
        name = node.func.id
        if name not in FUNCTIONS:
            allowed = ", ".join(FUNCTIONS)
            raise ParseError(f"unknown function '{name[:40]}'{_did_you_mean(name, FUNCTIONS)} "
                             f"(allowed: {allowed})")
        if node.keywords or len(node.args) != 1 or isinstance(node.args[0], ast.Starred):
            raise ParseError(f"function '{name}' takes exactly one argument")
        self.calls += 1
        if self.calls > MAX_FUNCTION_NESTING:
            raise ParseError(f"functions are nested more than {MAX_FUNCTION_NESTING} deep "
                             f"(e.g. {name}({name}(...))): their derivation would not end within a budget")
        argument, size = self.build(node.args[0], depth + 1)
        self.calls -= 1
        if name in _ROOTS:  # a power in SymPy: numbers and polynomials inside keep their size
            return FUNCTIONS[name](argument), size.power(_ROOTS[name]).check()
        return FUNCTIONS[name](argument), _ATOM


_ROOTS = {"sqrt": sp.Rational(1, 2), "cbrt": sp.Rational(1, 3)}

_FUNCTION_CLASSES: dict[type, str] = {
    function: name for name, function in FUNCTIONS.items() if isinstance(function, type)
}
"""The SymPy classes of the grammar's functions (``sqrt`` is a power in SymPy)."""
_SYMPY_CONSTANTS = (sp.pi, sp.E)
"""π, and e (``exp(1)`` evaluates to it)."""


def check_expression(expr: object) -> sp.Expr:
    """A SymPy expression given to the API, held to the caps of a parsed string: the grammar's
    operations, functions and constants only, rational exponents, finite real numbers below
    2**MAX_NUMBER_BITS, at most MAX_NODES nodes and MAX_DEPTH levels, and an expanded size within
    :class:`Size`'s caps. Raises :class:`ParseError`; returns ``expr``.

    ``sp.Integer(10)**10000 * phi`` was derived and then failed with Python's ValueError when its
    result was printed (more than 4300 digits); ``sp.Float('1e400') * phi`` gave infinite kernels.
    Symbols other than :data:`PHI` are left to :func:`symrot.core.validation.validate`'s message.
    """
    if not isinstance(expr, sp.Expr):
        raise ParseError(f"expression must be a string or a SymPy expression, got {type(expr).__name__}")
    for nodes, _ in enumerate(sp.preorder_traversal(expr), start=1):
        if nodes > MAX_NODES:
            raise ParseError(f"expression is too large (more than {MAX_NODES} nodes)")
    _ExpressionCheck().size(expr, 0)
    return expr


class _ExpressionCheck:
    """The :class:`Size` of a SymPy expression, checked node by node as :class:`_Builder` does."""

    def __init__(self) -> None:
        self.calls = 0

    def size(self, expr: sp.Basic, depth: int) -> Size:
        if depth > MAX_DEPTH:
            raise ParseError(f"expression is nested too deeply (more than {MAX_DEPTH} levels)")
        if expr.is_Symbol or expr in _SYMPY_CONSTANTS:
            return _ATOM
        if expr.is_Number:
            return Size(1, 0, _number_bits(expr))
        if isinstance(expr, sp.Add):
            total = self.size(expr.args[0], depth + 1)
            for arg in expr.args[1:]:
                total = total.plus(self.size(arg, depth + 1)).check()
            return total
        if isinstance(expr, sp.Mul):
            total = self.size(expr.args[0], depth + 1)
            for arg in expr.args[1:]:
                total = total.times(self.size(arg, depth + 1)).check()
            return total
        if isinstance(expr, sp.Pow):
            base, exponent = expr.args
            return self.size(base, depth + 1).power(_Builder._exponent(exponent)).check()
        name = _FUNCTION_CLASSES.get(type(expr))
        if name is None:
            if expr.is_number and expr.has(sp.I):
                raise ParseError("expression is not real")
            raise ParseError(f"'{type(expr).__name__}' is not allowed in an expression "
                             f"(allowed functions: {', '.join(FUNCTIONS)}; constants: pi, E)")
        if len(expr.args) != 1:
            raise ParseError(f"function '{name}' takes exactly one argument")
        self.calls += 1
        if self.calls > MAX_FUNCTION_NESTING:
            raise ParseError(f"functions are nested more than {MAX_FUNCTION_NESTING} deep")
        inner = self.size(expr.args[0], depth + 1)
        self.calls -= 1
        return inner.power(_ROOTS[name]).check() if name in _ROOTS else _ATOM


def _number_bits(number: sp.Basic) -> int:
    """Bits of a finite real SymPy number (numerator or denominator; a float's magnitude)."""
    if number.is_Rational:
        rational = sp.Rational(number)
        bits = max(abs(rational.p).bit_length(), rational.q.bit_length())
    elif number.is_Float and number.is_finite:
        _, _, exponent, mantissa_bits = sp.Float(number)._mpf_  # |value| < 2**(exponent + bits)
        bits = 0 if number.is_zero else abs(int(exponent) + int(mantissa_bits)) + 1
    else:
        raise ParseError(f"number {str(number)[:40]} is not a finite real number")
    if bits > MAX_NUMBER_BITS:
        raise ParseError(f"number {str(number)[:40] if bits < 10_000 else '(too long)'} is out of range "
                         f"(at most {MAX_NUMBER_BITS} bits)")
    return bits


_BASES = {"0x": 16, "0o": 8, "0b": 2}


def _literal_digits(literal: str) -> int:
    """Decimal digits a literal stands for: a hex, octal or binary literal counts its digits
    times log10 of its base (hex letters included); a decimal one its mantissa digits."""
    text = literal.lower().replace("_", "")
    if text[:2] in _BASES:
        return math.ceil((len(text) - 2) * math.log10(_BASES[text[:2]]))
    mantissa = text.partition("e")[0]
    return sum(ch.isdigit() for ch in mantissa)


def _describe(node: ast.AST) -> str:
    names = {
        ast.Attribute: "attribute access",
        ast.Subscript: "subscript",
        ast.Lambda: "lambda",
        ast.Compare: "comparison",
        ast.BoolOp: "boolean operator",
        ast.IfExp: "conditional expression",
        ast.NamedExpr: "assignment expression",
        ast.JoinedStr: "f-string",
        ast.List: "list",
        ast.Tuple: "tuple",
        ast.Dict: "dict",
        ast.Set: "set",
        ast.ListComp: "comprehension",
        ast.GeneratorExp: "generator",
        ast.Await: "await",
        ast.Yield: "yield",
        ast.Starred: "starred argument",
    }
    for cls, label in names.items():
        if isinstance(node, cls):
            return label
    if isinstance(node, ast.BinOp | ast.UnaryOp):
        return f"operator {type(node.op).__name__}"
    return type(node).__name__
