"""Common subexpressions for the printing backends (``sympy.cse``), without unread temporaries."""

from __future__ import annotations

from collections.abc import Sequence

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
