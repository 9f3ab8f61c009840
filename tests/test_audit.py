"""Issue 8: the audit's full result, its sensitivity to the core, the CLI and the committed errata.

The audit runs once (module fixture, ~30 s); the expected table below is the complete finding
(equation → status): any change in the core or in a check shows up as a changed finding.
"""

from __future__ import annotations

import json
import re
from pathlib import Path
from typing import Any

import pytest

from symrot.audit import checks as audit_checks
from symrot.audit import proof
from symrot.audit.checks import DEFINITION, ERRATUM, HOLDS, NOT_RUN, Check, Outcome, Result, run_all
from symrot.audit.report import REGENERATE, errata_markdown, findings
from symrot.audit.table1 import ROWS
from symrot.cli import main

ROOT = Path(__file__).resolve().parent.parent
PAPER = ROOT / "docs" / "paper" / "vectorial-parameterization.md"
"""Bauchau & Trainelli (2003), kept in the project (its header cites it)."""

TEXT_STATEMENTS = [
    "text after (6): eigenvalues", "text after (16): limits", "text after (17): eigenvalues, trace, det",
    "text after (19): change of basis", "text before (21): omega", "text before (21): phi_dot u",
    "text after (22): limits", "text after (23): eigenvalues of H", "text after (32): c",
    "text after (32): kappa", "text after (32): H^-1", "text after (37): family members",
    "text before (38): p0", "text before Table 1: columns", "text after (43): nu3", "text after (47): nu3",
    "text after (65): max", "text after (69): omega0", "text after (75): p = e", "text after (80): H = K_(1)",
    "text after (86): mu, nu, eps", "text after (89): phi = e/nu", "text after (94): average",
    "text after (98): mu, nu, eps", "text after (99): codomain", "text after (102): powers",
]
TABLE_CELLS = [f"Table 1 {row} {column}" for row in ("rotation_vector", "cayley_gibbs_rodrigues",
                                                       "wiener_milenkovic", "linear", "euler_rodrigues",
                                                       "sine_m4")
               for column in ("p", "p_prime", "nu", "epsilon", "validity")]
ERRATA = {
    "text after (6): eigenvalues", "9", "text before (21): omega", "23", "text after (32): c",
    "text after (32): kappa", "text before (38): p0", "38", "text before Table 1: columns",
    "Table 1 linear validity", "45", "47", "text after (65): max", "text after (86): mu, nu, eps", "89",
    "text after (89): phi = e/nu", "91", "94", "97", "98",
}
DEFINITIONS = {"11", "12", "13", "15", "16", "20", "21", "30", "36", "48", "49", "52", "53", "54", "55", "60",
               "65", "69", "70", "76", "78", "80", "82", "86", "99"}
ALL_KEYS = [str(n) for n in range(1, 103)] + TEXT_STATEMENTS + TABLE_CELLS


def expected_status(key: str) -> str:
    return ERRATUM if key in ERRATA else DEFINITION if key in DEFINITIONS else HOLDS


@pytest.fixture(scope="module")
def results() -> list[Result]:
    return run_all()


def test_full_findings(results: list[Result]) -> None:
    assert [r.error for r in results if r.outcome is None] == []
    assert findings(results) == {key: expected_status(key) for key in ALL_KEYS}


def test_every_numbered_equation_and_table_cell_is_checked(results: list[Result]) -> None:
    keys = [r.check.equation for r in results]
    assert len(keys) == len(set(keys))
    assert {int(k) for k in keys if k.isdigit()} == set(range(1, 103))
    assert len(ROWS) == 6 and sum(k.startswith("Table 1 ") for k in keys) == 30


def test_errata_carry_correction_and_evidence(results: list[Result]) -> None:
    for r in results:
        assert r.outcome is not None and r.outcome.evidence, r.check.equation
        if r.status == ERRATUM:
            assert r.outcome.corrected, r.check.equation
        else:
            assert r.outcome.corrected == "", r.check.equation


def test_numbered_equations_are_quoted_verbatim() -> None:
    """Each numbered equation's ``printed`` is the paper's LaTeX (fragments around \\dots)."""
    paper = re.sub(r"\s+", "", PAPER.read_text(encoding="utf-8"))
    for check in audit_checks.all_checks():
        if check.equation.isdigit():
            for fragment in check.printed.split(r"\dots"):
                assert re.sub(r"\s+", "", fragment) in paper, (check.equation, fragment)


def test_errata_report_is_current(results: list[Result]) -> None:
    committed = (ROOT / "docs" / "errata.md").read_text(encoding="utf-8")
    assert committed == errata_markdown(results), f"docs/errata.md is stale: run `{REGENERATE}`"


def test_a_core_regression_changes_the_findings(monkeypatch: pytest.MonkeyPatch) -> None:
    """Break the core's H (drop the (u×) term of eq 22): (22) must stop holding."""
    original = proof.tensor_definitions

    def broken(p: Any) -> dict[str, Any]:
        tensors = dict(original(p))
        h = tensors["H"]
        tensors["H"] = type(h)(h.a, 0 * h.b, h.c)
        return tensors

    proof.core_tensor.cache_clear()
    monkeypatch.setattr(proof, "tensor_definitions", broken)
    try:
        [result] = run_all(only={"22"})
    finally:
        proof.core_tensor.cache_clear()
    assert result.status == NOT_RUN and "disagree" in result.error


def test_check_that_cannot_run_is_reported() -> None:
    def failing() -> Outcome:
        raise ArithmeticError("boom")

    [result] = run_all([Check("x", "x", "symbolic", failing)])
    assert result.outcome is None and result.status == NOT_RUN and "boom" in result.error


def test_cli_json_only_and_exit_status(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["audit", "--json", "--only", "45,97,46"]) == 0
    rows = json.loads(capsys.readouterr().out)
    assert {row["equation"]: row["status"] for row in rows} == {"45": ERRATUM, "46": HOLDS, "97": ERRATUM}
    assert all(row["printed"] and row["evidence"] for row in rows)
    assert main(["audit", "--only", "42"]) == 0
    assert "(42)" in capsys.readouterr().out
    assert main(["audit", "--only", "no-such-equation"]) == 2
    assert "symrot: error:" in capsys.readouterr().err


def test_cli_exits_1_when_a_check_cannot_run(monkeypatch: pytest.MonkeyPatch,
                                             capsys: pytest.CaptureFixture[str]) -> None:
    def failing() -> Outcome:
        raise ArithmeticError("boom")

    monkeypatch.setattr(audit_checks, "_registry", lambda: [Check("7", "x", "numeric", failing)])
    assert main(["audit", "--only", "7"]) == 1
    assert "could not run" in capsys.readouterr().out
