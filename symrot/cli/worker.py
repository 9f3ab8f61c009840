"""Run one command in a forked worker process with a wall-clock and an address-space limit.

SymPy can loop in C-level big-integer arithmetic that no signal interrupts, or grow to gigabytes
within seconds. The parent therefore never does the work itself: it forks, the worker sets
``RLIMIT_AS`` and runs the command under :func:`symrot.budget.enforce` (a clean, in-process
expiry with the stage named), and the parent waits until the budget plus a short grace period
has passed, then kills the worker and names the stage the worker last published in shared
memory. The worker inherits stdout and stderr, so its output passes through unchanged; argument
parsing, ``--help`` and usage errors happen in the parent before the fork.
"""

from __future__ import annotations

import mmap
import os
import select
import signal
import sys
import time
from collections.abc import Callable

from .. import budget

GRACE_SECONDS = 1.5
"""How long the parent waits after the budget for the worker to report its own expiry."""
MEMORY_LIMIT = 4 * 2**30
"""Address-space limit of a worker (bytes). SymPy and NumPy need about 1 GiB of it."""
CRASH_SIGNALS = (signal.SIGKILL, signal.SIGSEGV, signal.SIGABRT, signal.SIGBUS)
"""Deaths a worker suffers when the address-space limit hits C code that cannot raise."""

EXIT_ERROR = 2
PR_SET_PDEATHSIG = 1


def available() -> bool:
    """True where a worker can be forked and limited (POSIX with setrlimit)."""
    try:
        import resource  # noqa: F401
    except ImportError:
        return False
    return hasattr(os, "fork")


def run(command: Callable[[], int], seconds: float | None, memory: int = MEMORY_LIMIT) -> int:
    """The exit status of ``command()`` run in a worker; 2 with one line on stderr when the
    worker ran out of time or memory."""
    shared = mmap.mmap(-1, budget.SHARED_SIZE)
    sys.stdout.flush()
    sys.stderr.flush()
    pid = os.fork()
    if pid == 0:  # pragma: no cover - the worker's coverage is the parent's result
        code = 70
        try:
            code = _worker(command, shared, memory)
        finally:
            os._exit(code)
    try:
        status = _wait(pid, None if not seconds else seconds + GRACE_SECONDS)
    except KeyboardInterrupt:  # the worker got the same SIGINT: let it report, briefly
        status = _wait(pid, GRACE_SECONDS)
        if status is None:
            _kill(pid)
            print("symrot: interrupted", file=sys.stderr)
            return 130
    if status is None:
        _kill(pid)
        assert seconds is not None
        print(f"symrot: error: the time budget of {seconds:g} s ran out during "
              f"{budget.read_shared(shared)} (--timeout changes it)", file=sys.stderr)
        return EXIT_ERROR
    if os.WIFSIGNALED(status) and os.WTERMSIG(status) in CRASH_SIGNALS:
        print(f"symrot: error: out of memory during {budget.read_shared(shared)} "
              f"(limit {memory / 2**30:g} GiB)", file=sys.stderr)
        return EXIT_ERROR
    if os.WIFSIGNALED(status):
        return 128 + os.WTERMSIG(status)
    return os.WEXITSTATUS(status)


def _worker(command: Callable[[], int], shared: mmap.mmap, memory: int) -> int:
    import resource

    _die_with_parent()
    try:
        _, hard = resource.getrlimit(resource.RLIMIT_AS)
        limit = memory if hard == resource.RLIM_INFINITY else min(memory, hard)
        resource.setrlimit(resource.RLIMIT_AS, (limit, hard))
        budget.share(shared)
        return command()
    finally:
        try:
            sys.stdout.flush()
            sys.stderr.flush()
        except (OSError, ValueError):
            pass


def _die_with_parent() -> None:
    """Linux: the worker gets SIGKILL when the parent dies, so none outlives a killed command."""
    try:
        import ctypes

        ctypes.CDLL(None, use_errno=True).prctl(PR_SET_PDEATHSIG, signal.SIGKILL)
    except (OSError, AttributeError):
        pass


def _wait(pid: int, seconds: float | None) -> int | None:
    """The worker's wait status, or None if it is still running after ``seconds``."""
    deadline = None if seconds is None else time.monotonic() + seconds
    try:
        handle = os.pidfd_open(pid)
    except (AttributeError, OSError):
        handle = None
    try:
        while True:
            done, status = os.waitpid(pid, os.WNOHANG)
            if done:
                return status
            left = None if deadline is None else deadline - time.monotonic()
            if left is not None and left <= 0:
                return None
            if handle is not None:
                select.select([handle], [], [], left)
            else:
                time.sleep(0.02 if left is None else min(0.02, left))
    finally:
        if handle is not None:
            os.close(handle)


def _kill(pid: int) -> None:
    try:
        os.kill(pid, signal.SIGKILL)
        os.waitpid(pid, 0)
    except (ProcessLookupError, ChildProcessError):
        pass
