"""Time bounds: inner limits fall back, outer limits always propagate."""

from __future__ import annotations

import sys
import time

import pytest

from symrot.errors import SymrotTimeout
from symrot.timeouts import bounded, time_limit


def spin(seconds: float) -> str:
    end = time.monotonic() + seconds
    while time.monotonic() < end:
        pass
    return "finished"


def test_bounded_returns_fallback_when_slow() -> None:
    started = time.monotonic()
    assert bounded(0.05, "fallback", spin, 5) == "fallback"
    assert time.monotonic() - started < 1


def test_bounded_returns_result_when_fast() -> None:
    assert bounded(1, "fallback", spin, 0.001) == "finished"


def test_outer_limit_is_not_swallowed_by_inner_bounded() -> None:
    started = time.monotonic()
    with pytest.raises(SymrotTimeout, match="outer"), time_limit(0.1, "outer"):
        bounded(5, "fallback", spin, 5)
    assert time.monotonic() - started < 1


def test_outer_limit_is_rearmed_after_an_inner_one() -> None:
    with pytest.raises(SymrotTimeout, match="outer"), time_limit(0.3, "outer"):
        assert bounded(0.05, "fallback", spin, 1) == "fallback"
        spin(2)


def test_deterministic_mode_turns_a_time_fallback_into_an_error() -> None:
    """Under deterministic() (make generate) a bounded step never silently falls back because the
    machine was slow: it gets SAFETY_FACTOR more time, and an expiry is an error."""
    from symrot.timeouts import SAFETY_FACTOR, deterministic, is_deterministic

    assert not is_deterministic()
    with deterministic():
        assert is_deterministic()
        assert bounded(0.02, "fallback", spin, 0.05) == "finished"  # within 0.02 * SAFETY_FACTOR
        with pytest.raises(SymrotTimeout, match="deterministic mode"):
            bounded(0.01, "fallback", spin, 0.01 * SAFETY_FACTOR + 0.5)
    assert not is_deterministic()
    assert bounded(0.02, "fallback", spin, 0.05) == "fallback"


class _SlowFinalizer:
    """An object whose ``__del__`` sleeps: an exception raised in it is printed as "Exception
    ignored" and dropped by the interpreter, as in JAX's garbage-collector callback."""

    def __del__(self) -> None:
        time.sleep(0.3)


@pytest.mark.filterwarnings("ignore::pytest.PytestUnraisableExceptionWarning")
def test_an_expiry_swallowed_by_a_finalizer_is_raised_again() -> None:
    started = time.monotonic()
    with pytest.raises(SymrotTimeout), time_limit(0.1):
        _SlowFinalizer()  # finalized at once; the expiry lands in its sleep and is dropped
        while time.monotonic() - started < 3.0:
            pass
    assert time.monotonic() - started < 1.0


@pytest.mark.filterwarnings("ignore::pytest.PytestUnraisableExceptionWarning")
def test_bounded_falls_back_when_its_expiry_is_swallowed() -> None:
    def slow() -> str:
        _SlowFinalizer()
        deadline = time.monotonic() + 3.0
        while time.monotonic() < deadline:
            pass
        return "finished"

    started = time.monotonic()
    assert bounded(0.1, "fallback", slow) == "fallback"
    assert time.monotonic() - started < 1.0


class _FailingFinalizer:
    """An object whose ``__del__`` raises: the interpreter reports it through ``sys.unraisablehook``."""

    def __del__(self) -> None:
        raise ValueError("reported by the hook")


def test_no_expiry_lands_in_the_unraisable_hook_and_dropped_expiries_are_not_reported(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """pytest's hook formats a traceback when a finalizer fails; an expiry raised inside it broke
    the report ("Failed to process unraisable exception") and failed an unrelated CI test."""
    reported: list[BaseException | None] = []

    def slow_hook(unraisable: object) -> None:
        deadline = time.monotonic() + 0.4  # several repeat intervals
        while time.monotonic() < deadline:
            pass
        reported.append(getattr(unraisable, "exc_value", None))

    monkeypatch.setattr(sys, "unraisablehook", slow_hook)
    started = time.monotonic()
    with pytest.raises(SymrotTimeout), time_limit(0.05):
        _FailingFinalizer()  # its report spans the expiry
        _SlowFinalizer()  # an expiry dropped here is not reported, and raised again
        while time.monotonic() - started < 3.0:
            pass
    assert time.monotonic() - started < 1.5
    assert len(reported) == 1 and isinstance(reported[0], ValueError)
    assert sys.unraisablehook is slow_hook
