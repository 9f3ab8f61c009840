"""Safe parsing: valid expressions build the right SymPy tree; hostile input executes nothing."""

from __future__ import annotations

import sys
import time
from pathlib import Path

import pytest
import sympy as sp

from symrot.core.errors import ParseError
from symrot.core.functions import RealCbrt
from symrot.core.parsing import PHI, parse_expression

sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "bench"))

import hostile_cli  # the CLI corpus: its injections and bombs are parse errors

VALID = {
    "cbrt(6*(phi-sin(phi)))": RealCbrt(6 * PHI - 6 * sp.sin(PHI)),
    "4*tan(φ/4)": 4 * sp.tan(PHI / 4),
    "2 * sin(phi / 2)": 2 * sp.sin(PHI / 2),
    "phi^3 + phi": PHI**3 + PHI,
    "phi^2*3": 3 * PHI**2,
    "0.5*phi": PHI / 2,
    "1e-3*phi": PHI / 1000,
    "-(-phi)": PHI,
    "sin(pi*phi)/pi": sp.sin(sp.pi * PHI) / sp.pi,
    "atanh(phi/2)*2": 2 * sp.atanh(PHI / 2),
    "phi**(1/3)": PHI ** sp.Rational(1, 3),
    "sqrt(1+phi**2)*phi": sp.sqrt(1 + PHI**2) * PHI,
    "  phi  ": PHI,
    "0x10*phi": 16 * PHI,
    "0b101*phi + 0o7*phi**3": 5 * PHI + 7 * PHI**3,
    "(1+phi)**64 - 1": (1 + PHI) ** 64 - 1,
    "sqrt((1+phi**2)**64)*phi": (1 + PHI**2) ** 32 * PHI,
    "(2**64)**4*phi": 2**256 * PHI,
}

HOSTILE = [
    *hostile_cli.INJECTIONS,
    *hostile_cli.BOMBS,
    "__import__('os').system('echo pwned')",
    "open('/etc/passwd')",
    "locals()",
    "vars()",
    "phi.__class__",
    "Symbol('x')",
    "[phi]",
    "(phi, phi)",
    "{phi}",
    "{1: phi}",
    "[x for x in range(10**9)]",
    "phi < 1",
    "not phi",
    "phi and 1",
    "phi or 1",
    "phi % 2",
    "phi << 2",
    "~phi",
    "x",
    "e * phi",
    "sin",
    "sin()",
    "sin(phi, 2)",
    "sin(**{})",
    "import os",
    "yield phi",
    "",
    "   ",
    "\x00phi",
    "phi**phi",
    "phi**sqrt(2)",
    "1" * 40 + "*phi",
    "1e999999 * phi",
    "1e99999999999 * phi",
    "sin(" * 100 + "phi" + ")" * 100,
    "1/0",
    "phi/0",
    "(-8)**(1/3)",
    "0**-1",
    "φ.__class__.__mro__",
    "help()",
    "quit()",
    "phi*(2**200)**3",
    "0o" + "7" * 40 + "*phi",
]


def test_corpus_has_at_least_fifty_hostile_inputs() -> None:
    assert len(HOSTILE) >= 50


@pytest.mark.parametrize("text, expected", list(VALID.items()))
def test_valid_expressions(text: str, expected: sp.Expr) -> None:
    assert parse_expression(text) == expected


class _AuditRecorder:
    """Records audit events that would mean user text was executed or reached the OS."""

    FORBIDDEN = ("exec", "import", "os.system", "subprocess.Popen", "open", "builtins.input",
                 "os.exec", "os.posix_spawn", "ctypes.dlopen", "socket.connect")

    def __init__(self) -> None:
        self.active = False
        self.events: list[str] = []

    def __call__(self, event: str, args: tuple[object, ...]) -> None:
        if self.active and event.startswith(self.FORBIDDEN):
            self.events.append(event)


_RECORDER = _AuditRecorder()
sys.addaudithook(_RECORDER)


@pytest.mark.parametrize("text", HOSTILE, ids=[repr(t)[:40] for t in HOSTILE])
def test_hostile_input_is_rejected_quickly_and_executes_nothing(text: str) -> None:
    _RECORDER.events.clear()
    started = time.monotonic()
    _RECORDER.active = True
    try:
        with pytest.raises(ParseError) as info:
            parse_expression(text)
    finally:
        _RECORDER.active = False
    assert time.monotonic() - started < 60  # hang-catcher (DERIVE_TIME_LIMIT; was 2 s, a speed)
    assert _RECORDER.events == []
    message = str(info.value)
    assert message and "\n" not in message and "Traceback" not in message


def test_non_string_input_is_rejected() -> None:
    with pytest.raises(ParseError):
        parse_expression(42)


def test_cbrt_is_the_real_odd_cube_root() -> None:
    expr = parse_expression("cbrt(phi)")
    assert expr.subs(PHI, -8) == -2
    assert sp.N(expr.subs(PHI, sp.Rational(-27, 1000))) == pytest.approx(-0.3)
    assert parse_expression("cbrt(-phi)") == -parse_expression("cbrt(phi)")
    assert sp.diff(expr, PHI) == sp.Rational(1, 3) / RealCbrt(PHI) ** 2
    assert str(parse_expression("cbrt(6*(phi-sin(phi)))")) == "cbrt(6*phi - 6*sin(phi))"
    # Printed form parses back to the same expression.
    assert parse_expression(str(expr)) == expr


def test_real_cube_root_in_mpmath_evaluation() -> None:
    import mpmath

    from symrot.core.functions import mpmath_namespace

    f = sp.lambdify(PHI, RealCbrt(PHI), modules=[mpmath_namespace(), "mpmath"])
    assert f(mpmath.mpf(-8)) == -2
    assert abs(sp.N(RealCbrt(PHI).subs(PHI, sp.Float(-27)), 30) + 3) < 1e-25


def test_functions_nested_beyond_the_cap_are_refused_at_once() -> None:
    """tan nested 31 times ran until the 60 s budget (issue 17); past MAX_FUNCTION_NESTING the
    parser refuses it in one line, while the deepest accepted nesting still parses."""
    import time

    from symrot.core.parsing import MAX_FUNCTION_NESTING

    deepest = "tan(" * MAX_FUNCTION_NESTING + "phi" + ")" * MAX_FUNCTION_NESTING
    assert parse_expression(deepest).has(PHI)
    started = time.monotonic()
    for depth in (MAX_FUNCTION_NESTING + 1, 31):
        with pytest.raises(ParseError, match=f"nested more than {MAX_FUNCTION_NESTING} deep"):
            parse_expression("tan(" * depth + "phi" + ")" * depth)
    with pytest.raises(ParseError, match="nested more than"):  # through other operators too
        depth = MAX_FUNCTION_NESTING
        parse_expression("2*sin(" + "1 + tan(" * depth + "phi" + ")" * depth + ")")
    assert time.monotonic() - started < 60  # hang-catcher (DERIVE_TIME_LIMIT; was 1 s, a speed)
