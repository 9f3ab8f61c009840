"""Backends: modules that print evaluation plans or derivations through templates.

``EMITTERS`` maps a ``--emit`` name to a function ``emit(derivation, name, out_dir) -> [paths]``.
A backend registers itself with ``register_emitter`` (imported lazily by ``emitter``), so adding
one touches neither the core nor the CLI.
"""

from __future__ import annotations

import importlib
from collections.abc import Callable
from pathlib import Path
from typing import Any

from symrot.core.errors import SymrotError

Emitter = Callable[[Any, str, Path], list[Path]]
EMITTERS: dict[str, str] = {"numpy": "symrot.backends.numpy_backend:emit",
                            "c": "symrot.backends.c_backend:emit",
                            "jax": "symrot.backends.jax_backend:emit",
                            "torch": "symrot.backends.torch_backend:emit"}
"""name → "module:function"; backends append here (e.g. "c": "symrot.backends.c_backend:emit")."""


class UnknownBackend(SymrotError):
    """--emit names no registered backend."""


def register_emitter(name: str, target: str) -> None:
    EMITTERS[name] = target


def emitter(name: str) -> Emitter:
    if name not in EMITTERS:
        raise UnknownBackend(f"unknown backend {name!r}; choose from {', '.join(sorted(EMITTERS))}")
    module_name, function = EMITTERS[name].split(":")
    return getattr(importlib.import_module(module_name), function)
