"""Table 1, cell by cell for the rows legible in our text (linear, Euler-Rodrigues, 4 sin φ/4).

Columns as printed: p(φ), p′(φ), ν(φ), a fourth column the caption calls det(H), validity.
Each cell is compared with the symbolic core (eqs 15, 16, 21, 24); the fourth column is also
compared with ε (eq 16), which it matches, while det H = μν² (eq 24) differs.
"""

from __future__ import annotations

from collections.abc import Callable

import sympy as sp

from ..core import scalar_definitions
from ..parsing import PHI
from ..timeouts import time_limit
from .checks import ERRATUM, HOLDS, Check, Outcome

ROWS: dict[str, tuple[sp.Expr, dict[str, sp.Expr]]] = {
    "linear": (sp.sin(PHI), {"p_prime": sp.cos(PHI), "nu": 1 / sp.cos(PHI / 2),
                             "column4": 1 / sp.cos(PHI / 2) ** 2}),
    "euler_rodrigues": (2 * sp.sin(PHI / 2), {"p_prime": sp.cos(PHI / 2), "nu": sp.Integer(1),
                                              "column4": 1 / sp.cos(PHI / 2)}),
    "sine_m4": (4 * sp.sin(PHI / 4), {"p_prime": sp.cos(PHI / 4), "nu": sp.cos(PHI / 4),
                                      "column4": sp.cos(PHI / 4) / sp.cos(PHI / 2)}),
}


def _is_zero(expr: sp.Expr) -> bool:
    with time_limit(20, "Table 1 cell"):
        return bool(sp.simplify(sp.expand_trig(sp.expand_trig(expr).rewrite(sp.tan))) == 0) or \
            bool(sp.simplify(expr) == 0)


def _cell(row: str, column: str) -> Callable[[], Outcome]:
    def verify() -> Outcome:
        p, cells = ROWS[row]
        scalars = scalar_definitions(p)
        printed = cells[column]
        if column != "column4":
            residual = scalars[column] - printed
            if _is_zero(residual):
                return Outcome(HOLDS, f"{column} - printed simplifies to 0")
            return Outcome(ERRATUM, f"{column} - printed = {sp.simplify(residual)}")
        det_residual = scalars["det_H"] - printed
        if not _is_zero(scalars["epsilon"] - printed):
            raise ArithmeticError(f"Table 1 {row}: fourth column matches neither det H nor epsilon")
        if _is_zero(det_residual):
            return Outcome(HOLDS, "equals det H and epsilon")
        at_one = sp.N(det_residual.subs(PHI, 1), 50)
        return Outcome(ERRATUM, f"det H - printed at phi = 1: {sp.N(at_one, 20)} != 0; "
                       "epsilon - printed simplifies to 0",
                       "the fourth column (headed det(H) in the caption) lists epsilon = 2 tan(phi/2)/p")
    return verify


CHECKS = [
    Check(f"Table 1 {row} {column}", f"{column if column != 'column4' else 'det(H)'} = {cells[column]}",
          "symbolic", _cell(row, column))
    for row, (_, cells) in ROWS.items() for column in ("p_prime", "nu", "column4")
]
