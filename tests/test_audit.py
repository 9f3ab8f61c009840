"""Issue 8: the audit's full result, the CLI and the committed errata report."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from symrot.audit import run_all
from symrot.audit.checks import Check, Outcome
from symrot.audit.report import REGENERATE, errata_markdown, findings
from symrot.cli import main

ROOT = Path(__file__).resolve().parent.parent

EXPECTED = {
    "1": "definition",
    "text after (6)": "erratum",
    "7": "holds",
    "8": "holds",
    "9": "erratum",
    "10": "holds",
    "11": "definition",
    "12": "definition",
    "13": "definition",
    "text after (32)": "erratum",
    "14": "holds",
    "15": "definition",
    "16": "definition",
    "18": "holds",
    "19": "holds",
    "40": "holds",
    "41": "holds",
    "42": "holds",
    "43": "holds",
    "text after (43)": "holds",
    "Table 1 linear p_prime": "holds",
    "Table 1 linear nu": "holds",
    "Table 1 linear column4": "erratum",
    "Table 1 euler_rodrigues p_prime": "holds",
    "Table 1 euler_rodrigues nu": "holds",
    "Table 1 euler_rodrigues column4": "holds",
    "Table 1 sine_m4 p_prime": "holds",
    "Table 1 sine_m4 nu": "holds",
    "Table 1 sine_m4 column4": "erratum",
    "A (text after 75): mu": "holds",
    "A (text after 75): nu": "holds",
    "A (text after 75): epsilon": "holds",
    "C (text after 86): nu": "erratum",
    "C (text after 86): epsilon": "erratum",
    "89": "holds",
    "D (text after 98): mu": "holds",
    "D (text after 98): nu": "holds",
    "D (text after 98): epsilon": "holds",
}


@pytest.fixture(scope="module")
def results():  # type: ignore[no-untyped-def]
    return run_all()


def test_full_findings(results) -> None:  # type: ignore[no-untyped-def]
    assert findings(results) == EXPECTED


def test_every_erratum_has_correction_and_evidence(results) -> None:  # type: ignore[no-untyped-def]
    for r in results:
        assert r.outcome is not None, r.error
        if r.outcome.status == "erratum":
            assert r.outcome.corrected and r.outcome.evidence


def test_errata_report_is_current(results) -> None:  # type: ignore[no-untyped-def]
    committed = (ROOT / "docs" / "errata.md").read_text(encoding="utf-8")
    assert committed == errata_markdown(results), f"docs/errata.md is stale: run `{REGENERATE}`"


def test_check_that_cannot_run_is_reported() -> None:
    def broken() -> Outcome:
        raise ArithmeticError("boom")

    [result] = run_all([Check("x", "x", "symbolic", broken)])
    assert result.outcome is None and "boom" in result.error


def test_cli_json_and_exit_status(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    target = tmp_path / "errata.md"
    assert main(["audit", "--json", "--write", str(target)]) == 0
    rows = json.loads(capsys.readouterr().out)
    assert {row["equation"]: row["status"] for row in rows} == EXPECTED
    assert "## 9\n" in target.read_text(encoding="utf-8")
