"""The one Jinja2 environment every backend renders through.

Strict (``StrictUndefined``: a missing variable is an error, never an empty string), no
auto-escaping (we emit code and LaTeX, not HTML), trailing newlines kept, and nothing
time-dependent is ever passed in, so output is byte-identical across runs. Templates live in the
``symrot/backends/templates/`` directory (the ``symrot.backends.templates`` package, shipped in the wheel).
"""

from __future__ import annotations

from functools import lru_cache
from importlib.resources import files
from typing import Any

import jinja2


@lru_cache(maxsize=1)
def environment() -> jinja2.Environment:
    root = files("symrot.backends.templates")
    return jinja2.Environment(
        loader=jinja2.FileSystemLoader(str(root)),
        undefined=jinja2.StrictUndefined,
        autoescape=False,
        keep_trailing_newline=True,
        trim_blocks=True,
        lstrip_blocks=True,
    )


def render(template_name: str, **context: Any) -> str:
    """Render ``templates/<template_name>`` with ``context``."""
    return environment().get_template(template_name).render(**context)


def macro(template_name: str, name: str, *args: Any) -> str:
    """The text of macro ``name`` of ``templates/<template_name>`` called with ``args`` (for
    functions that are the same in every output but for a few names, e.g. ``c/shared.h.j2``)."""
    return str(getattr(environment().get_template(template_name).module, name)(*args))
