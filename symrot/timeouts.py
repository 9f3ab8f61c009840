"""Wall-clock bounds for symbolic steps that could otherwise run for minutes.

SymPy is pure Python, so a SIGALRM raised through ``signal.setitimer`` interrupts it cleanly.
Signals only work in the main thread of the main interpreter; elsewhere the bound cannot be
enforced and :func:`time_limit` runs the body unbounded (documented, never silently wrong).

Limits nest: an inner limit never extends an outer one, and each limit's :class:`SymrotTimeout`
carries a marker so that :func:`bounded` absorbs only its own expiry, never an outer one.
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
def alarm(seconds: float, error: Callable[[], BaseException]) -> Iterator[None]:
    """Raise ``error()`` in the body if it runs longer than ``seconds`` (nests, see above)."""
    if not _can_use_signals() or seconds <= 0:
        yield
        return
    outer_remaining, _ = signal.getitimer(signal.ITIMER_REAL)
    if outer_remaining and outer_remaining <= seconds:
        yield  # the outer limit expires first and is reported as the outer one
        return

    def _on_alarm(signum: int, frame: object) -> None:
        raise error()

    previous = signal.signal(signal.SIGALRM, _on_alarm)
    started = time.monotonic()
    signal.setitimer(signal.ITIMER_REAL, seconds)
    try:
        yield
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, previous)
        if outer_remaining:
            elapsed = time.monotonic() - started
            signal.setitimer(signal.ITIMER_REAL, max(outer_remaining - elapsed, 1e-3))


@contextmanager
def time_limit(seconds: float, what: str = "symbolic step", marker: object = None) -> Iterator[None]:
    """Raise :class:`SymrotTimeout` (with ``.marker``) if the body runs longer than ``seconds``."""

    def expired() -> SymrotTimeout:
        error = SymrotTimeout(f"{what} took longer than {seconds:g} s")
        error.marker = marker  # type: ignore[attr-defined]
        return error

    with alarm(seconds, expired):
        yield


def bounded(seconds: float, fallback: T, func: Callable[..., T], *args: Any) -> T:
    """Return ``func(*args)`` if it finishes within ``seconds``, else ``fallback``.

    Used for optional work such as simplification: a slow simplify never blocks a derivation,
    while an enclosing limit that expires meanwhile still propagates.
    """
    marker = object()
    try:
        with time_limit(seconds, "simplification", marker):
            return func(*args)
    except SymrotTimeout as exc:
        if getattr(exc, "marker", None) is marker:
            return fallback
        raise
    except RecursionError:
        return fallback
