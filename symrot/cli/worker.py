"""Run one command in a forked worker process with a wall-clock and an address-space limit.

SymPy can loop in C-level big-integer arithmetic that no signal interrupts, or grow to gigabytes
within seconds. The parent therefore never does the work itself: it forks, the worker sets
``RLIMIT_AS`` and runs the command under :func:`symrot.core.budget.enforce` (a clean, in-process
expiry with the stage named), and the parent waits until the budget plus a short grace period
has passed, then kills the worker and names the stage the worker last published in shared
memory. The worker inherits stdout and stderr, so its output passes through unchanged; argument
parsing, ``--help`` and usage errors happen in the parent before the fork.

SIGINT from a terminal reaches both processes; SIGTERM sent to ``symrot`` reaches the parent only,
which passes it on to the worker and waits the grace period for it to clean up (temporary files,
scratch directories) and exit 143; a worker that does not end by then is killed.
"""

from __future__ import annotations

import faulthandler
import mmap
import os
import select
import signal
import sys
import time
from collections.abc import Callable, Iterator
from contextlib import contextmanager, suppress

from symrot.core import budget
from symrot.core.forked import die_with_parent

GRACE_SECONDS = 1.5
"""How long the parent waits after the budget for the worker to report its own expiry."""
MEMORY_LIMIT = 4 * 2**30
"""Address-space limit of a worker (bytes). SymPy and NumPy need about 1 GiB of it."""
CRASH_SIGNALS = (signal.SIGSEGV, signal.SIGABRT, signal.SIGBUS, signal.SIGFPE, signal.SIGILL)
"""Deaths of C code: after exhausting the address-space limit (C code that cannot raise when an
allocation fails), or a genuine crash; the worker's peak resident size tells them apart."""
MEMORY_FRACTION = 0.5
"""A crash with a peak resident size of at least this fraction of the limit counts as memory
exhaustion (exit 2); below it, it is a genuine crash (exit 70, signal named)."""

EXIT_ERROR = 2
EXIT_INTERNAL = 70
EXIT_TERMINATED = 128 + signal.SIGTERM
"""Exit status after SIGTERM (143), reported once the command has cleaned up."""


class Terminated(BaseException):
    """SIGTERM arrived: raised in the main thread so that ``finally`` blocks and context managers
    (temporary files, scratch directories) clean up as they do for ``KeyboardInterrupt``."""


def _raise_terminated(number: int, frame: object) -> None:
    raise Terminated


@contextmanager
def terminate_raises() -> Iterator[None]:
    """Within the block, SIGTERM raises :class:`Terminated` (in the main thread only; elsewhere
    the handler cannot be set and the block runs unchanged)."""
    try:
        previous = signal.signal(signal.SIGTERM, _raise_terminated)
    except ValueError:  # not the main thread
        yield
        return
    try:
        yield
    finally:
        signal.signal(signal.SIGTERM, previous)


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
    parent = os.getpid()
    pid = os.fork()
    if pid == 0:  # pragma: no cover - the worker's coverage is the parent's result
        code = 70
        try:
            code = _worker(command, shared, memory, parent)
        finally:
            os._exit(code)
    try:
        with terminate_raises():
            status, peak = _wait(pid, None if not seconds else seconds + GRACE_SECONDS)
    except KeyboardInterrupt:  # the worker got the same SIGINT: let it report, briefly
        status, peak = _wait(pid, GRACE_SECONDS)
        if status is None:
            _kill(pid)
            print("symrot: interrupted", file=sys.stderr)
            return 130
    except Terminated:  # SIGTERM reaches this process only: pass it on, let the worker clean up
        _signal(pid, signal.SIGTERM)
        status, peak = _wait(pid, GRACE_SECONDS)
        if status is None:
            _kill(pid)
            print("symrot: terminated", file=sys.stderr)
            return EXIT_TERMINATED
    if status is None:
        _kill(pid)
        assert seconds is not None
        print(f"symrot: error: the time budget of {seconds:g} s ran out during "
              f"{budget.read_shared(shared)} (--timeout changes it)", file=sys.stderr)
        return EXIT_ERROR
    if os.WIFSIGNALED(status):
        return _report_signal(os.WTERMSIG(status), peak, memory, budget.read_shared(shared))
    return os.WEXITSTATUS(status)


def signal_name(number: int) -> str:
    """'SIGSEGV (Segmentation fault)' for 11; the number when the signal is unknown."""
    try:
        name = signal.Signals(number).name
    except ValueError:
        return f"signal {number}"
    description = signal.strsignal(number)
    return f"{name} ({description})" if description else name


def _report_signal(number: int, peak: int, memory: int, where: str) -> int:
    """One line on stderr for a worker killed by signal ``number``; the exit status.

    SIGKILL is the kernel's out-of-memory killer (exit 2). A crash signal of C code is memory
    exhaustion when the worker had reached ``MEMORY_FRACTION`` of its limit (exit 2), else a bug
    (exit 70); either way the line names the signal. Other signals pass as 128 + number."""
    limit = f"limit {memory / 2**30:g} GiB"
    if number == signal.SIGKILL:
        print(f"symrot: error: out of memory during {where} (killed by SIGKILL; {limit})", file=sys.stderr)
        return EXIT_ERROR
    if number not in CRASH_SIGNALS:
        return 128 + number
    if peak >= MEMORY_FRACTION * memory:
        print(f"symrot: error: out of memory during {where} ({signal_name(number)} at "
              f"{peak / 2**30:.2g} GiB resident; {limit})", file=sys.stderr)
        return EXIT_ERROR
    print(f"symrot: internal error: the worker crashed with {signal_name(number)} during {where} "
          f"({peak / 2**20:.0f} MiB resident, {limit}); please report it", file=sys.stderr)
    return EXIT_INTERNAL


def _worker(command: Callable[[], int], shared: mmap.mmap, memory: int, parent: int) -> int:
    import resource

    die_with_parent(parent)
    faulthandler.disable()  # a crash is reported by the parent in one line, not as a dump
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


def _wait(pid: int, seconds: float | None) -> tuple[int | None, int]:
    """(the worker's wait status, its peak resident size in bytes), or (None, 0) if it is still
    running after ``seconds``."""
    deadline = None if seconds is None else time.monotonic() + seconds
    try:
        handle = os.pidfd_open(pid)
    except (AttributeError, OSError):
        handle = None
    try:
        while True:
            done, status, usage = os.wait4(pid, os.WNOHANG)
            if done:
                return status, usage.ru_maxrss * 1024  # kilobytes on Linux
            left = None if deadline is None else deadline - time.monotonic()
            if left is not None and left <= 0:
                return None, 0
            if handle is not None:
                select.select([handle], [], [], left)
            else:
                time.sleep(0.02 if left is None else min(0.02, left))
    finally:
        if handle is not None:
            os.close(handle)


def _signal(pid: int, number: int) -> None:
    with suppress(ProcessLookupError):
        os.kill(pid, number)


def _kill(pid: int) -> None:
    try:
        os.kill(pid, signal.SIGKILL)
        os.waitpid(pid, 0)
    except (ProcessLookupError, ChildProcessError):
        pass
