"""Common subexpressions for the printing backends (``sympy.cse``), without unread temporaries."""

from __future__ import annotations

import re
from collections.abc import Sequence
from typing import Any

import sympy as sp


def common_subexpressions(exprs: Sequence[sp.Expr], prefix: str) -> tuple[list[tuple[sp.Symbol, sp.Expr]],
                                                                          list[sp.Expr]]:
    """``sympy.cse`` of ``exprs`` (temporaries ``prefix``0, 1, …), keeping only the replacements that
    the reduced expressions read, directly or through a kept replacement. SymPy can leave one that
    nothing reads: for (e^φ − e^−φ) in −4(e^φ − e^−φ)/((e^φ − e^−φ)(e^φ + e^−φ)³) (a coefficient of
    (exp(phi) - exp(-phi))/2) the quotient cancels to −1 once the temporary is substituted, and the
    unused ``const double w14`` failed the C header's -Werror build."""
    replacements, reduced = sp.cse(list(exprs), symbols=sp.numbered_symbols(prefix))
    needed: set[sp.Basic] = set().union(*(e.free_symbols for e in reduced))
    kept: list[tuple[sp.Symbol, sp.Expr]] = []
    for symbol, value in reversed(replacements):
        if symbol in needed:
            kept.append((symbol, value))
            needed |= value.free_symbols
    return kept[::-1], list(reduced)


def alias_repeated(functions: Sequence[dict[str, Any]]) -> list[dict[str, Any]]:
    """The printed functions (dicts with ``name``, ``args``, ``body``) with ``alias`` set to the name
    of an earlier function whose code is the same (None otherwise), so that a module prints each
    piece of code once and binds the other name to it (often the float32 plan's polynomial is the
    float64 one's). Calls of an aliased function count as calls of its original, so a function that
    differs only in calling an alias is an alias too."""
    seen: dict[tuple[str, tuple[str, ...]], str] = {}
    originals: dict[str, str] = {}
    result = []
    for function in functions:
        body = tuple(function["body"])
        for alias, original in originals.items():
            call = re.compile(rf"(?<![\w.]){re.escape(alias)}\(")
            body = tuple(call.sub(original + "(", line) for line in body)
        key = (function["args"], body)
        alias_of = seen.get(key)
        if alias_of is None:
            seen[key] = function["name"]
        else:
            originals[function["name"]] = alias_of
        result.append({**function, "alias": alias_of})
    return result
