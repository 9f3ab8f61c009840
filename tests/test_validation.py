"""Validation of generating functions (Section 3.1, eq 12)."""

from __future__ import annotations

import pytest
import sympy as sp

from symrot.core.errors import InvalidGeneratingFunction
from symrot.core.parsing import parse_expression
from symrot.core.validation import validate


@pytest.mark.parametrize(
    "text, kappa",
    [
        ("phi", 1),
        ("4*tan(phi/4)", 1),
        ("cbrt(6*(phi-sin(phi)))", 1),
        ("tan(phi/2)", sp.Rational(1, 2)),
        ("sin(phi/2)", sp.Rational(1, 2)),
        ("3*sinh(phi)", 3),
        ("sin(pi*phi)/pi", 1),
        ("atan(phi)*exp(phi**2)", 1),
        ("phi*sqrt(1+phi**2)", 1),
        ("log(1+phi) - log(1-phi)", 2),
    ],
)
def test_valid_functions_report_kappa(text: str, kappa: sp.Expr) -> None:
    assert validate(parse_expression(text)).kappa == kappa


@pytest.mark.parametrize(
    "text, reason",
    [
        ("cos(phi)", r"p\(0\) must be 0"),
        ("phi**2", "not odd"),
        ("phi + phi**2", "not odd"),
        ("phi**3", "kappa = lim p/phi = 0"),
        ("phi - sin(phi)", "kappa = lim p/phi = 0"),
        ("1/phi", "pole"),
        ("sqrt(phi)", "not real-analytic"),
        ("sqrt(phi**2)", "not real-analytic"),
        ("phi**(1/3)", "not real-analytic"),
        ("log(phi)", "not real-analytic"),
        ("exp(1/phi**2)*phi", "not real-analytic"),
        ("sqrt(-1-phi**2)*phi", "not real"),
        ("sqrt(1+phi)*phi", "not odd"),
        ("phi + (phi**2)**7", "not odd"),
        ("2", "does not depend on phi"),
        ("sin(phi) - sin(phi)", "does not depend on phi"),
    ],
)
def test_invalid_functions_are_rejected_with_a_reason(text: str, reason: str) -> None:
    with pytest.raises(InvalidGeneratingFunction, match=reason):
        validate(parse_expression(text))


def test_oddness_beyond_the_series_order_is_caught_numerically() -> None:
    # Even part phi**40 is beyond the checked Taylor order; the 50-digit check finds it.
    with pytest.raises(InvalidGeneratingFunction, match="not odd"):
        validate(parse_expression("phi + phi**40"))


def test_a_timeout_in_the_numeric_check_is_not_reported_as_a_bad_function(
        monkeypatch: pytest.MonkeyPatch) -> None:
    from symrot.core import validation
    from symrot.core.errors import SymrotTimeout

    def slow(*args: object, **kwargs: object) -> None:
        raise SymrotTimeout("derivation took longer than 60 s")

    monkeypatch.setattr(validation, "evaluate", slow)
    with pytest.raises(SymrotTimeout):
        validate(parse_expression("sin(phi)"))
