"""One time budget per command, and the stage (parse, validation, ...) it is spent in.

Library steps mark themselves with ``with stage("validation"):``; stages nest (validity analysis
re-validates p) and :func:`current` names the innermost one with its enclosing stage. When the
budget runs out or memory is exhausted, the stage the exception left first is kept
(:func:`failed`), so that the message can name it after the stack has unwound.

:func:`enforce` bounds a whole command in-process with ``SIGALRM``: it raises
:class:`BudgetExceeded`, a ``BaseException`` so that no ``except Exception`` (SymPy has many) nor
``except SymrotTimeout`` (fallbacks after a slow optional step) can swallow it. Inner
:func:`symrot.core.timeouts.time_limit` bounds nest inside it and never extend it. In a worker process
(:mod:`symrot.cli.worker`), :func:`share` mirrors the stage into shared memory so that the parent
can name it after killing a worker that no longer reacts to signals (long C-level arithmetic).
"""

from __future__ import annotations

import mmap
from collections.abc import Iterator
from contextlib import contextmanager

from symrot.core.timeouts import alarm


class BudgetExceeded(BaseException):
    """The command's time budget ran out; ``stage`` is where."""

    def __init__(self, seconds: float, stage: str) -> None:
        super().__init__(f"the time budget of {seconds:g} s ran out during {stage}")
        self.seconds = seconds
        self.stage = stage


_STACK: list[str] = []
_SHARED: list[mmap.mmap] = []
_FAILED: list[str] = []
SHARED_SIZE = 256
"""Bytes of the shared buffer: the stage text, UTF-8, NUL-padded."""


def share(buffer: mmap.mmap | None) -> None:
    """Mirror every stage change into ``buffer`` (a shared anonymous mmap), or stop with None."""
    _SHARED.clear()
    if buffer is not None:
        _SHARED.append(buffer)
        _publish()


def current() -> str:
    """The innermost stage, with the outermost one when they differ ("validation in validity
    analysis"); "startup" before the first stage."""
    if not _STACK:
        return "startup"
    if len(_STACK) == 1 or _STACK[0] == _STACK[-1]:
        return _STACK[-1]
    return f"{_STACK[-1]} (in {_STACK[0]})"


def failed() -> str:
    """The stage that the last exception left (its innermost stage), else :func:`current`."""
    return _FAILED[0] if _FAILED else current()


def reset() -> None:
    """Forget the stages of a previous command (in-process callers run several)."""
    _STACK.clear()
    _FAILED.clear()
    _publish()


def read_shared(buffer: mmap.mmap) -> str:
    """The stage text a worker last published into ``buffer``."""
    return bytes(buffer[:SHARED_SIZE]).split(b"\0", 1)[0].decode("utf-8", "replace") or "startup"


@contextmanager
def stage(name: str) -> Iterator[None]:
    """Mark the body as stage ``name``."""
    _STACK.append(name)
    _publish()
    try:
        yield
    except (BudgetExceeded, MemoryError, RecursionError):
        if not _FAILED:
            _FAILED.append(current())
        raise
    finally:
        _STACK.pop()
        _publish()


def _publish() -> None:
    if not _SHARED:
        return
    data = current().encode("utf-8")[:SHARED_SIZE - 1]
    buffer = _SHARED[0]
    buffer[:SHARED_SIZE] = data + b"\0" * (SHARED_SIZE - len(data))


@contextmanager
def enforce(seconds: float | None) -> Iterator[None]:
    """Raise :class:`BudgetExceeded` in the body after ``seconds`` (None or 0: unbounded).

    Needs the main thread (signals); elsewhere the body runs unbounded, as with
    :func:`symrot.core.timeouts.time_limit`.
    """
    with alarm(seconds or 0, lambda: BudgetExceeded(seconds or 0, current())):
        yield
