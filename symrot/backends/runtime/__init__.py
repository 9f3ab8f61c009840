"""The runtimes of the generated Python modules, as ordinary, linted, type-checked and tested code.

Each file here holds the code that a generated module needs whatever its plan: the NumPy module's
(:mod:`~symrot.backends.runtime.numpy_runtime`), the array modules' shared part
(:mod:`~symrot.backends.runtime.array_runtime`) and each framework's primitives
(:mod:`~symrot.backends.runtime.jax_runtime`, :mod:`~symrot.backends.runtime.torch_runtime`).
Below a marker line, a file's text is copied verbatim into every module the backends write, so a
generated module needs only its framework; above it, stand-ins give the names a plan defines, so
that the file also imports on its own (tests/test_runtime.py binds them to a hand-written plan).
"""

from __future__ import annotations

from functools import cache
from importlib.resources import files

MARKER = "# --- copied into every generated "
"""The start of the line after which a runtime file's text is copied."""


@cache
def runtime_text(name: str) -> str:
    """The copied part of ``symrot/backends/runtime/<name>.py``: every line after its marker line."""
    text = files("symrot.backends.runtime").joinpath(f"{name}.py").read_text(encoding="utf-8")
    _head, marker, tail = text.partition("\n" + MARKER)
    if not marker or MARKER in tail:
        raise ValueError(f"{name}.py: expected one line starting with {MARKER!r}")
    return tail.split("\n", 1)[1].lstrip("\n")
