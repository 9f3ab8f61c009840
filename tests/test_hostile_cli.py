"""Reliability of the command line under hostile input (issue 17): the corpus of
``bench/hostile_cli.py``, each input its own process with a small budget, answered in time with
exit 0 or 2 and no traceback. The quick inputs run in processes forked from a server that has
imported ``symrot.cli`` (``hostile_cli.run_all_preloaded``: the same ``main`` on ``sys.argv``, worker
and budget included, without 166 interpreter start-ups); the heavy ones as ``python -m symrot``
subprocesses. The long version: ``python bench/hostile_cli.py``."""

from __future__ import annotations

import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "bench"))

import hostile_cli  # noqa: E402

QUICK_BUDGET = 15.0
HEAVY_BUDGET = 10.0


def hang_margin(budget: float) -> float:
    """Seconds a test allows past a command's budget: at least twice the budget (so three times it
    in all) and at least ``hostile_cli.MARGIN``. Only a hang fails; a loaded machine may be slow."""
    return max(hostile_cli.MARGIN, 2 * budget)


def _report(outcomes: list[hostile_cli.Outcome], budget: float) -> list[str]:
    margin = hang_margin(budget)
    return [f"{' '.join(o.args)[:80]!r}: {', '.join(o.problems(budget, margin))}; "
            f"stderr: {o.stderr[-300:]!r}" for o in outcomes if o.problems(budget, margin)]


def test_the_corpus_is_large_and_covers_every_subcommand() -> None:
    corpus = hostile_cli.QUICK + hostile_cli.HEAVY
    assert len(corpus) >= 150
    commands = {word for args in corpus for word in args[:3]}
    assert {"derive", "solve", "table", "sheet", "plot", "audit"} <= commands


def test_outcomes_are_judged() -> None:
    judge = hostile_cli.Outcome
    assert judge(("x",), 2, 1.0, "symrot: error: no").problems(10) == []
    assert judge(("x",), 70, 1.0, "symrot: internal error (X)").problems(10) == [
        "exit 70", "traceback or internal error"]
    assert judge(("x",), 0, 30.0, "").problems(10) == ["took 30.0 s (budget 10 s)"]
    # the tests' margin grows with the budget: 2.5x the heavy budget is slow, not a hang
    assert judge(("x",), 0, 2.5 * HEAVY_BUDGET, "").problems(HEAVY_BUDGET, hang_margin(HEAVY_BUDGET)) == []
    assert hang_margin(HEAVY_BUDGET) >= hostile_cli.MARGIN
    assert judge(("x",), -9, 1.0, "Traceback (most recent call last):").problems(10)[0] == "exit -9"


def test_the_preloaded_runner_reports_what_the_command_did() -> None:
    ok, refused, unknown = hostile_cli.run_all_preloaded(
        [["derive", "phi"], ["derive", "__import__('os')"], ["no-such-command"]], QUICK_BUDGET)
    assert (ok.status, ok.problems(QUICK_BUDGET)) == (0, [])
    assert refused.status == 2 and "unknown function '__import__'" in refused.stderr
    assert unknown.status == 2 and "invalid choice" in unknown.stderr


def test_quick_hostile_inputs_exit_0_or_2_in_time_without_traceback() -> None:
    outcomes = hostile_cli.run_all_preloaded(hostile_cli.QUICK, QUICK_BUDGET)
    assert _report(outcomes, QUICK_BUDGET) == []
    # nothing the injections name was executed: no file appeared in the scratch directories
    assert not (Path.cwd() / "pwned").exists()


@pytest.mark.slow
def test_heavy_inputs_end_within_the_budget() -> None:
    outcomes = hostile_cli.run_all(hostile_cli.HEAVY, HEAVY_BUDGET)
    assert _report(outcomes, HEAVY_BUDGET) == []
    # a tower of 31 tangents is refused by the parser before any derivation starts ...
    tower = outcomes[0]
    assert tower.status == 2 and "nested more than" in tower.stderr
    # (refused by the parser: the message says so; its time is only held to the budget, in _report,
    # as a hang-catcher: a loaded machine missed HEAVY_BUDGET / 2)
    # ... and what only the budget can stop is stopped by it, with the stage named
    assert any(outcome.status == 2 and "ran out during" in outcome.stderr for outcome in outcomes)
