"""Writing output files for every command: one place for the checks and the one-line errors.

Any ``OSError`` (a missing or read-only directory, ``/proc``, ``/dev/null/x``, a full disk)
becomes a :class:`~symrot.core.errors.SymrotError`. Every file is written atomically
(:mod:`symrot.core.atomic`): after a failure, ``SIGINT`` or ``SIGTERM`` the previous file is whole and
no temporary file is left; :func:`write_files` replaces several files all or none.

Inside the output directory (``--out``, which may itself be a link the user chose) no symbolic
link is followed: a target that is a link, or whose directory resolves outside ``--out``, is
refused (exit 2, one line), and so is a target that exists but is not a regular file (a FIFO
would block the write forever, a device would swallow it).
"""

from __future__ import annotations

import os
import stat
from collections.abc import Sequence
from pathlib import Path

from symrot.core.atomic import replace_all, stage_file
from symrot.core.budget import stage
from symrot.core.errors import SymrotError


def check_writable(directory: Path) -> None:
    """Refuse ``directory`` (exit 2, one line) unless it is, or can be created as, a writable
    directory: checked before any work, so that no derivation is spent on an unusable ``--out``."""
    probe = directory
    while not os.path.lexists(probe) and probe != probe.parent:
        probe = probe.parent
    if not os.path.lexists(probe):
        probe = Path(".")
    if not probe.is_dir():
        raise SymrotError(f"cannot write into {directory}: {probe} is not a directory")
    what = "" if probe == directory else f" ({probe} is the nearest existing directory)"
    if not os.access(probe, os.W_OK | os.X_OK):
        raise SymrotError(f"cannot write into {directory}: permission denied{what}")
    try:  # access() says yes to root, and knows nothing of /proc or a full quota: try it
        stage_file(probe / ".symrot-probe", b"").unlink()
    except OSError as exc:
        raise SymrotError(f"cannot write into {directory}: {exc.strerror or exc}{what}") from None


def output_directory(directory: Path, root: Path | None = None) -> Path:
    """``directory``, created if needed (exit 2 with one line when it cannot be, or when it lies
    outside ``root`` through a symbolic link)."""
    with stage("writing"):
        try:
            if root is not None:  # no directory is created through a link out of root
                root.mkdir(parents=True, exist_ok=True)
                existing = directory
                while not os.path.lexists(existing) and existing != existing.parent:
                    existing = existing.parent
                _inside(root, existing, directory)
            directory.mkdir(parents=True, exist_ok=True)
        except OSError as exc:
            raise SymrotError(f"cannot create {directory}: {exc.strerror or exc}") from None
        if not directory.is_dir():
            raise SymrotError(f"cannot write into {directory}: not a directory")
        if root is not None and directory != root:
            _inside(root, directory, directory)
    return directory


def _inside(root: Path, directory: Path, shown: Path) -> None:
    try:
        directory.resolve().relative_to(root.resolve())
    except ValueError:
        raise SymrotError(f"cannot write {shown}: a symbolic link leads outside {root} "
                          "(symrot follows no link inside the output directory)") from None


def _check_target(root: Path, path: Path) -> None:
    if path.is_symlink():
        raise SymrotError(f"cannot write {path}: it is a symbolic link (symrot follows no link "
                          "inside the output directory)")
    _inside(root, path.parent, path)
    if path.exists() and not stat.S_ISREG(path.stat().st_mode):
        raise SymrotError(f"cannot write {path}: it exists and is not a regular file")


def write_files(root: Path, files: Sequence[tuple[Path, str | bytes]], announce: bool = True) -> list[Path]:
    """Write every ``(path, content)`` of ``files`` (paths under ``root``), all or none; print
    each path when ``announce``."""
    for directory in dict.fromkeys(path.parent for path, _ in files):
        output_directory(directory, root)
    with stage("writing"):
        try:
            for path, _ in files:
                _check_target(root, path)
            replace_all(files)
        except OSError as exc:
            shown = files[0][0] if len(files) == 1 else root
            raise SymrotError(f"cannot write {shown}: {exc.strerror or exc} (the previous "
                              f"file{'s are' if len(files) > 1 else ' is'} unchanged)") from None
    if announce:
        for path, _ in files:
            print(path)
    return [path for path, _ in files]


def write_file(directory: Path, filename: str, content: str | bytes, announce: bool = True) -> Path:
    """Write ``content`` to ``directory/filename`` (created if needed) atomically; print the path
    when ``announce``."""
    return write_files(directory, [(directory / filename, content)], announce)[0]
