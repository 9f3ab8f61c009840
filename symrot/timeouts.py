"""Wall-clock bounds for symbolic steps that could otherwise run for minutes.

SymPy is pure Python, so a SIGALRM raised through ``signal.setitimer`` interrupts it cleanly.
Signals only work in the main thread of the main interpreter; elsewhere the bound cannot be
enforced and :func:`time_limit` runs the body unbounded (documented, never silently wrong).
"""

from __future__ import annotations

import signal
import threading
import time
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from typing import Any, TypeVar

from .errors import SymrotTimeout

T = TypeVar("T")


def _can_use_signals() -> bool:
    return threading.current_thread() is threading.main_thread() and hasattr(signal, "setitimer")


@contextmanager
def time_limit(seconds: float, what: str = "symbolic step") -> Iterator[None]:
    """Raise :class:`SymrotTimeout` if the body runs longer than ``seconds``.

    Nested limits are honoured: the inner limit never extends an outer one.
    """
    if not _can_use_signals() or seconds <= 0:
        yield
        return

    def _on_alarm(signum: int, frame: object) -> None:
        raise SymrotTimeout(f"{what} took longer than {seconds:g} s")

    outer_remaining, _ = signal.getitimer(signal.ITIMER_REAL)
    previous = signal.signal(signal.SIGALRM, _on_alarm)
    if outer_remaining and outer_remaining < seconds:
        # The outer bound fires first and keeps its own handler semantics.
        signal.signal(signal.SIGALRM, previous)
        yield
        return
    started = time.monotonic()
    signal.setitimer(signal.ITIMER_REAL, seconds)
    try:
        yield
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, previous)
        if outer_remaining:
            # Re-arm the outer timer with what is left of it (never less than a tick).
            elapsed = time.monotonic() - started
            signal.setitimer(signal.ITIMER_REAL, max(outer_remaining - elapsed, 1e-3))


def bounded(seconds: float, fallback: T, func: Callable[..., T], *args: Any) -> T:
    """Return ``func(*args)`` if it finishes within ``seconds``, else ``fallback``.

    Used for optional simplification: a slow simplify never blocks a derivation.
    """
    try:
        with time_limit(seconds, "simplification"):
            return func(*args)
    except SymrotTimeout:
        return fallback
    except RecursionError:
        return fallback
