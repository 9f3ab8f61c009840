"""A small reader of the LaTeX math that symrot typesets, into functions of φ evaluated in mpmath.

Independent of SymPy and of symrot's printer: a tokenizer and a recursive-descent parser of the
subset the sheets and Table 1 use (numbers, ``\\varphi``, ``\\pi``, ``x``, ``+ -``, products by
juxtaposition, slashes, ``\\frac``, ``\\sqrt``, ``\\sqrt[3]``, powers ``^{…}``, parentheses and
``\\left( … \\right)``, and functions with an optional power, ``\\cos^{2}(\\varphi/2)``). Anything
else, and anything whose reading would be ambiguous (``a/b c``, ``\\sin \\varphi^{2}``), raises
:class:`LatexSyntaxError`, so a test never skips what it cannot read.

Precedence, as the printer writes it: a slash divides the whole product before it by the single
factor after it (``\\varphi \\sin \\varphi/\\left(2 - 2 \\cos \\varphi\\right)``); a leading sign
applies to the term after it.
"""

from __future__ import annotations

import re
from collections.abc import Callable

import mpmath

Value = Callable[[mpmath.mpf], mpmath.mpf]
"""A parsed formula: φ (or x, for the series) ↦ its value at the working precision."""


class LatexSyntaxError(ValueError):
    """The text is outside the subset this reader knows, or ambiguous in it."""


def _real_root(x: mpmath.mpf, n: int) -> mpmath.mpf:
    if n == 2:
        return mpmath.sqrt(x)
    if n % 2:
        return mpmath.sign(x) * mpmath.root(abs(x), n)
    return mpmath.root(x, n)


FUNCTIONS: dict[str, Callable[[mpmath.mpf], mpmath.mpf]] = {
    "sin": mpmath.sin, "cos": mpmath.cos, "tan": mpmath.tan, "sinh": mpmath.sinh,
    "cosh": mpmath.cosh, "tanh": mpmath.tanh, "arcsin": mpmath.asin, "arccos": mpmath.acos,
    "arctan": mpmath.atan, "asin": mpmath.asin, "acos": mpmath.acos, "atan": mpmath.atan,
    "asinh": mpmath.asinh, "acosh": mpmath.acosh, "atanh": mpmath.atanh, "exp": mpmath.exp,
    "log": mpmath.log, "ln": mpmath.log,
}
"""``\\sin`` … and ``\\operatorname{atan}`` …: every function name the reader accepts."""
CONSTANTS: dict[str, Callable[[], mpmath.mpf]] = {"pi": lambda: +mpmath.pi}
IGNORED = {r"\displaystyle", r"\,", r"\;", r"\:", r"\!", r"\ "}
TOKEN = re.compile(r"\s*(\\[A-Za-z]+|\\.|\d+(?:\.\d+)?|[A-Za-z]|[{}()\[\]^/+\-])")


def tokenize(text: str) -> list[str]:
    """The tokens of ``text`` (commands, numbers, letters, brackets, operators), spacing dropped."""
    tokens: list[str] = []
    position = 0
    text = text.rstrip()
    while position < len(text):
        match = TOKEN.match(text, position)
        if match is None:
            raise LatexSyntaxError(f"unexpected {text[position:position + 20]!r} in {text!r}")
        position = match.end()
        if match.group(1) not in IGNORED:
            tokens.append(match.group(1))
    return tokens


class _Parser:
    """Recursive descent over the tokens; each rule returns a :data:`Value`."""

    def __init__(self, text: str, variable: str) -> None:
        self.text = text
        self.tokens = tokenize(text)
        self.index = 0
        self.variable = variable

    def peek(self) -> str | None:
        return self.tokens[self.index] if self.index < len(self.tokens) else None

    def take(self, expected: str | None = None) -> str:
        token = self.peek()
        if token is None or (expected is not None and token != expected):
            raise LatexSyntaxError(f"expected {expected or 'more'}, found {token!r} at token "
                                   f"{self.index} of {self.text!r}")
        self.index += 1
        return token

    def fail(self, what: str) -> LatexSyntaxError:
        return LatexSyntaxError(f"{what} at token {self.index} ({self.peek()!r}) of {self.text!r}")

    def whole(self) -> Value:
        value = self.expression()
        if self.peek() is not None:
            raise self.fail("unexpected trailing token")
        return value

    def expression(self) -> Value:
        """[sign] term (± term)*."""
        sign = -1 if self.peek() == "-" else 1
        if self.peek() in ("+", "-"):
            self.take()
        terms: list[tuple[int, Value]] = [(sign, self.term())]
        while self.peek() in ("+", "-"):
            terms.append((-1 if self.take() == "-" else 1, self.term()))
        return lambda x: mpmath.fsum(s * t(x) for s, t in terms)

    def starts_factor(self) -> bool:
        token = self.peek()
        return token is not None and (token[0].isdigit() or token in ("(", "{", self.variable)
                                      or (token.startswith("\\") and token != r"\right"))

    def term(self) -> Value:
        """A product by juxtaposition, then any number of ``/ factor`` (one factor each)."""
        factors = [self.power()]
        while self.starts_factor():
            factors.append(self.power())
        divisors: list[Value] = []
        while self.peek() == "/":
            self.take()
            divisors.append(self.power())
            if self.starts_factor():
                raise self.fail("ambiguous juxtaposition after a slash")
        return lambda x: mpmath.fprod(f(x) for f in factors) / mpmath.fprod(d(x) for d in divisors)

    def power(self) -> Value:
        base, applied = self.atom()
        if self.peek() != "^":
            return base
        if applied:
            raise self.fail("ambiguous power after a function's argument")
        self.take("^")
        exponent = self.group()
        return lambda x: base(x) ** exponent(x)

    def group(self) -> Value:
        self.take("{")
        value = self.expression()
        self.take("}")
        return value

    def parenthesized(self) -> Value:
        """``( … )`` or ``\\left( … \\right)``."""
        if self.peek() == r"\left":
            self.take()
            self.take("(")
            value = self.expression()
            self.take(r"\right")
            self.take(")")
            return value
        self.take("(")
        value = self.expression()
        self.take(")")
        return value

    def atom(self) -> tuple[Value, bool]:
        """An atom, and whether it is a function applied to an argument."""
        token = self.peek()
        if token is None:
            raise self.fail("expected an operand")
        if token[0].isdigit():
            self.take()
            number = mpmath.mpf(token)
            return (lambda x: number), False
        if token == self.variable:
            self.take()
            return (lambda x: x), False
        if token in ("(", r"\left"):
            return self.parenthesized(), False
        if token == "{":
            return self.group(), False
        if token == r"\frac":
            self.take()
            top, bottom = self.group(), self.group()
            return (lambda x: top(x) / bottom(x)), False
        if token == r"\sqrt":
            return self.root(), False
        if token.startswith("\\") and token[1:] in CONSTANTS:
            self.take()
            constant = CONSTANTS[token[1:]]
            return (lambda x: constant()), False
        return self.function(), True

    def root(self) -> Value:
        self.take(r"\sqrt")
        degree = 2
        if self.peek() == "[":
            self.take("[")
            text = self.take()
            if not text.isdigit():
                raise self.fail("a root's degree must be an integer")
            degree = int(text)
            self.take("]")
        radicand = self.group()
        return lambda x: _real_root(radicand(x), degree)

    def function(self) -> Value:
        """``\\name`` or ``\\operatorname{name}``, ``^{k}`` optionally, then its argument."""
        token = self.take()
        if token == r"\operatorname":
            self.take("{")
            name = ""
            while self.peek() != "}":
                name += self.take()
            self.take("}")
        elif token.startswith("\\"):
            name = token[1:]
        else:
            raise LatexSyntaxError(f"unknown token {token!r} in {self.text!r}")
        if name not in FUNCTIONS:
            raise LatexSyntaxError(f"unknown command or function {token!r} ({name}) in {self.text!r}")
        function = FUNCTIONS[name]
        exponent: Value = lambda x: mpmath.mpf(1)  # noqa: E731
        if self.peek() == "^":
            self.take()
            exponent = self.group()
        argument = self.argument()
        return lambda x: function(argument(x)) ** exponent(x)

    def argument(self) -> Value:
        """A braced group, a parenthesized group, a ``\\frac`` or a single symbol or number."""
        token = self.peek()
        if token == "{":
            return self.group()
        if token in ("(", r"\left"):
            return self.parenthesized()
        if token == r"\frac" or token == self.variable or (token is not None and (
                token[0].isdigit() or (token.startswith("\\") and token[1:] in CONSTANTS))):
            value, _ = self.atom()
            return value
        raise self.fail("expected a function argument")


def read(text: str, variable: str = r"\varphi") -> Value:
    """``text`` (LaTeX math of the subset above) as a function of ``variable`` (``\\varphi``, ``x``)."""
    return _Parser(text, variable).whole()
