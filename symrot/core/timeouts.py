"""Wall-clock bounds for symbolic steps that could otherwise run for minutes.

SymPy is pure Python, so a SIGALRM raised through ``signal.setitimer`` interrupts it cleanly.
Signals only work in the main thread of the main interpreter; elsewhere the bound cannot be
enforced and :func:`time_limit` runs the body unbounded (documented, never silently wrong).

Limits nest: an inner limit never extends an outer one, and each limit's :class:`SymrotTimeout`
carries a marker so that :func:`bounded` absorbs only its own expiry, never an outer one.

An expiry can land while the interpreter runs a callback whose exceptions it swallows ("Exception
ignored in ...": a garbage-collector callback such as JAX's ``_xla_gc_callback``, a ``__del__``,
a weakref callback). The limit would then be lost and the body run unbounded (a 0.5 s bound on a
simplification that took over 20 minutes in a process that had imported JAX). The timer
therefore repeats every :data:`RETRY_SECONDS` after it first expires, until the body ends. While
the limit is armed, ``sys.unraisablehook`` is wrapped: an expiry the interpreter dropped is not
reported (the repeat raises it again), and no expiry is raised while the hook reports anything
else (pytest's hook formats tracebacks; an expiry inside it broke the report and failed a test).

A fallback taken because a step ran out of *time* makes the result depend on the machine's speed
and load. Steps whose result feeds any output (derived forms, plans, generated code) are therefore
gated by deterministic size caps (operation counts, see :mod:`symrot.core.simplify` and
:mod:`symrot.plan.algebraic`) that decide which inputs are attempted at all, and their time bound is
only a safety net: it is ``SAFETY_FACTOR`` times the nominal bound and its expiry is an error,
never a silent fallback. That is the default everywhere (the deterministic mode): an output is
the same on every machine and under any load, or the command fails loudly. The nominal bounds
alone were within 2x of the normal run time: a 0.5 s ``trigsimp`` that took 0.28 s on an idle
machine ran past 0.5 s in a test process busy with JAX's garbage collection, fell back, and
changed a generated module (CI failed on it). :func:`time_fallbacks` restores the silent,
speed-dependent fallback at the nominal bound for callers whose result is never output.
"""

from __future__ import annotations

import signal
import sys
import threading
import time
from collections.abc import Callable, Iterator
from contextlib import AbstractContextManager, _GeneratorContextManager, contextmanager
from types import FrameType
from typing import Any, TypeVar

from sympy.core import random as sympy_random

from symrot.core.errors import SymrotTimeout

T = TypeVar("T")

RETRY_SECONDS = 0.05
"""Interval of the repeated expiry after the first (see the module docstring)."""
SAFETY_FACTOR = 30.0
"""How much wider the time bounds of :func:`bounded` are under :func:`deterministic`. It was 10, and
steps well inside their size caps met it on a loaded machine: a sum factor's trigsimp of 1.5 s
alone took 3.7 s beside a CI run, and once a base-angle reduction that took at most 0.3 s in four
other runs (hypothesis row 1) stopped a plan at its 5 s safety bound while a benchmark shared the
machine. The cause was found later, and it was not the load: the reduction's opaque symbols shared
names, so SymPy's generator order followed the string hash seed, and in one order its factoring ran
past a minute (see :func:`symrot.core.simplify._numbered_dummy`).
The bound only stops hangs; the size caps decide what is attempted."""
SYMPY_SEED = 0
"""The state of SymPy's random generator at the start of every :func:`bounded` step."""
_deterministic = threading.local()
_reporting_unraisable = threading.local()


@contextmanager
def _mode(on: bool) -> Iterator[None]:
    previous = is_deterministic()
    _deterministic.on = on
    try:
        yield
    finally:
        _deterministic.on = previous


def deterministic() -> AbstractContextManager[None]:
    """In the body, :func:`bounded` never falls back because of time (the default; see the module
    docstring): it gets ``SAFETY_FACTOR`` times its bound, and an expiry is an error."""
    return _mode(True)


def time_fallbacks() -> AbstractContextManager[None]:
    """In the body, :func:`bounded` returns its fallback once its nominal bound expires: faster, but
    the result depends on the machine's speed and load (never for anything that is output)."""
    return _mode(False)


def is_deterministic() -> bool:
    return bool(getattr(_deterministic, "on", True))


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

    raised: list[BaseException] = []  # the latest expiry: the one a swallowing callback drops

    def _on_alarm(signum: int, frame: FrameType | None) -> None:
        if getattr(_reporting_unraisable, "depth", 0) or _cleaning_up(frame):
            return  # the repeat raises it once the report is done; a limit being removed is over
        raised[:] = [error()]
        raise raised[0]

    previous_hook = sys.unraisablehook

    def _report_unraisable(unraisable: Any) -> None:
        if any(unraisable.exc_value is expiry for expiry in raised):
            return  # dropped where the interpreter swallows exceptions; the repeat raises it again
        _reporting_unraisable.depth = getattr(_reporting_unraisable, "depth", 0) + 1
        try:
            previous_hook(unraisable)
        finally:
            _reporting_unraisable.depth -= 1

    previous = signal.signal(signal.SIGALRM, _on_alarm)
    sys.unraisablehook = _report_unraisable
    started = time.monotonic()
    signal.setitimer(signal.ITIMER_REAL, seconds, RETRY_SECONDS)
    try:
        yield
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, previous)
        sys.unraisablehook = previous_hook
        if outer_remaining:
            elapsed = time.monotonic() - started
            signal.setitimer(signal.ITIMER_REAL, max(outer_remaining - elapsed, 1e-3), RETRY_SECONDS)


def _cleaning_up(frame: FrameType | None) -> bool:
    """Whether the interrupted code is a limit's own setup or cleanup (:func:`alarm`,
    :func:`time_limit` or the context manager exit that runs them).

    The repeated expiry must never land there: raised in the cleanup of :func:`alarm` before the
    timer is disarmed, it skipped the rest of the cleanup and left the repeating timer and its
    handler installed after the limit had ended, so that an unrelated later step failed with "took
    longer than ..." (seen after a 20 s limit expired deep inside ``sympy.solveset``, whose
    unwinding outlasted the 0.05 s repeat interval)."""
    while frame is not None:
        if frame.f_code in _CLEANUP_CODE:
            return True
        frame = frame.f_back
    return False


@contextmanager
def time_limit(seconds: float, what: str = "symbolic step", marker: object = None) -> Iterator[None]:
    """Raise :class:`SymrotTimeout` (with ``.marker``) if the body runs longer than ``seconds``."""

    def expired() -> SymrotTimeout:
        error = SymrotTimeout(f"{what} took longer than {seconds:g} s")
        error.marker = marker  # type: ignore[attr-defined]
        return error

    with alarm(seconds, expired):
        yield


_CLEANUP_CODE = frozenset({alarm.__wrapped__.__code__, time_limit.__wrapped__.__code__,  # type: ignore[attr-defined]
                           _GeneratorContextManager.__exit__.__code__})


@contextmanager
def seeded_sympy_random(seed: int = SYMPY_SEED) -> Iterator[None]:
    """In the body, SymPy's random generator (``sympy.core.random.rng``) starts from ``seed``; its
    state is restored afterwards. SymPy's multivariate factorization (Wang's algorithm,
    ``dmp_zz_wang``) draws random evaluation points, so its run time depends on the generator's
    state, which is seeded from the OS at import and advanced by everything that ran before: the
    base-angle reduction of det H of φ³/4 + sin(2φ) cos(φ/4)/2 (hypothesis row 72) took 0.4–1.1 s
    in 18 of 21 processes and 21–29 s in 3, past its 15 s safety bound (the emit failed). The
    factorization is unique, so the seed changes the time, not the result; seeded, a step's time
    depends on its input alone."""
    rng = sympy_random.rng
    state = rng.getstate()
    rng.seed(seed)
    try:
        yield
    finally:
        rng.setstate(state)


def bounded(seconds: float, fallback: T, func: Callable[..., T], *args: Any) -> T:
    """Return ``func(*args)`` if it finishes within ``seconds``, else ``fallback``.

    Used for optional work such as simplification, whose inputs are capped by size: the bound is a
    safety net against a hang. By default (:func:`deterministic`) it is ``SAFETY_FACTOR`` times
    ``seconds`` and its expiry raises :class:`SymrotTimeout`; under :func:`time_fallbacks` the
    ``fallback`` is returned after ``seconds``. An enclosing limit that expires meanwhile always
    propagates.
    """
    marker = object()
    strict = is_deterministic()
    try:
        with seeded_sympy_random(), \
                time_limit(seconds * SAFETY_FACTOR if strict else seconds, "simplification", marker):
            return func(*args)
    except SymrotTimeout as exc:
        if getattr(exc, "marker", None) is marker:
            if strict:
                name = getattr(func, "__qualname__", repr(func))
                raise SymrotTimeout(
                    f"a symbolic step ({name}) ran past its safety bound of {seconds * SAFETY_FACTOR:g} s; "
                    "stopping rather than giving a result that would depend on this machine's speed "
                    "(deterministic mode)") from None
            return fallback
        raise
    except RecursionError:
        return fallback
