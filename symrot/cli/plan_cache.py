"""The evaluation plans of ``symrot derive --emit``, kept on disk between runs.

A plan (:func:`symrot.plan.evaluation_plan`) takes seconds to minutes and is a function of p(φ), the
module name and the code that computes it, nothing else: it is the same on every machine and under
any load. So it is stored under a key made of exactly those: p's ``srepr``, the name, the bytes of
every file of the installed symrot package, and the versions of Python, SymPy, NumPy and mpmath.
Any change of the code or of a library makes a new key; an entry is never stale, only unused.

Location: ``$SYMROT_CACHE_DIR``, else ``$XDG_CACHE_HOME/symrot/plans``, else
``~/.cache/symrot/plans``. ``--no-cache`` or ``SYMROT_NO_CACHE=1`` neither reads nor writes it, nor
does a process without the commands' fixed hash seed (:func:`enabled`); deleting the directory is
always safe. At most :data:`KEPT` plans are kept (the oldest go first).

The files are pickles, and loading a pickle can run code: a file is read only when it and its
directory belong to this user and nobody else may write them (POSIX permissions). The cache is an
optimisation, so every failure (an unreadable, corrupt or foreign file; a read-only disk) is silent
and the plan is computed instead.
"""

from __future__ import annotations

import hashlib
import os
import pickle
import platform
import stat
import sys
import tempfile
from functools import lru_cache
from pathlib import Path

import mpmath
import numpy
import sympy as sp

from ..core import Derivation
from ..plan import evaluation_plan, remember_plan
from ..plan_ir import EvaluationPlan

COMMANDS_HASH_SEED = "0"
"""``symrot.entry.SEED``, the hash seed every command runs with (not imported: ``symrot.entry`` imports
the CLI; tests/test_plan_cache.py checks that the two agree)."""
KEPT = 256
"""Plans kept on disk; storing one more removes the least recently used."""
DISABLE_VARIABLE = "SYMROT_NO_CACHE"
DIRECTORY_VARIABLE = "SYMROT_CACHE_DIR"


def enabled() -> bool:
    """Whether plans are read and stored: not when ``SYMROT_NO_CACHE`` is set to anything but empty
    or 0, and only in a process with the commands' hash seed (:mod:`symrot.entry`), whose plans are
    the canonical ones (with another seed SymPy may return another of equally accurate forms)."""
    return (os.environ.get(DISABLE_VARIABLE, "") in ("", "0")
            and os.environ.get("PYTHONHASHSEED") == COMMANDS_HASH_SEED)


def directory() -> Path:
    """Where the plans are kept (see the module's docstring)."""
    explicit = os.environ.get(DIRECTORY_VARIABLE)
    if explicit:
        return Path(explicit)
    base = os.environ.get("XDG_CACHE_HOME") or str(Path.home() / ".cache")
    return Path(base) / "symrot" / "plans"


@lru_cache(maxsize=1)
def code_digest() -> str:
    """SHA-256 of every file of the symrot package (sources, templates, data) and of the versions
    of what computes a plan."""
    digest = hashlib.sha256()
    for text in (sys.version, platform.python_implementation(), sp.__version__, numpy.__version__,
                 mpmath.__version__):
        digest.update(text.encode() + b"\0")
    package = Path(__file__).resolve().parent.parent
    for path in sorted(package.rglob("*")):
        if path.is_file() and "__pycache__" not in path.parts and path.suffix != ".pyc":
            digest.update(str(path.relative_to(package)).encode() + b"\0")
            digest.update(path.read_bytes() + b"\0")
    return digest.hexdigest()


def entry_name(p: sp.Expr, name: str) -> str:
    """The file name of the plan of ``p`` named ``name`` for this code."""
    digest = hashlib.sha256()
    for text in (code_digest(), sp.srepr(p), name):
        digest.update(text.encode() + b"\0")
    return digest.hexdigest() + ".pickle"


def _private(path: Path) -> bool:
    """``path`` belongs to this user and only this user may write it (always true off POSIX)."""
    if not hasattr(os, "getuid"):
        return True
    info = path.stat()
    return info.st_uid == os.getuid() and not info.st_mode & (stat.S_IWGRP | stat.S_IWOTH)


def load(p: sp.Expr, name: str) -> EvaluationPlan | None:
    """The stored plan of ``p`` named ``name``, or None (absent, disabled or unusable)."""
    if not enabled():
        return None
    folder = directory()
    path = folder / entry_name(p, name)
    try:
        if not (path.is_file() and _private(folder) and _private(path)):
            return None
        with path.open("rb") as stream:
            plan = pickle.load(stream)
        os.utime(path)  # recently used: kept longest
    except Exception:  # a corrupt or truncated entry (any unpickling error): computed instead
        return None
    if not isinstance(plan, EvaluationPlan) or plan.p != p or plan.name != name:
        return None
    return plan


def store(plan: EvaluationPlan) -> None:
    """Keep ``plan`` on disk (written to a temporary file and renamed: readers never see half a
    file); then remove the least recently used plans beyond :data:`KEPT`."""
    if not enabled():
        return
    folder = directory()
    try:
        folder.mkdir(mode=0o700, parents=True, exist_ok=True)
        if not _private(folder):
            return
        handle, temporary = tempfile.mkstemp(dir=folder, prefix=".plan-", suffix=".tmp")
        try:
            with os.fdopen(handle, "wb") as stream:
                pickle.dump(plan, stream, protocol=pickle.HIGHEST_PROTOCOL)
            os.replace(temporary, folder / entry_name(plan.p, plan.name))
        finally:
            if os.path.exists(temporary):
                os.unlink(temporary)
        entries = sorted(folder.glob("*.pickle"), key=lambda path: path.stat().st_mtime, reverse=True)
        for old in entries[KEPT:]:
            old.unlink(missing_ok=True)
    except Exception:  # a read-only or full disk, a plan pickle cannot write: computed next time
        return


def cached_plan(derivation: Derivation, name: str) -> tuple[EvaluationPlan, bool]:
    """(the plan of ``derivation`` named ``name``, whether it came from the disk). Either way the
    backends printing it in this process get it without computing it again (a plan read back is
    handed to :func:`symrot.plan.remember_plan`; a computed one is remembered by the plan layer)."""
    plan = load(derivation.p, name)
    if plan is not None:
        remember_plan(plan)
        return plan, True
    plan = evaluation_plan(derivation, name)
    store(plan)
    return plan, False
