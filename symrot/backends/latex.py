"""LaTeX printing of derived formulas, in the paper's notation.

A subclass of SymPy's LatexPrinter that only overrides what differs: φ is written ``\\varphi``
and trigonometric functions of a fraction of φ as ``\\tan\\frac{\\varphi}{4}``, as the paper does.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import sympy as sp
from sympy.printing.latex import LatexPrinter

from ..parsing import PHI

if TYPE_CHECKING:
    from ..api import DerivationResult


class PaperLatexPrinter(LatexPrinter):
    """LaTeX in the notation of Bauchau & Trainelli (2003)."""

    def __init__(self, settings: dict[str, Any] | None = None) -> None:
        super().__init__({"symbol_names": {PHI: r"\varphi"}, **(settings or {})})

    def _print_trig(self, expr: sp.Expr, name: str, exp: Any = None) -> str:
        argument = expr.args[0]
        numerator, denominator = sp.fraction(argument)
        if denominator != 1 and numerator.has(PHI) and not numerator.is_Add:
            body = r"\frac{%s}{%s}" % (self._print(numerator), self._print(denominator))
        else:
            body = self._print(argument)
            if not (argument.is_Symbol or argument.is_Number):
                body = r"\left(%s\right)" % body
        head = rf"\{name}"
        if exp is not None:
            head += "^{%s}" % exp
        return rf"{head}{{{body}}}" if body.startswith("\\frac") else rf"{head} {body}"

    def _print_sin(self, expr: sp.Expr, exp: Any = None) -> str:
        return self._print_trig(expr, "sin", exp)

    def _print_cos(self, expr: sp.Expr, exp: Any = None) -> str:
        return self._print_trig(expr, "cos", exp)

    def _print_tan(self, expr: sp.Expr, exp: Any = None) -> str:
        return self._print_trig(expr, "tan", exp)


def latex(expr: sp.Expr) -> str:
    return PaperLatexPrinter().doprint(expr)


def derivation_display(result: DerivationResult) -> str:
    """A compact LaTeX block (for Jupyter) of p, κ and the scalar functions."""
    d = result.derivation
    rows = [
        rf"p(\varphi) &= {latex(d.p)}",
        rf"\kappa &= {latex(d.kappa)}",
        rf"p' &= {latex(d.scalars['p_prime'])}",
        rf"\nu &= {latex(d.scalars['nu'])}",
        rf"\varepsilon &= {latex(d.scalars['epsilon'])}",
        rf"\mu &= {latex(d.scalars['mu'])}",
        rf"\det\mathbf{{H}} &= {latex(d.scalars['det_H'])}",
    ]
    return r"$\begin{aligned}" + r" \\ ".join(rows) + r"\end{aligned}$"
