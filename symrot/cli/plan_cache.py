"""The evaluation plans of ``symrot derive --emit``, kept on disk between runs.

A plan (:func:`symrot.plan.builder.evaluation_plan`) takes seconds to minutes and is a function of p(φ), the
module name and the code that computes it, nothing else: it is the same on every machine and under
any load. So it is stored under a key made of exactly those: p's ``srepr``, the name, the bytes of
every file of the installed symrot package, and the versions of Python, SymPy, NumPy and mpmath.
Any change of the code or of a library makes a new key; an entry is never stale, only unused.

Location: a directory of symrot's own, :data:`SUBDIRECTORY` (versioned with the entry format),
inside ``$SYMROT_CACHE_DIR``, else inside ``$XDG_CACHE_HOME/symrot`` (an absolute path), else inside
``$HOME/.cache/symrot`` (an absolute ``HOME``); with none of them there is no cache (never one
under ``/``). ``--no-cache`` or ``SYMROT_NO_CACHE=1`` neither reads nor writes it, nor does a
process without the commands' fixed hash seed (:func:`enabled`); deleting the directory is always
safe. Entries are named ``symrot-plan-<64 hex digits>.json`` (:data:`ENTRY_PATTERN`); at most
:data:`KEPT` are kept (the least recently used go first), and pruning removes nothing else: no
file of another name, nothing outside that directory.

An entry is two lines of JSON (:func:`entry_bytes`): a header with the entry format, its version,
the key and the SHA-256 of the payload, then the payload, the plan in the format of
:mod:`symrot.plan.serialized`, which never runs code when read. Every check (the header, the checksum,
the decoding, p and the name) is made before a plan is used, and any failure is a miss: the plan
is computed again and the entry rewritten. The cache is an optimisation, so every failure (an
unreadable, corrupt, truncated or foreign file; a read-only or full disk) is silent. A file is
read only when it and its directory belong to this user and nobody else may write them (POSIX
permissions): a forged plan would print a wrong kernel. A read-only cache directory is read, and
not written.
"""

from __future__ import annotations

import contextlib
import hashlib
import json
import os
import platform
import re
import stat
import sys
import tempfile
from functools import lru_cache
from pathlib import Path

import mpmath
import numpy
import sympy as sp

from symrot.core.derivation import Derivation
from symrot.plan.builder import evaluation_plan, remember_plan
from symrot.plan.ir import EvaluationPlan
from symrot.plan.serialized import canonical_json, decode_plan, encode_plan

COMMANDS_HASH_SEED = "0"
"""``symrot.entry.SEED``, the hash seed every command runs with (not imported: ``symrot.entry`` imports
the CLI; tests/test_plan_cache.py checks that the two agree)."""
KEPT = 256
"""Plans kept on disk; storing one more removes the least recently used."""
DISABLE_VARIABLE = "SYMROT_NO_CACHE"
DIRECTORY_VARIABLE = "SYMROT_CACHE_DIR"
ENTRY_FORMAT = "symrot-plan-cache"
ENTRY_VERSION = 1
"""Version of the entry layout and of its directory: entries of another version are never read."""
SUBDIRECTORY = f"symrot-plans-v{ENTRY_VERSION}"
ENTRY_PATTERN = re.compile(r"symrot-plan-[0-9a-f]{64}\.json")
"""The names of entries (matched whole): the only files pruning ever removes."""
TEMPORARY_PREFIX = ".symrot-plan-"
def enabled() -> bool:
    """Whether plans are read and stored: not when ``SYMROT_NO_CACHE`` is set to anything but empty
    or 0, and only in a process with the commands' hash seed (:mod:`symrot.entry`), whose plans are
    the canonical ones (with another seed SymPy may return another of equally accurate forms)."""
    return (os.environ.get(DISABLE_VARIABLE, "") in ("", "0")
            and os.environ.get("PYTHONHASHSEED") == COMMANDS_HASH_SEED)


def directory() -> Path | None:
    """Where the plans are kept (see the module's docstring), or None: no place for a cache."""
    explicit = os.environ.get(DIRECTORY_VARIABLE)
    if explicit:
        return Path(explicit) / SUBDIRECTORY
    xdg = os.environ.get("XDG_CACHE_HOME", "")
    if os.path.isabs(xdg):  # the XDG specification ignores a relative path
        return Path(xdg) / "symrot" / SUBDIRECTORY
    home = os.environ.get("HOME", "")
    if os.path.isabs(home) and home.strip("/"):  # not unset, empty, relative or /
        return Path(home) / ".cache" / "symrot" / SUBDIRECTORY
    return None


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


def entry_key(p: sp.Expr, name: str) -> str:
    """The key (64 hex digits) of the plan of ``p`` named ``name`` for this code."""
    digest = hashlib.sha256()
    for text in (code_digest(), sp.srepr(p), name):
        digest.update(text.encode() + b"\0")
    return digest.hexdigest()


def entry_name(p: sp.Expr, name: str) -> str:
    """The file name of the plan of ``p`` named ``name`` for this code (matches :data:`ENTRY_PATTERN`)."""
    return f"symrot-plan-{entry_key(p, name)}.json"


def entry_bytes(plan: EvaluationPlan, key: str) -> bytes:
    """The file of ``plan`` stored under ``key``: the header line, then the payload line."""
    payload = encode_plan(plan)
    header = {"format": ENTRY_FORMAT, "version": ENTRY_VERSION, "key": key,
              "sha256": hashlib.sha256(payload).hexdigest()}
    return canonical_json(header) + b"\n" + payload + b"\n"


def plan_of_entry(content: bytes, key: str) -> EvaluationPlan:
    """The plan an entry's bytes hold; ValueError (or another exception of decoding) unless they
    are exactly what :func:`entry_bytes` writes for ``key``."""
    header_line, separator, rest = content.partition(b"\n")
    if not separator or not rest.endswith(b"\n"):
        raise ValueError("an entry is two lines")
    payload = rest[:-1]
    header = json.loads(header_line.decode("ascii"))
    expected = {"format": ENTRY_FORMAT, "version": ENTRY_VERSION, "key": key,
                "sha256": hashlib.sha256(payload).hexdigest()}
    if header != expected or canonical_json(header) != header_line:
        raise ValueError("another format, version or key, or a payload that does not match its checksum")
    return decode_plan(payload)


def _private(path: Path) -> bool:
    """``path`` belongs to this user and only this user may write it (always true off POSIX)."""
    if not hasattr(os, "getuid"):
        return True
    info = path.stat()
    return info.st_uid == os.getuid() and not info.st_mode & (stat.S_IWGRP | stat.S_IWOTH)


def load(p: sp.Expr, name: str) -> EvaluationPlan | None:
    """The stored plan of ``p`` named ``name``, or None (absent, disabled or unusable)."""
    folder = directory() if enabled() else None
    if folder is None:
        return None
    key = entry_key(p, name)
    path = folder / f"symrot-plan-{key}.json"
    try:
        if not (path.is_file() and _private(folder) and _private(path)):
            return None
        plan = plan_of_entry(path.read_bytes(), key)
        if plan.p != p or plan.name != name:
            return None
    except Exception:  # unreadable, corrupt, truncated, of another version or key: computed instead
        return None
    with contextlib.suppress(OSError):  # a read-only cache is still read
        os.utime(path)  # recently used: kept longest
    return plan


def _prune(folder: Path) -> None:
    """Remove the least recently used entries beyond :data:`KEPT`; only files named like entries."""
    entries = []
    for path in folder.iterdir():
        if ENTRY_PATTERN.fullmatch(path.name):
            try:
                info = path.lstat()
            except OSError:
                continue
            if stat.S_ISREG(info.st_mode):
                entries.append((info.st_mtime, path))
    entries.sort(key=lambda entry: entry[0], reverse=True)
    for _, old in entries[KEPT:]:
        old.unlink(missing_ok=True)


def store(plan: EvaluationPlan) -> None:
    """Keep ``plan`` on disk (written to a temporary file and renamed: readers never see half a
    file); then remove the least recently used entries beyond :data:`KEPT`."""
    folder = directory() if enabled() else None
    if folder is None:
        return
    try:
        content = entry_bytes(plan, entry_key(plan.p, plan.name))
        folder.mkdir(mode=0o700, parents=True, exist_ok=True)
        if not _private(folder) or not os.access(folder, os.W_OK):
            return  # another's directory, or a read-only cache: read, never written
        handle, temporary = tempfile.mkstemp(dir=folder, prefix=TEMPORARY_PREFIX, suffix=".tmp")
        try:
            with os.fdopen(handle, "wb") as stream:
                stream.write(content)
                stream.flush()
                os.fsync(stream.fileno())
            os.replace(temporary, folder / entry_name(plan.p, plan.name))
        finally:
            if os.path.exists(temporary):
                os.unlink(temporary)
        _prune(folder)
    except Exception:  # a read-only or full disk, a plan outside the JSON form: computed next time
        return


def cached_plan(derivation: Derivation, name: str) -> tuple[EvaluationPlan, bool]:
    """(the plan of ``derivation`` named ``name``, whether it came from the disk). Either way the
    backends printing it in this process get it without computing it again (a plan read back is
    handed to :func:`symrot.plan.builder.remember_plan`; a computed one is remembered by the plan layer)."""
    plan = load(derivation.p, name)
    if plan is not None:
        remember_plan(plan)
        return plan, True
    plan = evaluation_plan(derivation, name)
    store(plan)
    return plan, False
