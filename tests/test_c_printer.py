"""The C99 printer subclass: only what differs from SymPy's C99CodePrinter."""

from __future__ import annotations

import re
import shutil
from fractions import Fraction
from pathlib import Path

import numpy as np
import pytest
import sympy as sp
from hypothesis import given, settings
from hypothesis import strategies as st

from symrot.backends.c_printer import SymrotCPrinter, print_c
from symrot.core.functions import RealCbrt

X, Y = sp.symbols("x y", real=True)


def literal_value(text: str, precision: str) -> Fraction:
    """The exact value a C compiler gives the literal ``text``."""
    if precision == "float":
        assert text.endswith("F"), text
        return Fraction(float(np.float32(text[:-1])))
    assert not text.endswith(("F", "f", "L")), text
    return Fraction(float(text))


def is_correctly_rounded(value: Fraction, exact: Fraction, precision: str) -> bool:
    """|value − exact| ≤ half an ulp of value's binade (ties checked by the exact comparison)."""
    bits = 53 if precision == "double" else 24
    if exact == 0:
        return value == 0
    exponent = Fraction(2) ** (abs(exact).numerator.bit_length() - abs(exact).denominator.bit_length())
    while exponent > abs(exact):
        exponent /= 2
    while exponent * 2 <= abs(exact):
        exponent *= 2
    half_ulp = exponent / 2**bits
    return abs(value - exact) <= half_ulp


@settings(max_examples=200, deadline=None)
@given(st.integers(-(2**90), 2**90), st.integers(1, 2**90), st.sampled_from(["double", "float"]))
def test_rational_literals_are_correctly_rounded(numerator: int, denominator: int, precision: str) -> None:
    exact = Fraction(numerator, denominator)
    printer = SymrotCPrinter(precision)
    text = printer.doprint(sp.Rational(numerator, denominator))
    if re.fullmatch(r"-?\d+", text):  # a C int constant: converted exactly
        assert exact.denominator == 1 and abs(exact) < 2**31 and int(text) == exact
    elif "/" in text:  # a quotient of two exact literals, rounded once by IEEE division
        num_text, den_text = text.strip("()").split("/")
        num, den = literal_value(num_text, precision), literal_value(den_text, precision)
        assert (num, den) == (exact.numerator, exact.denominator)
    else:
        assert is_correctly_rounded(literal_value(text, precision), exact, precision), text


def test_large_rational_is_one_literal_not_an_inexact_quotient() -> None:
    big = sp.Rational(2**60 + 1, 3**40)
    assert "/" not in print_c(big, "double")
    assert is_correctly_rounded(literal_value(print_c(big, "double"), "double"),
                                Fraction(2**60 + 1, 3**40), "double")
    assert print_c(sp.Rational(1, 7), "double") == "1.0/7.0"
    assert print_c(sp.Rational(1, 7), "float") == "1.0F/7.0F"
    assert print_c(sp.Rational(2**30 + 1, 7), "float") != "1073741825.0F/7.0F"


@pytest.mark.parametrize("precision", ["double", "float"])
def test_pi_is_a_correctly_rounded_literal_not_a_posix_macro(precision: str) -> None:
    text = print_c(sp.pi * X, precision)
    assert "M_PI" not in text
    number = text.split("*")[0]
    assert is_correctly_rounded(literal_value(number, precision),
                                Fraction(sp.Rational(sp.N(sp.pi, 60))), precision)


def test_real_cube_root_prints_as_cbrt() -> None:
    assert print_c(RealCbrt(X - Y), "double") == "cbrt(x - y)"
    assert print_c(RealCbrt(X - Y), "float") == "cbrtf(x - y)"


def test_small_integer_powers_of_a_symbol_are_parenthesized_products() -> None:
    assert print_c(X**2, "double") == "(x*x)"
    assert print_c(X**4 * Y, "double") == "(x*x*x*x)*y"
    assert print_c(Y / X**2, "double") == "y/(x*x)"
    assert print_c(X**-3, "double") == "1.0/(x*x*x)"
    assert print_c(X**-2, "float") == "1.0F/(x*x)"
    assert print_c(X**9, "double") == "pow(x, 9)"
    assert print_c((X + Y) ** 2, "double") == "pow(x + y, 2)"
    assert print_c(1 / sp.sqrt(X), "float") == "1.0F/sqrtf(x)"


def test_float_variant_calls_only_float_functions_and_float_literals() -> None:
    expr = sp.sin(X) / 3 + sp.cos(Y) + sp.atan2(Y, X) + sp.sqrt(X) + sp.tan(X) + sp.Abs(Y) + sp.Float("0.1")
    text = print_c(expr, "float")
    for name in ("sin", "cos", "atan2", "sqrt", "tan", "fabs"):
        assert f"{name}f(" in text
        assert not re.search(rf"\b{name}\(", text), text
    literals = re.findall(r"\d+\.\d*(?:e[-+]?\d+)?[Ff]?", text)
    assert literals and all(lit.endswith("F") for lit in literals), literals
    double_text = print_c(expr, "double")
    assert "F" not in double_text and "sinf" not in double_text


def test_unknown_precision_is_rejected() -> None:
    with pytest.raises(ValueError, match="precision"):
        SymrotCPrinter("half")  # type: ignore[arg-type]


NON_FINITE = [(sp.Float("1.1253368e42"), "float"), (sp.Integer(10) ** 39, "float"),
              (sp.Float("1e309"), "double"),
              (-sp.Integer(2) ** 1024, "double"), (sp.oo, "double"), (sp.nan, "float")]


@pytest.mark.parametrize(("value", "precision"), NON_FINITE)
def test_non_finite_literal_is_refused_in_one_line(value: sp.Expr, precision: str) -> None:
    """A constant that is ±inf or NaN in the type would print as ``inf.0F`` (gcc: 'inf' undeclared):
    a SymrotError (exit 2 at the CLI) naming the constant and the type instead."""
    from symrot.core.errors import NonFiniteLiteral, SymrotError

    with pytest.raises(NonFiniteLiteral) as caught:
        print_c(value * X, precision)  # type: ignore[arg-type]
    assert isinstance(caught.value, SymrotError)
    message = str(caught.value)
    assert "\n" not in message and precision in message and "not finite" in message
    assert print_c(sp.Float("3.4028234e38") * X, "float").startswith("3.4028235e+38F")  # largest float


@pytest.mark.skipif(shutil.which("gcc") is None, reason="gcc not installed")
def test_sign_is_real_typed_and_compiles_strictly(tmp_path: Path) -> None:
    """sign appears in derived slopes (asinh(tan(φ))); SymPy's C form is an int, which
    -Wconversion rejects in float code. Values: ±1, 0 at ±0, NaN for NaN (as NumPy's sign)."""
    import ctypes
    import subprocess

    from .c_harness import STRICT_C

    v = sp.Symbol("v", real=True)
    lines = []
    for precision, t in (("double", "double"), ("float", "float")):
        body = SymrotCPrinter(precision).doprint(sp.sign(v))
        lines.append(f"{t} sign_{precision}({t} v) {{ return {body}; }}")
    source = tmp_path / "sign.c"
    source.write_text("\n".join(lines) + "\n", encoding="utf-8")
    library = tmp_path / "sign.so"
    command = ["gcc", *STRICT_C, "-fPIC", "-shared", str(source), "-o", str(library)]
    result = subprocess.run(command, capture_output=True, text=True, check=False)
    assert result.returncode == 0, result.stderr
    loaded = ctypes.CDLL(str(library))
    for precision, ctype in (("double", ctypes.c_double), ("float", ctypes.c_float)):
        function = getattr(loaded, f"sign_{precision}")
        function.argtypes, function.restype = [ctype], ctype
        assert [function(x) for x in (-2.5, -0.0, 0.0, 3.0)] == [-1.0, 0.0, 0.0, 1.0]
        assert np.isnan(function(float("nan")))


def test_integers_the_type_cannot_hold_print_as_rounded_literals() -> None:
    """-42181425 (a Horner coefficient of phi + phi**3) is exact in double but not in float, where an
    int constant is rounded by the compiler and rejected by -Wfloat-conversion."""
    x = sp.Symbol("x", real=True)
    expression = 42181425 * x + 3
    assert SymrotCPrinter("double").doprint(expression) == "42181425*x + 3"
    assert SymrotCPrinter("float").doprint(expression) == "4.2181424e+07F*x + 3"
    assert SymrotCPrinter("float").doprint(16777216 * x) == "16777216*x"  # 2^24: exact in float
