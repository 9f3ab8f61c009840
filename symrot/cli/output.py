"""Writing output files for every command: one place for the checks and the one-line errors.

Any ``OSError`` (a missing or read-only directory, ``/proc``, ``/dev/null/x``) becomes a
:class:`~symrot.errors.SymrotError`, and a target that exists but is not a regular file (a FIFO
would block the write forever, a device would swallow it) is refused.
"""

from __future__ import annotations

import stat
from pathlib import Path

from ..budget import stage
from ..errors import SymrotError


def output_directory(directory: Path) -> Path:
    """``directory``, created if needed (exit 2 with one line when it cannot be)."""
    with stage("writing"):
        try:
            directory.mkdir(parents=True, exist_ok=True)
        except OSError as exc:
            raise SymrotError(f"cannot create {directory}: {exc.strerror or exc}") from None
        if not directory.is_dir():
            raise SymrotError(f"cannot write into {directory}: not a directory")
    return directory


def write_file(directory: Path, filename: str, content: str | bytes, announce: bool = True) -> Path:
    """Write ``content`` to ``directory/filename`` (created if needed); print the path when
    ``announce``."""
    path = output_directory(directory) / filename
    with stage("writing"):
        try:
            if path.exists() and not stat.S_ISREG(path.stat().st_mode):
                raise SymrotError(f"cannot write {path}: it exists and is not a regular file")
            if isinstance(content, bytes):
                path.write_bytes(content)
            else:
                path.write_text(content, encoding="utf-8")
        except OSError as exc:
            raise SymrotError(f"cannot write {path}: {exc.strerror or exc}") from None
    if announce:
        print(path)
    return path
