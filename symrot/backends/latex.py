"""LaTeX for papers: Table 1 of the paper and per-parameterization derivation sheets.

A subclass of SymPy's LatexPrinter that only overrides what differs from the paper's notation:
φ is written ``\\varphi`` and trigonometric functions of a fraction of φ as
``\\tan\\frac{\\varphi}{4}``. Every value comes from the derivation (symbolic core) and the
singularity analysis; the templates under ``templates/latex/`` only lay them out.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any, Protocol

import sympy as sp
from sympy.printing.latex import LatexPrinter

from ..core import SCALAR_EQUATIONS, TENSOR_EQUATIONS, TENSOR_NAMES, Derivation
from ..parsing import PHI
from ..registry import NamedParameterization
from .templating import render


class NamedDerivation(Protocol):
    """What the tables and sheets read: a derivation and its registry entry, if any.

    :class:`symrot.api.DerivationResult` is one; the backend depends on this shape, not on the API.
    """

    @property
    def derivation(self) -> Derivation: ...

    @property
    def entry(self) -> NamedParameterization | None: ...


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

    def _print_RealCbrt(self, expr: sp.Expr, exp: Any = None) -> str:
        root = r"\sqrt[3]{%s}" % self._print(expr.args[0])
        return root if exp is None else r"\left(%s\right)^{%s}" % (root, exp)

    def _print_sin(self, expr: sp.Expr, exp: Any = None) -> str:
        return self._print_trig(expr, "sin", exp)

    def _print_cos(self, expr: sp.Expr, exp: Any = None) -> str:
        return self._print_trig(expr, "cos", exp)

    def _print_tan(self, expr: sp.Expr, exp: Any = None) -> str:
        return self._print_trig(expr, "tan", exp)


def latex(expr: sp.Expr | int) -> str:
    return PaperLatexPrinter().doprint(sp.sympify(expr))


def series_latex(coefficients: list[sp.Expr], variable: str = "x") -> str:
    """c0 + c1 x + ... + O(x^n), ascending, as the leading series of a coefficient."""
    x = sp.Symbol(variable)
    terms = [latex(c * x**j) for j, c in enumerate(coefficients) if c != 0]
    if not terms:
        return "0"
    body = " + ".join(terms).replace("+ -", "- ")
    return body + rf" + O\left({variable}^{{{len(coefficients)}}}\right)"


def angle_latex(value: sp.Expr) -> str:
    return r"\infty" if value == sp.oo else latex(value)


@dataclass(frozen=True)
class ValidityText:
    """Validity range and singularities as LaTeX, from :mod:`symrot.singularities`."""

    phi_max: sp.Expr
    range: str
    p_max: str
    singularities: tuple[tuple[str, str, str], ...]
    """(angle, quantity → limit, cause)."""
    numeric_only: bool


def validity_text(derivation: Derivation) -> ValidityText:
    from ..singularities import validity

    result = validity(derivation)
    p_max = r"\infty" if result.p_max_float == float("inf") else f"{result.p_max_float:.6g}"
    rows = tuple(
        (angle_latex(s.phi), rf"\texttt{{{s.quantity.replace('_', '-')}}} \to {_limit(s.limit)}",
         _escape(s.cause))
        for s in result.singularities
    )
    return ValidityText(result.phi_max, rf"|\varphi| < {angle_latex(result.phi_max)}", p_max, rows,
                        result.numeric_only)


def _limit(text: str) -> str:
    return {"oo": r"\infty", "-oo": r"-\infty"}.get(text, _escape(text))


def _escape(text: str) -> str:
    for plain, escaped in (("\\", r"\textbackslash{}"), ("&", r"\&"), ("%", r"\%"), ("#", r"\#"),
                           ("_", r"\_"), ("{", r"\{"), ("}", r"\}"), ("^", r"\^{}"),
                           ("~", r"\~{}"), ("$", r"\$"), ("<", r"$<$"), (">", r"$>$")):
        text = text.replace(plain, escaped)
    return text.replace("-$>$", r"$\to$")


def title_of(result: NamedDerivation) -> str:
    if result.entry is not None:
        return _escape(result.entry.title)
    return "$p = " + latex(result.derivation.p) + "$"


def table(results: Sequence[NamedDerivation], extra_columns: tuple[str, ...] = (),
          paper_validity: dict[str, sp.Expr] | None = None) -> str:
    """Table 1 (name, p, p′, ν, ε, validity) plus optional μ, det H and singularity columns.

    ``paper_validity`` maps registry identifiers to the bound printed in the paper's Table 1;
    rows where symrot's derived range differs get a footnote generated from the data.
    """
    rows: list[list[str]] = []
    notes: list[tuple[int, str, str, str, str]] = []
    for result in results:
        d = result.derivation
        validity = validity_text(d)
        cells = [title_of(result)] + [
            "$" + latex(value) + "$"
            for value in (d.p, d.scalars["p_prime"], d.scalars["nu"], d.scalars["epsilon"])
        ]
        if "mu" in extra_columns:
            cells.append("$" + latex(d.scalars["mu"]) + "$")
        if "det_H" in extra_columns:
            cells.append("$" + latex(d.scalars["det_H"]) + "$")
        validity_cell = "$" + validity.range + "$"
        identifier = result.entry.identifier if result.entry else None
        printed = (paper_validity or {}).get(identifier or "")
        if printed is not None and sp.simplify(printed - validity.phi_max) != 0:
            printed_text = rf"|\varphi| < {angle_latex(printed)}"
            notes.append((len(notes) + 1, title_of(result), printed_text, validity.range,
                          validity.singularities[0][2] if validity.singularities else ""))
            validity_cell += rf"$^{{{len(notes)}}}$"
        cells.append(validity_cell)
        if "causes" in extra_columns:
            cells.append("; ".join(s[2] for s in validity.singularities[:2]) or "none")
        rows.append(cells)
    headers = ["Name", r"$p(\varphi)$", r"$p'$", r"$\nu$", r"$\varepsilon$"]
    headers += [h for key, h in (("mu", r"$\mu$"), ("det_H", r"$\det\mathbf{H}$"))
                if key in extra_columns]
    headers.append("Validity")
    if "causes" in extra_columns:
        headers.append("Singularity")
    return render("latex/table.tex.j2", headers=headers, rows=rows, notes=notes)


def sheet(result: NamedDerivation, series_terms: int = 4) -> str:
    """A derivation sheet: every derived formula with the paper equation it instantiates."""
    d = result.derivation
    scalars = [
        (r"p'", d.scalars["p_prime"], SCALAR_EQUATIONS["p_prime"]),
        (r"\nu", d.scalars["nu"], SCALAR_EQUATIONS["nu"]),
        (r"\varepsilon", d.scalars["epsilon"], SCALAR_EQUATIONS["epsilon"]),
        (r"\mu", d.scalars["mu"], SCALAR_EQUATIONS["mu"]),
        (r"\det\mathbf{H}", d.scalars["det_H"], SCALAR_EQUATIONS["det_H"]),
    ]
    symbols = {"R": r"\mathbf{R}", "H": r"\mathbf{H}", "H_inverse": r"\mathbf{H}^{-1}",
               "G": r"\mathbf{G}", "K": r"\mathbf{K}"}
    canonical_eq = {"R": "17", "H": "23", "H_inverse": "27", "G": "81", "K": "83"}
    tensors = []
    for name in TENSOR_NAMES:
        tensor = d.tensors[name]
        tensors.append({
            "symbol": symbols[name],
            "equation": TENSOR_EQUATIONS[name],
            "canonical_equation": canonical_eq[name],
            "coefficients": [latex(c) for c in tensor.simplified],
            "canonical": latex(tensor.canonical),
        })
    series_names = ("nu", "mu", "det_H", "R_1", "R_2", "H_2", "H_inverse_2")
    series = [(_escape(n), series_latex(d.series_in_x(n, series_terms))) for n in series_names]
    return render(
        "latex/sheet.tex.j2",
        title=title_of(result),
        equation=result.entry.equation if result.entry else None,
        p=latex(d.p),
        kappa=latex(d.kappa),
        scalars=[(symbol, latex(value), eq) for symbol, value, eq in scalars],
        tensors=tensors,
        series=series,
        validity=validity_text(d),
    )


def standalone(body: str, landscape: bool = False) -> str:
    return render("latex/standalone.tex.j2", body=body, landscape=landscape)


def derivation_display(result: NamedDerivation) -> str:
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
