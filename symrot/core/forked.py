"""Run a function in a forked child process while the caller goes on, and take its result back.

:func:`symrot.plan.builder.evaluation_plan` measures the candidate forms of every coefficient in float64
and in float32. Once the symbolic work both share is done, the two precisions are independent: the
float32 plan is computed in a child forked at that point while the parent computes float64, which
takes the plan's wall time on a machine with two cores to that of its longer precision. Both start
from the same process state, so the plan is the same whichever process computes which precision
(SymPy's caches carry state from one step to the next; :mod:`symrot.core.parsing`).

The result comes back pickled through a pipe, and so does an exception (re-raised in the parent;
one that cannot be pickled becomes a :class:`ForkedChildError` naming it). The child dies with its
parent (Linux ``PR_SET_PDEATHSIG``), so a command killed at its time budget leaves no process
behind, and a parent that stops waiting (an exception of its own, an expired budget) kills it.
Where ``os.fork`` does not exist or fails (no process or memory left for a child) the function
runs in the calling process, before the caller's own work.
"""

from __future__ import annotations

import os
import pickle
import signal
import sys
from collections.abc import Callable, Iterator, Sequence
from contextlib import ExitStack, contextmanager, suppress
from typing import Generic, TypeVar

from symrot.core.errors import SymrotError

T = TypeVar("T")
PR_SET_PDEATHSIG = 1
"""Linux ``prctl`` option: the signal a process receives when its parent ends."""


class ForkedChildError(SymrotError):
    """The forked child failed in a way that cannot be re-raised as such in the parent."""


def die_with_parent(parent: int) -> None:
    """Linux: this process gets SIGKILL when its parent ends, so none outlives a killed command.

    A parent that ended between the fork and the ``prctl`` call sends no signal: this process then
    already has another parent and ends at once (exit status 2)."""
    try:
        import ctypes

        ctypes.CDLL(None, use_errno=True).prctl(PR_SET_PDEATHSIG, signal.SIGKILL)
    except (OSError, AttributeError):
        pass
    if os.getppid() != parent:
        os._exit(2)


class _Child(Generic[T]):
    """A forked child computing one value (:func:`in_child`)."""

    def __init__(self, function: Callable[[], T]) -> None:
        sys.stdout.flush()
        sys.stderr.flush()
        read, write = os.pipe()
        parent = os.getpid()
        try:
            pid = os.fork()
        except OSError:
            os.close(read)
            os.close(write)
            raise
        if pid == 0:  # pragma: no cover - the child's work is the parent's result
            os.close(read)
            status = 1
            try:
                die_with_parent(parent)
                with os.fdopen(write, "wb") as stream:
                    stream.write(_outcome(function))
                status = 0
            finally:
                os._exit(status)
        os.close(write)
        self._pid: int | None = pid
        self._read = read

    def result(self) -> T:
        """Wait for the child; its value, or its exception raised here."""
        try:
            with os.fdopen(self._read, "rb") as stream:
                payload = stream.read()
            assert self._pid is not None
            _, status = os.waitpid(self._pid, 0)
            self._pid = None
        except BaseException:
            self.close()
            raise
        if not payload:
            raise ForkedChildError(f"a forked child ended without a result (wait status {status})")
        succeeded, value = pickle.loads(payload)
        if not succeeded:
            raise value
        return value

    def close(self) -> None:
        """Kill the child unless its result was taken."""
        if self._pid is None:
            return
        try:
            os.kill(self._pid, signal.SIGKILL)
            os.waitpid(self._pid, 0)
        except (ProcessLookupError, ChildProcessError):
            pass
        with suppress(OSError):
            os.close(self._read)
        self._pid = None


def _outcome(function: Callable[[], object]) -> bytes:
    """The pickled (True, value) of ``function()``, or (False, exception)."""
    try:
        return pickle.dumps((True, function()), protocol=pickle.HIGHEST_PROTOCOL)
    except BaseException as error:  # every failure is re-raised in the parent
        try:  # an exception whose constructor does not take its args back fails in pickle.loads
            payload = pickle.dumps((False, error), protocol=pickle.HIGHEST_PROTOCOL)
            pickle.loads(payload)
            return payload
        except Exception:  # one that does not pickle is named instead
            message = f"{type(error).__name__}: {error}"
            return pickle.dumps((False, ForkedChildError(message)), protocol=pickle.HIGHEST_PROTOCOL)


class _Done(Generic[T]):
    """A value computed in the calling process (no ``os.fork``), with the interface of _Child."""

    def __init__(self, function: Callable[[], T]) -> None:
        self._value = function()

    def result(self) -> T:
        return self._value

    def close(self) -> None:
        pass


@contextmanager
def in_child(function: Callable[[], T]) -> Iterator[Callable[[], T]]:
    """``function()`` in a forked child; the body gets a callable that waits for its value (or
    raises its exception). The child is killed if the body leaves without taking the value."""
    child: _Child[T] | _Done[T] | None = None
    if hasattr(os, "fork"):
        with suppress(OSError):  # no process or memory left for a child (EAGAIN, ENOMEM)
            child = _Child(function)
    if child is None:
        child = _Done(function)
    try:
        yield child.result
    finally:
        child.close()


def first_here_others_in_children(functions: Sequence[Callable[[], T]]) -> list[T]:
    """The values of ``functions``, in order: the first computed in this process while each other
    one runs in a forked child of its own (started first, all from this process's state)."""
    first, *others = functions
    with ExitStack() as children:
        waits = [children.enter_context(in_child(function)) for function in others]
        values = [first()]
        values += [wait() for wait in waits]
    return values
