"""C99 printing of plan expressions, for ``double`` and for ``float``.

A subclass of SymPy's :class:`~sympy.printing.c.C99CodePrinter` that overrides only what differs
from what the C backend needs:

* **precision**: the float variant uses SymPy's own ``type_aliases`` machinery (``sinf``, ``sqrtf``,
  ``1.0F`` literals); nothing else is hand-written for it;
* :class:`~symrot.core.functions.RealCbrt` prints as ``cbrt``/``cbrtf`` (the real cube root, which is
  what C's ``cbrt`` computes);
* small integer powers of a symbol print as parenthesized products (``(x*x*x)``, ``1.0/(x*x)``),
  not ``pow``;
* numbers are **correctly rounded** to the target type: a rational whose numerator and denominator
  are exact in the type stays a quotient of two literals (IEEE division rounds it once), a larger
  one and every float constant print as the shortest literal that reads back as the correctly
  rounded value (SymPy's default prints 17 or 9 decimal digits, which rounds twice);
* no ``M_PI``-style macros: they are POSIX, not C99, and ``-std=c99 -Wpedantic`` rejects them;
* **every literal finite**: a number that rounds to ±inf or NaN in the type (e.g. a Horner
  coefficient 1e39 in float) raises :class:`~symrot.core.errors.NonFiniteLiteral` (a one-line
  :class:`~symrot.core.errors.SymrotError`) instead of printing ``inf.0F``, which no compiler accepts.
"""

from __future__ import annotations

from typing import Any, Literal

import mpmath
import numpy as np
import sympy as sp
from sympy.codegen.ast import float32, float64, real
from sympy.printing.c import C99CodePrinter

from symrot.core.errors import NonFiniteLiteral
from symrot.plan.ir import nearest_binary

Precision = Literal["double", "float"]
PRECISIONS: tuple[Precision, ...] = ("double", "float")
MANTISSA_BITS = {"double": 53, "float": 24}
LARGEST = {"double": mpmath.mpf(float(np.finfo(np.float64).max)),
           "float": mpmath.mpf(float(np.finfo(np.float32).max))}
"""The largest finite value of each type: a literal rounded beyond it would be ``inf``."""
MAX_EXPANDED_POWER = 4
"""x**n with a symbol x and 2 ≤ |n| ≤ this prints as a product instead of ``pow``."""


class SymrotCPrinter(C99CodePrinter):
    """C99 printer for one precision (``"double"`` or ``"float"``)."""

    def __init__(self, precision: Precision = "double", settings: dict[str, Any] | None = None) -> None:
        if precision not in MANTISSA_BITS:
            raise ValueError(f"unknown precision {precision!r}")
        self.precision: Precision = precision
        base: dict[str, Any] = {
            "type_aliases": {real: float32 if precision == "float" else float64},
            "math_macros": {},
            "inline": True,
        }
        super().__init__({**base, **(settings or {})})

    # -- numbers ---------------------------------------------------------------------------------
    def literal(self, value: sp.Expr | float | int) -> str:
        """The shortest C literal that reads back as ``value`` correctly rounded to the type."""
        bits = MANTISSA_BITS[self.precision]
        number = sp.sympify(value)
        if number.is_Rational:
            rounded = nearest_binary(number, bits)
        else:
            with mpmath.workprec(bits):
                rounded = +sp.Float(number, 70)._to_mpmath(240)
        if not mpmath.isfinite(rounded) or abs(rounded) > LARGEST[self.precision]:
            raise NonFiniteLiteral(f"the constant {sp.Float(number, 8)} is not finite in C {self.precision} "
                                   f"(largest {float(LARGEST[self.precision]):.8g}): it cannot be printed")
        if self.precision == "float":
            text, suffix = str(np.float32(float(rounded))), self._get_literal_suffix(real)
        else:
            text, suffix = repr(float(rounded)), ""
        if "e" not in text and "." not in text:
            text += ".0"
        return text + suffix

    def _exact_in_type(self, integer: int) -> bool:
        return abs(integer) <= 2 ** MANTISSA_BITS[self.precision]

    def _print_Rational(self, expr: sp.Rational) -> str:
        if self._exact_in_type(int(expr.p)) and self._exact_in_type(int(expr.q)):
            return str(super()._print_Rational(expr))
        return self.literal(expr)

    def _print_Integer(self, expr: sp.Integer) -> str:
        # an int constant only where the type holds it exactly: -42181425 in float code is rounded
        # by the compiler and rejected by -Wfloat-conversion (a Horner coefficient of phi + phi**3)
        if abs(int(expr)) < 2**31 and self._exact_in_type(int(expr)):
            return str(super()._print_Integer(expr))
        return self.literal(expr)

    def _print_Float(self, flt: sp.Float) -> str:
        return self.literal(flt)

    def _refuse(self, expr: sp.Expr) -> str:
        raise NonFiniteLiteral(f"the constant {expr} is not finite in C {self.precision}: "
                               "it cannot be printed")

    _print_Infinity = _print_NegativeInfinity = _print_ComplexInfinity = _print_NaN = _refuse

    def _print_NumberSymbol(self, expr: sp.Expr) -> str:
        return self.literal(expr)

    def _print_Exp1(self, expr: sp.Expr) -> str:
        return self.literal(expr)

    def _print_Pi(self, expr: sp.Expr) -> str:
        return self.literal(expr)

    # -- functions -------------------------------------------------------------------------------
    def _print_sign(self, expr: sp.Expr) -> str:
        """sign(v) in the real type (NaN for NaN, as NumPy's): C99CodePrinter's ``((v > 0) - (v < 0))``
        is an int, which -Wconversion rejects in float code."""
        argument = self._print(expr.args[0])
        zero, one = self.literal(0), self.literal(1)
        return f"(({argument}) > {zero} ? {one} : (({argument}) < {zero} ? -{one} : ({argument}) * {zero}))"

    def _print_RealCbrt(self, expr: sp.Expr) -> str:
        return f"cbrt{self._get_func_suffix(real)}({self._print(expr.args[0])})"

    def _print_Pow(self, expr: sp.Pow) -> str:
        base, exponent = expr.base, expr.exp
        if base.is_Symbol and exponent.is_Integer and 2 <= abs(int(exponent)) <= MAX_EXPANDED_POWER:
            product = "(" + "*".join([self._print(base)] * abs(int(exponent))) + ")"
            if exponent > 0:  # parenthesized: a/x**2 must print as a/(x*x), not a/x*x
                return product
            return f"{self._print_Float(sp.Float(1))}/{product}"
        if exponent == sp.Rational(-1, 2):
            suffix = self._get_func_suffix(real)
            return f"{self._print_Float(sp.Float(1))}/sqrt{suffix}({self._print(base)})"
        return str(super()._print_Pow(expr))

    def _print_BoundedPower(self, expr: sp.Expr) -> str:
        """(b)**n of :class:`symrot.core.functions.BoundedPower`: the base once, or a product of its
        copies (which the compiler computes once) up to :data:`MAX_EXPANDED_POWER`."""
        base, exponent = expr.args
        text = f"({self._print(base)})"
        if int(exponent) <= MAX_EXPANDED_POWER:
            return "(" + "*".join([text] * int(exponent)) + ")" if exponent > 1 else text
        return f"pow{self._get_func_suffix(real)}({self._print(base)}, {self._print(exponent)})"


def horner(coefficients: tuple[sp.Expr, ...], variable: sp.Symbol) -> sp.Expr:
    """Σ coefficients[j] variable^j in Horner order, unevaluated so that it prints as nested."""
    result: sp.Expr = sp.sympify(coefficients[-1])
    for c in reversed(coefficients[:-1]):
        product = sp.Mul(variable, result, evaluate=False)
        result = product if c == 0 else sp.Add(c, product, evaluate=False)
    return result


def print_c(expr: sp.Expr, precision: Precision = "double") -> str:
    """``expr`` as a C99 expression in ``precision``."""
    return str(SymrotCPrinter(precision).doprint(expr))


__all__ = ["PRECISIONS", "Precision", "SymrotCPrinter", "horner", "print_c"]
