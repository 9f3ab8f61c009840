"""symrot.core.forked: a function run in a forked child, its value or exception taken back."""

from __future__ import annotations

import os
import time
from pathlib import Path

import pytest

from symrot.core.errors import InvalidGeneratingFunction
from symrot.core.forked import ForkedChildError, in_child


def test_the_value_comes_from_another_process() -> None:
    with in_child(lambda: (os.getpid(), [1.5, "x"])) as wait:
        child, value = wait()
    assert child != os.getpid() and value == [1.5, "x"]


def test_the_parent_works_while_the_child_computes(tmp_path: Path) -> None:
    """The child waits for a file that the parent writes inside the body: it sees it only if the
    parent ran while the child computed (was: two 0.6 s sleeps within 1.1 s, a speed)."""
    signal = tmp_path / "parent-ran"

    def child() -> str:
        deadline = time.monotonic() + 60  # hang-catcher only
        while not signal.exists() and time.monotonic() < deadline:
            time.sleep(0.01)
        return "saw the parent" if signal.exists() else "alone"

    with in_child(child) as wait:
        signal.write_text("x")
        assert wait() == "saw the parent"


def test_an_exception_of_the_child_is_raised_in_the_parent() -> None:
    def fail() -> None:
        raise InvalidGeneratingFunction("p(0) must be 0")

    with in_child(fail) as wait, pytest.raises(InvalidGeneratingFunction, match="p\\(0\\) must be 0"):
        wait()


def test_an_exception_that_does_not_pickle_is_named() -> None:
    class Local(Exception):
        pass

    def fail() -> None:
        raise Local("not at module level")

    with in_child(fail) as wait, pytest.raises(ForkedChildError, match="Local: not at module level"):
        wait()


def test_an_exception_that_does_not_unpickle_is_named() -> None:
    def fail() -> None:
        raise _TwoArguments(3.0, "validation")

    with in_child(fail) as wait, pytest.raises(ForkedChildError, match=r"_TwoArguments: 3\.0 s in"):
        wait()


class _TwoArguments(Exception):
    """Like symrot.core.budget.BudgetExceeded: its args (the message) do not rebuild it."""

    def __init__(self, seconds: float, stage: str) -> None:
        super().__init__(f"{seconds} s in {stage}")


def test_a_child_whose_value_is_not_taken_is_killed(tmp_path: Path) -> None:
    marker = tmp_path / "pid"

    def sleep() -> None:
        marker.write_text(str(os.getpid()))
        time.sleep(60)

    with in_child(sleep):
        while not marker.exists() or not marker.read_text():
            time.sleep(0.01)
    with pytest.raises(ProcessLookupError):
        os.kill(int(marker.read_text()), 0)


def test_a_child_that_dies_without_a_result_is_an_error() -> None:
    with in_child(lambda: os._exit(3)) as wait, pytest.raises(ForkedChildError, match="without a result"):
        wait()


def test_without_a_child_the_function_runs_here(monkeypatch: pytest.MonkeyPatch) -> None:
    def no_fork() -> int:
        raise BlockingIOError(11, "Resource temporarily unavailable")

    monkeypatch.setattr(os, "fork", no_fork)
    with in_child(os.getpid) as wait:
        assert wait() == os.getpid()
