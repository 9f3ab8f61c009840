"""Strict JSON for every ``--json`` output and ``generated/derivations/*.json``.

Python's ``json`` writes ``Infinity`` and ``NaN``, which strict parsers (JavaScript's
``JSON.parse``, jq, Go, Rust's serde_json) reject. Non-finite numbers are therefore written as
the strings ``"inf"`` and ``"-inf"`` (e.g. ``p_max_float`` of an unbounded p, eq 33) and NaN as
``null``; everything else is unchanged.
"""

from __future__ import annotations

import json
import math
from typing import Any


def strict(value: Any) -> Any:
    """``value`` with every non-finite float replaced as described in the module docstring."""
    if isinstance(value, float) and not math.isfinite(value):
        return None if math.isnan(value) else ("inf" if value > 0 else "-inf")
    if isinstance(value, dict):
        return {key: strict(item) for key, item in value.items()}
    if isinstance(value, list | tuple):
        return [strict(item) for item in value]
    return value


def dumps(value: Any, **options: Any) -> str:
    """``json.dumps`` of :func:`strict` ``(value)``; never writes Infinity or NaN."""
    return json.dumps(strict(value), allow_nan=False, **options)
