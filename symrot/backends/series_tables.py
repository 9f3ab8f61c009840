"""The Taylor coefficients of a generated Python module as tuples, each printed once.

The plan gives every ``Branch`` its Horner polynomial (``Branch.horner``, constant term first). A
module's float32 plan usually takes the first terms of the float64 plan's series of the same
coefficient, and several coefficients share a series; printed as statements, the same coefficients
stood two or more times in one file. Here each distinct series is one tuple, and a polynomial that
is the start of another reads the longer tuple with its own number of terms (the runtime's
``_horner``), so the arithmetic, and every bit of the result, is that of the statements it replaces.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

PER_ROW = 3
"""Coefficients per printed row."""


class SeriesTables:
    """The tuples of one module, in the order their first polynomial was printed."""

    def __init__(self) -> None:
        self._tables: list[tuple[str, list[str]]] = []

    def reference(self, owner: str, literals: Sequence[str]) -> str:
        """The name of the tuple that holds ``literals`` (printed coefficients, constant term first)
        as its start, made or lengthened here; ``owner`` names a new tuple."""
        values = list(literals)
        for index, (name, stored) in enumerate(self._tables):
            common = min(len(values), len(stored))
            if stored[:common] == values[:common]:
                if len(values) > len(stored):
                    self._tables[index] = (name, values)
                return name
        taken = {name for name, _ in self._tables}
        name = f"_SERIES_{owner}"
        count = 1
        while name in taken:
            count += 1
            name = f"_SERIES_{owner}_{count}"
        self._tables.append((name, values))
        return name

    def context(self) -> list[dict[str, Any]]:
        """The tuples for a template: {"name", "rows"}, rows of PER_ROW literals each."""
        return [{"name": name, "rows": [", ".join(values[k:k + PER_ROW]) + ","
                                        for k in range(0, len(values), PER_ROW)]}
                for name, values in self._tables]
