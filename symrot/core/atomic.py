"""Writing files so that a reader only ever sees a whole old version or a whole new one.

:func:`write_atomic` writes one file: the content goes into a temporary file in the target's own
directory (``.NAME.PID.RANDOM.symrot-partial``), is flushed and ``fsync``-ed, then renamed over
the target with :func:`os.replace` (atomic on POSIX). On any failure (``ENOSPC``, ``EIO``, an
exception raised by a signal handler) the temporary file is removed and the old file is untouched.

:func:`replace_all` writes several files all or none: every file is first staged as a temporary
file next to its target; then, with ``SIGINT``, ``SIGTERM`` and ``SIGALRM`` blocked
(:func:`signal.pthread_sigmask`), each existing target is kept as a hard link
(``.NAME.PID.RANDOM.symrot-backup``) and the staged file renamed over it. When a rename fails,
the renames already done are undone from the backups (a target that did not exist is removed);
the backups are removed in every case. A signal that arrived meanwhile is delivered after the
mask is lifted, when the files are all new or all old.

``SIGKILL`` cannot be caught: each file then is still whole (old or new), and the temporary files
a killed process leaves carry its process id; :func:`remove_stale` (called before every write)
removes those of processes that no longer run.
"""

from __future__ import annotations

import os
import secrets
import signal
import threading
from collections.abc import Iterator, Sequence
from contextlib import contextmanager, suppress
from pathlib import Path
from typing import Any

PARTIAL = ".symrot-partial"
"""Suffix of a staged file that has not been renamed into place yet."""
BACKUP = ".symrot-backup"
"""Suffix of the hard link that keeps a previous version until all renames have succeeded."""
DEFERRED = (signal.SIGINT, signal.SIGTERM, signal.SIGALRM)
"""Signals held back while the renames of :func:`replace_all` run."""


def _sibling(target: Path, suffix: str) -> Path:
    """A fresh name in ``target``'s directory, hidden, with this process's id."""
    return target.with_name(f".{target.name}.{os.getpid()}.{secrets.token_hex(4)}{suffix}")


def _owner(path: Path) -> int | None:
    """The process id in the name of a temporary file of this module, or None."""
    parts = path.name.rsplit(".", 3)
    try:
        return int(parts[-3])
    except (IndexError, ValueError):
        return None


def process_running(pid: int) -> bool:
    """True while process ``pid`` exists (also one of another user)."""
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        return True
    return True


def remove_stale(directory: Path) -> list[Path]:
    """Remove the temporary files that a killed symrot left in ``directory``; the removed paths.

    Only names of this module (``.*.PID.RANDOM.symrot-partial`` or ``-backup``) whose process no
    longer runs are touched; a missing or unreadable directory is no error."""
    removed = []
    try:
        entries = list(directory.iterdir())
    except OSError:
        return []
    for path in entries:
        if not path.name.startswith(".") or not path.name.endswith((PARTIAL, BACKUP)):
            continue
        pid = _owner(path)
        if pid is None or (pid != os.getpid() and process_running(pid)):
            continue
        try:
            path.unlink()
            removed.append(path)
        except OSError:
            pass
    return removed


def _unlink(path: Path) -> None:
    with suppress(FileNotFoundError):
        path.unlink()


def stage_file(target: Path, content: str | bytes) -> Path:
    """``content`` in a new temporary file next to ``target``, flushed and fsynced; its path.

    On failure nothing is left behind and the ``OSError`` (or the exception a signal handler
    raised) propagates."""
    data = content.encode("utf-8") if isinstance(content, str) else content
    temporary = _sibling(target, PARTIAL)
    try:
        descriptor = os.open(temporary, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o666)
        try:
            view = memoryview(data)
            while view:
                written = os.write(descriptor, view)
                view = view[written:]
            os.fsync(descriptor)
        finally:
            os.close(descriptor)
    except BaseException:
        _unlink(temporary)
        raise
    return temporary


def write_atomic(target: Path, content: str | bytes) -> Path:
    """Replace ``target`` by ``content`` atomically (see the module docstring); ``target``."""
    replace_all([(target, content)])
    return target


@contextmanager
def signals_deferred(signals: Sequence[int] = DEFERRED) -> Iterator[None]:
    """Hold ``signals`` back; each that arrived is delivered (once) when the block ends.

    They are blocked in this thread (:func:`signal.pthread_sigmask`) and, in the main thread,
    their Python handlers are replaced by a recorder meanwhile, since another thread (which
    does not block them) may take the signal and Python runs the handler in the main thread."""
    arrived: list[int] = []
    handlers: dict[int, Any] = {}
    if threading.current_thread() is threading.main_thread():
        for number in signals:
            handlers[number] = signal.signal(number, lambda received, frame: arrived.append(received))
    try:
        previous = signal.pthread_sigmask(signal.SIG_BLOCK, signals)
    except (AttributeError, OSError, ValueError):  # no pthread_sigmask on this platform
        previous = None
    try:
        yield
    finally:
        if previous is not None:
            signal.pthread_sigmask(signal.SIG_SETMASK, previous)
        for number, handler in handlers.items():
            signal.signal(number, handler)
        for number in dict.fromkeys(arrived):
            signal.raise_signal(number)


def replace_all(files: Sequence[tuple[Path, str | bytes]]) -> None:
    """Replace every ``(target, content)`` of ``files``, all of them or none.

    Raises the first ``OSError`` (after undoing the renames already done) or the exception of a
    signal handler during staging; no temporary file is left either way."""
    for directory in dict.fromkeys(target.parent for target, _ in files):
        remove_stale(directory)
    staged: list[tuple[Path, Path]] = []
    try:
        for target, content in files:
            staged.append((target, stage_file(target, content)))
    except BaseException:
        for _, temporary in staged:
            _unlink(temporary)
        raise
    with signals_deferred():
        _commit(staged)


def _commit(staged: list[tuple[Path, Path]]) -> None:
    """Rename every staged file over its target, keeping backups until all have succeeded."""
    done: list[tuple[Path, Path | None]] = []
    pending = list(staged)
    try:
        while pending:
            target, temporary = pending[0]
            backup = _keep(target)
            try:
                os.replace(temporary, target)
            except BaseException:
                if backup is not None:
                    _unlink(backup)
                raise
            done.append((target, backup))
            pending.pop(0)
    except BaseException:
        for target, backup in reversed(done):
            try:
                if backup is None:
                    _unlink(target)
                else:
                    os.replace(backup, target)
            except OSError:
                pass
        for _, temporary in pending:
            _unlink(temporary)
        raise
    finally:
        for _, backup in done:
            if backup is not None:
                _unlink(backup)


def _keep(target: Path) -> Path | None:
    """A hard link to ``target``'s current version (None when there is none)."""
    if not os.path.lexists(target):
        return None
    backup = _sibling(target, BACKUP)
    try:
        os.link(target, backup, follow_symlinks=False)
    except OSError:  # a file system without hard links: a copy instead
        _unlink(backup)
        copy = stage_file(target, Path(target).read_bytes())
        os.replace(copy, backup)
    return backup
