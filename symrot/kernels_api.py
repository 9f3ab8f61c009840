"""Generated kernels in one call from Python: :func:`kernels` and :func:`emit`.

``symrot.kernels(p)`` returns the generated module of a generating function p(φ), imported and
ready to call, with a ``backend`` attribute (``"numpy"``, ``"jax"`` or ``"torch"``)::

    rv = symrot.kernels("rotation_vector")
    R = rv.rotation_matrix([0.1, 0.2, 0.3])

``symrot.emit(p, backends, out)`` is the command line's ``--emit``: it writes the files and returns
their paths. Both run ``python -m symrot derive EXPR --emit …`` in a child process, so the code is
the command line's to the byte (its fixed hash seed, time budget, memory limit and plan cache) and a
bad expression gets the command's one-line message, raised as :class:`~symrot.core.errors.SymrotError`.

:func:`kernels` keeps each module it loads in ``symrot-kernels-v1`` beside the plan cache
(``$SYMROT_CACHE_DIR``, else ``$XDG_CACHE_HOME/symrot``, else ``~/.cache/symrot``), keyed by the
expression as given, the backend, the name and a digest of symrot's own files and of the versions
of Python, SymPy and NumPy; an entry is used only when its SHA-256 checks, is written atomically,
and a later process imports it without starting a child. A second call in one process returns
the same module object.
"""

from __future__ import annotations

import hashlib
import importlib.metadata
import importlib.util
import json
import os
import stat
import subprocess
import sys
import tempfile
from collections.abc import Sequence
from functools import lru_cache
from pathlib import Path
from types import ModuleType

from symrot.core.atomic import write_atomic
from symrot.core.errors import SymrotError

BACKENDS = ("numpy", "jax", "torch")
"""The backends whose modules :func:`kernels` imports (``--emit c`` writes a header: see :func:`emit`)."""
SUBDIRECTORY = "symrot-kernels-v1"
_LOADED: dict[str, ModuleType] = {}


def emit(expression: str, backends: str | Sequence[str] = "numpy", out: str | Path = ".",
         name: str | None = None, *, cache: bool = True, timeout: float | None = None) -> list[Path]:
    """Write the code of ``expression`` for each of ``backends`` (``"c"``, ``"numpy"``, ``"jax"``,
    ``"torch"``, a list of them or ``"all"``) into ``out`` (several: ``out/BACKEND/``), all files or
    none, as ``symrot derive EXPR --emit … --out OUT`` does; return the paths written. ``cache``:
    read and keep the evaluation plan in the plan cache; ``timeout``: the command's ``--timeout``."""
    names = backends if isinstance(backends, str) else ",".join(backends)
    command = ["derive", str(expression), "--emit", names, "--out", str(out)]
    command += ["--name", name] if name is not None else []
    command += [] if cache else ["--no-cache"]
    command += ["--timeout", str(timeout)] if timeout is not None else []
    printed = _run(command)
    return [Path(line) for line in printed.splitlines() if line.strip()]


def kernels(expression: str, backend: str = "numpy", name: str | None = None) -> ModuleType:
    """The generated ``backend`` module of ``expression`` (a registry name such as
    ``"wiener_milenkovic"`` or an expression in ``phi``), imported; see the module docstring for
    where it is kept. Raises :class:`~symrot.core.errors.SymrotError` with one line for a bad
    expression or name, an unknown backend, or a backend whose framework is not installed."""
    if backend not in BACKENDS:
        raise SymrotError(f"kernels(backend={backend!r}): choose from {', '.join(BACKENDS)}")
    key = hashlib.sha256(json.dumps([str(expression), backend, name, _code_digest()]).encode()).hexdigest()
    if key in _LOADED:
        return _LOADED[key]
    folder = _cache_folder()
    path = _cached(folder / key) if folder is not None else None
    if path is None:
        with tempfile.TemporaryDirectory(prefix="symrot-kernels-") as scratch:
            written = emit(expression, backend, scratch, name)
            if len(written) != 1 or written[0].suffix != ".py":
                raise SymrotError(f"--emit {backend} wrote {len(written)} files, not one module")
            text = written[0].read_text(encoding="utf-8")
            path = written[0]
            if folder is not None:
                path = _store(folder / key, written[0].name, text) or path
            module = _load(path, key, backend)
    else:
        module = _load(path, key, backend)
    _LOADED[key] = module
    return module


def _run(arguments: list[str]) -> str:
    """stdout of ``python -m symrot ARGUMENTS``; its last line of stderr raised where it fails."""
    result = subprocess.run([sys.executable, "-m", "symrot", *arguments], capture_output=True, text=True,
                            check=False)
    if result.returncode != 0:
        lines = [line for line in result.stderr.splitlines() if line.strip()]
        raise SymrotError(lines[-1] if lines else f"symrot {arguments[0]} failed ({result.returncode})")
    return result.stdout


@lru_cache(maxsize=1)
def _code_digest() -> str:
    """SHA-256 of every file of the symrot package and of the versions the code depends on."""
    digest = hashlib.sha256(sys.version.encode())
    for package in ("sympy", "numpy", "mpmath"):
        try:
            digest.update(f"{package} {importlib.metadata.version(package)}".encode())
        except importlib.metadata.PackageNotFoundError:
            digest.update(f"{package} absent".encode())
    root = Path(__file__).resolve().parent
    for path in sorted(root.rglob("*")):
        if path.is_file() and "__pycache__" not in path.parts:
            digest.update(str(path.relative_to(root)).encode() + b"\0" + path.read_bytes() + b"\0")
    return digest.hexdigest()


def _cache_folder() -> Path | None:
    """The folder of :data:`SUBDIRECTORY`, beside the plan cache (the same rules), or None where
    there is no place: ``SYMROT_NO_CACHE`` set, or none of the variables usable."""
    if os.environ.get("SYMROT_NO_CACHE", "") not in ("", "0"):
        return None
    explicit = os.environ.get("SYMROT_CACHE_DIR")
    if explicit:
        return Path(explicit) / SUBDIRECTORY
    xdg = os.environ.get("XDG_CACHE_HOME", "")
    if os.path.isabs(xdg):
        return Path(xdg) / "symrot" / SUBDIRECTORY
    home = os.environ.get("HOME", "")
    if os.path.isabs(home) and home.strip("/"):
        return Path(home) / ".cache" / "symrot" / SUBDIRECTORY
    return None


def _private(path: Path) -> bool:
    """``path`` belongs to this user and nobody else may write it: code is imported from there."""
    if not hasattr(os, "getuid"):
        return True
    info = path.stat()
    return info.st_uid == os.getuid() and not info.st_mode & (stat.S_IWGRP | stat.S_IWOTH)


def _cached(entry: Path) -> Path | None:
    """The module kept in ``entry`` when it is private to this user and its checksum holds."""
    try:
        (module,) = list(entry.glob("*.py"))
        checksum = entry / f"{module.name}.sha256"
        if not all(_private(path) for path in (entry, module, checksum)):
            return None
        if hashlib.sha256(module.read_bytes()).hexdigest() == checksum.read_text(encoding="ascii").strip():
            return module
    except (OSError, ValueError):
        pass
    return None


def _store(entry: Path, filename: str, text: str) -> Path | None:
    """Keep ``text`` as ``entry/filename`` with its checksum (each file replaced atomically);
    None where the cache cannot be written (the module is then loaded from the scratch copy)."""
    try:
        entry.mkdir(mode=0o700, parents=True, exist_ok=True)
        path = write_atomic(entry / filename, text)
        write_atomic(entry / f"{filename}.sha256", hashlib.sha256(text.encode()).hexdigest() + "\n")
        return path
    except OSError:
        return None


def _load(path: Path, key: str, backend: str) -> ModuleType:
    """Import the module at ``path`` under a name of its own; ``backend`` set on it."""
    module_name = f"symrot_kernels_{key[:16]}_{path.stem}"
    spec = importlib.util.spec_from_file_location(module_name, path)
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    sys.modules[module_name] = module
    try:
        spec.loader.exec_module(module)
    except ImportError as error:
        del sys.modules[module_name]
        raise SymrotError(f"kernels(backend={backend!r}) needs {error.name or 'its framework'}: "
                          f"pip install 'symrot[{backend}]'") from None
    module.backend = backend  # type: ignore[attr-defined]
    return module


__all__ = ["BACKENDS", "emit", "kernels"]
