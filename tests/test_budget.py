"""One time budget per command: stages named on expiry, a worker process that is killed when it
no longer reacts, an address-space limit, and the command-line rules that came with issue 17."""

from __future__ import annotations

import argparse
import contextlib
import mmap
import os
import signal
import time
from pathlib import Path

import pytest

from symrot.cli import main, run, worker
from symrot.core import budget

TOWER = "tan(" * 4 + "phi" + ")" * 4
"""The deepest nesting the parser accepts; its derivation takes longer than the 1 s budgets below."""


def test_stages_nest_and_are_shared() -> None:
    shared = mmap.mmap(-1, budget.SHARED_SIZE)
    budget.share(shared)
    try:
        with budget.stage("validity analysis"), budget.stage("validation"):
            assert budget.current() == "validation (in validity analysis)"
            assert budget.read_shared(shared) == "validation (in validity analysis)"
        assert budget.read_shared(shared) == "startup"
    finally:
        budget.share(None)


def test_in_process_budget_names_the_stage(capsys: pytest.CaptureFixture[str]) -> None:
    started = time.monotonic()
    assert main(["--timeout", "1", "derive", TOWER]) == 2
    assert time.monotonic() - started < 8
    line = capsys.readouterr().err.strip()
    assert "\n" not in line and "the time budget of 1 s ran out during" in line


def test_the_budget_is_not_swallowed_by_except_exception() -> None:
    def stubborn() -> None:
        with contextlib.suppress(Exception):  # what SymPy does in places
            time.sleep(5)

    started = time.monotonic()
    with pytest.raises(budget.BudgetExceeded), budget.enforce(0.2):
        stubborn()
    assert time.monotonic() - started < 2


def test_worker_kills_a_command_that_ignores_signals(capsys: pytest.CaptureFixture[str]) -> None:
    def runaway() -> int:
        signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGALRM})
        with budget.stage("planning"):
            time.sleep(30)
        return 0

    started = time.monotonic()
    assert worker.run(runaway, 0.5) == 2
    assert time.monotonic() - started < 0.5 + worker.GRACE_SECONDS + 3
    assert "ran out during planning" in capsys.readouterr().err


def test_worker_passes_the_exit_status_and_survives_a_crash(capsys: pytest.CaptureFixture[str]) -> None:
    assert worker.run(lambda: 3, 5) == 3

    def crash() -> int:
        with budget.stage("derivation"):
            os.kill(os.getpid(), signal.SIGKILL)
        return 0

    assert worker.run(crash, 5) == 2
    assert "out of memory during derivation (killed by SIGKILL" in capsys.readouterr().err


def test_worker_names_a_genuine_crash_by_its_signal(capsys: pytest.CaptureFixture[str]) -> None:
    """A segmentation fault far below the memory limit is a bug (exit 70), not "out of memory"."""
    def segfault() -> int:
        with budget.stage("printing"):
            os.kill(os.getpid(), signal.SIGSEGV)
        return 0

    assert worker.run(segfault, 5) == 70
    err = capsys.readouterr().err
    assert "SIGSEGV" in err and "during printing" in err and "out of memory" not in err
    assert len(err.strip().splitlines()) == 1


def test_worker_counts_a_crash_at_the_memory_limit_as_memory(capsys: pytest.CaptureFixture[str]) -> None:
    """The same signal from a worker that had filled its limit: exit 2, memory and signal named."""
    limit = 4 * 2**30
    assert worker._report_signal(signal.SIGBUS, 3 * 2**30, limit, "derivation") == 2
    assert "out of memory during derivation (SIGBUS" in capsys.readouterr().err
    assert worker._report_signal(signal.SIGBUS, 2**28, limit, "derivation") == 70
    assert "internal error" in capsys.readouterr().err
    assert worker._report_signal(signal.SIGTERM, 0, limit, "derivation") == 128 + signal.SIGTERM


def test_worker_address_space_limit_turns_a_memory_bomb_into_exit_2() -> None:
    args = argparse.Namespace(run=lambda _: len(bytearray(3 * 2**30)))
    assert worker.run(lambda: run(args, 10), 10, memory=2 * 2**30) == 2


@pytest.mark.parametrize("seconds", ["-1", "nan", "inf", "abc"])
def test_bad_timeouts_are_usage_errors(seconds: str) -> None:
    with pytest.raises(SystemExit) as info:
        main(["--timeout", seconds, "derive", "phi"])
    assert info.value.code == 2


def test_timeout_is_accepted_after_the_command(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["derive", TOWER, "--timeout", "1"]) == 2
    assert "time budget of 1 s" in capsys.readouterr().err


def test_an_expression_may_start_with_a_minus(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["derive", "-phi", "--json"]) == 0
    assert '"expression": "-phi"' in capsys.readouterr().out


@pytest.mark.parametrize("command", [
    ["derive", "phi", "--emit", "numpy", "--out"],
    ["derive", "phi", "--emit", "c", "--out"],
    ["plot", "--figure", "1", "--format", "png", "--out"],
    ["table", "phi", "--out"],
    ["sheet", "phi", "--out"],
])
def test_out_errors_are_one_line_for_every_command(command: list[str], tmp_path: Path,
                                                   capsys: pytest.CaptureFixture[str]) -> None:
    assert main([*command, "/dev/null/x"]) == 2
    lines = capsys.readouterr().err.strip().splitlines()
    # derive --emit checks --out before any work ("cannot write into"); the others when writing
    assert len(lines) == 1 and lines[0].startswith("symrot: error: cannot ") and "/dev/null/x" in lines[0]


def test_a_fifo_in_the_way_is_refused_not_blocked_on(tmp_path: Path,
                                                     capsys: pytest.CaptureFixture[str]) -> None:
    os.mkfifo(tmp_path / "rotation_vector.tex")
    assert main(["sheet", "phi", "--out", str(tmp_path)]) == 2
    assert "is not a regular file" in capsys.readouterr().err


def test_the_worker_dies_with_a_killed_command() -> None:
    import subprocess
    import sys

    command = subprocess.Popen([sys.executable, "-m", "symrot", "derive", TOWER],
                               stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    children: list[str] = []
    deadline = time.monotonic() + 20
    while not children and time.monotonic() < deadline:
        time.sleep(0.2)
        children = Path(f"/proc/{command.pid}/task/{command.pid}/children").read_text().split()
    command.kill()
    command.wait()
    assert children, "no worker was forked"
    time.sleep(0.5)
    assert not Path(f"/proc/{children[0]}").exists() or "Z" in Path(
        f"/proc/{children[0]}/stat").read_text().split()[2]
