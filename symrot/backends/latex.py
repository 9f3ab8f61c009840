"""LaTeX for papers: Table 1 of the paper and per-parameterization derivation sheets.

One printer, a subclass of SymPy's LatexPrinter that only overrides what differs from the
paper's notation: φ is written ``\\varphi``; a trigonometric function of a fraction of φ is
``\\tan\\frac{\\varphi}{4}`` at the top level and ``\\tan(\\varphi/4)`` inside a fraction, so that no
fraction is ever nested in another one (the inner one would drop to scriptscript size); and the
radicand of a root is printed with its common factor taken out, so p and its derived functions
show the same form (∛(6(φ − sin φ)) in every cell of a row). Every value comes from the
derivation (symbolic core) and the singularity analysis (Section 3.4); the templates under
``templates/latex/`` only lay them out.
"""

from __future__ import annotations

import re
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any, Protocol

import sympy as sp
from sympy.printing.latex import LatexPrinter

from symrot.backends.templating import render
from symrot.core.derivation import SCALAR_EQUATIONS, TENSOR_EQUATIONS, TENSOR_NAMES, Derivation
from symrot.core.derivatives import (
    DIFFERENTIATED,
    ROOT_DIFFERENTIATED,
    SLOPES,
    VALUES,
    rate_vector,
    slope_name,
    tensor_derivative,
)
from symrot.core.functions import RealCbrt
from symrot.core.parsing import PHI
from symrot.core.registry import NamedParameterization


class NamedDerivation(Protocol):
    """What the tables and sheets read: a derivation and its registry entry, if any.

    :class:`symrot.api.DerivationResult` is one; the backend depends on this shape, not on the API.
    """

    @property
    def derivation(self) -> Derivation: ...

    @property
    def entry(self) -> NamedParameterization | None: ...


class PaperLatexPrinter(LatexPrinter):
    """LaTeX in the notation of Bauchau & Trainelli (2003), with no fraction inside a fraction."""

    def __init__(self, settings: dict[str, Any] | None = None) -> None:
        super().__init__({"symbol_names": {PHI: r"\varphi"}, **(settings or {})})
        self._fraction_depth = 0

    def doprint(self, expr: Any) -> str:
        return str(super().doprint(common_radicands(expr)))

    def _print_Mul(self, expr: sp.Expr) -> str:  # also reached for x**-n from _print_Pow
        """A fraction inside a fraction is slashed, ``a/(b c)``; the outer one stays ``\\frac``."""
        numerator, denominator = sp.fraction(expr, exact=True)
        if denominator == 1 or self._fraction_depth == 0:
            self._fraction_depth += denominator != 1
            try:
                return str(super()._print_Mul(expr))
            finally:
                self._fraction_depth -= denominator != 1
        sign = ""
        if expr.could_extract_minus_sign():
            sign = "- "
            numerator, denominator = sp.fraction(-expr, exact=True)
        top, bottom = self._print(numerator), self._print(denominator)
        if numerator.is_Add:
            top = rf"\left({top}\right)"
        if denominator.is_Add or denominator.is_Mul:
            bottom = rf"\left({bottom}\right)"
        return f"{sign}{top}/{bottom}"

    def _print_Rational(self, expr: sp.Rational) -> str:
        if self._fraction_depth == 0 or expr.q == 1:
            return str(super()._print_Rational(expr))
        return f"{'- ' if expr.p < 0 else ''}{abs(expr.p)}/{expr.q}"

    def _print_trig(self, expr: sp.Expr, name: str, exp: Any = None) -> str:
        argument = expr.args[0]
        numerator, denominator = sp.fraction(argument)
        head = rf"\{name}" + ("" if exp is None else "^{%s}" % exp)
        simple = argument.is_Symbol or argument.is_Number
        if denominator != 1 and numerator.has(PHI) and not numerator.is_Add:
            top, bottom = self._print(numerator), self._print(denominator)
            if self._fraction_depth == 0:
                return rf"{head}\frac{{{top}}}{{{bottom}}}"
            return rf"{head}({top}/{bottom})"
        body = self._print(argument)
        return rf"{head} {body}" if simple else rf"{head}\left({body}\right)"

    def _print_MatrixBase(self, expr: sp.MatrixBase) -> str:
        """A bracketed matrix with display-style entries (fractions at full size)."""
        rows = [" & ".join(r"\displaystyle " + self._print(expr[i, j]) for j in range(expr.cols))
                for i in range(expr.rows)]
        return r"\begin{bmatrix}" + r" \\[2ex] ".join(rows) + r"\end{bmatrix}"

    def _print_RealCbrt(self, expr: sp.Expr, exp: Any = None) -> str:
        root = r"\sqrt[3]{%s}" % self._print(expr.args[0])
        return root if exp is None else r"\left(%s\right)^{%s}" % (root, exp)

    def _print_sin(self, expr: sp.Expr, exp: Any = None) -> str:
        return self._print_trig(expr, "sin", exp)

    def _print_cos(self, expr: sp.Expr, exp: Any = None) -> str:
        return self._print_trig(expr, "cos", exp)

    def _print_tan(self, expr: sp.Expr, exp: Any = None) -> str:
        return self._print_trig(expr, "tan", exp)


def common_radicands(expr: Any) -> Any:
    """``expr`` with the common factor of every root's radicand taken out (an identity).

    The simplifier may return ∛(6φ − 6 sin φ) for p and ∛(6(φ − sin φ)) inside p′; printing every
    radicand as ``factor_terms`` of itself makes the forms of one row agree.
    """
    expr = sp.sympify(expr)
    if not isinstance(expr, sp.Basic) or expr.is_Atom:
        return expr
    return expr.replace(
        lambda e: isinstance(e, RealCbrt) or (e.is_Pow and e.exp.is_Rational and not e.exp.is_Integer),
        lambda e: e.func(*[sp.factor_terms(a) for a in e.args]),
    )


def latex(expr: sp.Expr | int) -> str:
    """``expr`` in the paper's notation (the one printer of every table, sheet and legend)."""
    return PaperLatexPrinter().doprint(sp.sympify(expr))


QUANTITY_SYMBOLS = {"p": "p", "p_prime": "p'", "nu": r"\nu", "epsilon": r"\varepsilon",
                    "mu": r"\mu", "det_H": r"\det\mathbf{H}"}
"""The paper's symbol of each scalar function (keys as in :data:`symrot.core.derivation.SCALAR_NAMES`)."""
TENSOR_SYMBOLS = {"R": r"\mathbf{R}", "H": r"\mathbf{H}", "H_inverse": r"\mathbf{H}^{-1}",
                  "G": r"\mathbf{G}", "K": r"\mathbf{K}"}
CANONICAL_EQUATIONS = {"R": "17", "H": "23", "H_inverse": "27", "G": "81", "K": "83"}
"""The paper's equation of each tensor's components in the basis {u, v, w}."""
LIMITS = {"0": "0", "oo": r"\infty"}
CAUSE_MEANINGS = {
    ("p", "oo"): r"the generating function is singular",
    ("nu", "0"): r"the kinematic inversion through Euler--Rodrigues parameters, eq.~(75), fails",
    ("nu", "oo"): r"the kinematic inversion through Euler--Rodrigues parameters, eq.~(75), fails",
    ("p_prime", "0"): r"$\mu \to \infty$, so $\mathbf{H}$, eq.~(22), is unbounded and"
                      r" $\mathbf{H}^{-1}$, eq.~(26), singular",
    ("p_prime", "oo"): r"$\mu \to 0$, so $\mathbf{H}$, eq.~(22), is singular",
    ("det_H", "0"): r"$\mathbf{H}$ is singular, eq.~(24)",
    ("det_H", "oo"): r"$\mathbf{H}^{-1}$ is singular, eq.~(24)",
    ("monotonicity", "0"): r"$p'$ changes sign, so $\|\mathbf{p}\|$ no longer determines"
                           r" $\varphi$",
    ("p", "edge"): r"$p$ is not real beyond this angle (the edge of its real domain)",
    ("monotonicity", "jump"): r"$p'$ jumps across 0 ($p$ has a kink), so $\|\mathbf{p}\|$ no longer"
                              r" determines $\varphi$",
    ("p", "jump"): r"$p$ jumps (is discontinuous), so $\|\mathbf{p}\|$ no longer determines $\varphi$",
}
"""What each kind of singularity of :data:`symrot.core.singularities.CAUSES` means, as LaTeX."""
SERIES = (("nu", r"\nu"), ("mu", r"\mu"), ("det_H", r"\det\mathbf{H}"),
          ("R_1", r"c_1^{\mathbf{R}}"), ("R_2", r"c_2^{\mathbf{R}}"),
          ("H_2", r"c_2^{\mathbf{H}}"), ("H_inverse_2", r"c_2^{\mathbf{H}^{-1}}"))
"""The coefficients whose series in x = ‖p‖² the sheets show, with their symbols."""


def series_latex(coefficients: list[sp.Expr], variable: str = "x") -> str:
    """The sum c₀ + c₁ x + … + c_{n−1} x^{n−1} + O(x^n), ascending."""
    x = sp.Symbol(variable)
    terms = [latex(c * x**j) for j, c in enumerate(coefficients) if c != 0]
    body = " + ".join(terms).replace("+ -", "-") if terms else "0"
    return body + rf" + O\left({variable}^{{{len(coefficients)}}}\right)"


def angle_latex(value: sp.Expr) -> str:
    return r"\infty" if value == sp.oo else latex(value)


def cause_latex(quantity: str, limit: str) -> str:
    """The short math for a singularity: ``\\nu \\to 0``, ``p' \\gtrless 0`` (sign change)."""
    if quantity == "monotonicity":
        return r"p' \gtrless 0"
    if limit == "edge":
        return r"p \notin \mathbb{R}\ \text{beyond}"
    if limit == "jump":
        return r"p\ \text{jumps}"
    return rf"{QUANTITY_SYMBOLS[quantity]} \to {LIMITS[limit]}"


@dataclass(frozen=True)
class CauseText:
    """One singular angle as LaTeX: where, the condition in short math, and what it means."""

    angle: str
    condition: str
    meaning: str
    at_edge: bool
    """At the validity bound (the angle is then the one of the validity range)."""


@dataclass(frozen=True)
class ValidityText:
    """Validity range and singularities as LaTeX, from :mod:`symrot.core.singularities`."""

    phi_max: sp.Expr
    range: str
    p_max: str
    singularities: tuple[CauseText, ...]
    """The singular angles ``symrot derive`` lists (up to twice the bound)."""
    numeric_only: bool


def validity_text(derivation: Derivation) -> ValidityText:
    from symrot.core.singularities import validity

    result = validity(derivation)
    p_max = r"\infty" if result.p_max_float == float("inf") else f"{result.p_max_float:.6g}"
    causes = tuple(
        CauseText(angle_latex(s.phi), cause_latex(s.quantity, s.limit),
                  CAUSE_MEANINGS[(s.quantity, s.limit)], s.phi == result.phi_max)
        for s in result.listed()
    )
    return ValidityText(result.phi_max, rf"|\varphi| < {angle_latex(result.phi_max)}", p_max,
                        causes, result.numeric_only)


def _escape(text: str) -> str:
    for plain, escaped in (("\\", r"\textbackslash{}"), ("&", r"\&"), ("%", r"\%"), ("#", r"\#"),
                           ("_", r"\_"), ("{", r"\{"), ("}", r"\}"), ("^", r"\^{}"),
                           ("~", r"\~{}"), ("$", r"\$")):
        text = text.replace(plain, escaped)
    return text


def title_of(result: NamedDerivation) -> str:
    """The registry title typeset: en-dashes between names, ``$m = 4$``, ``$\\det\\mathbf{H}$``;
    an expression without a registry entry is titled by its p(φ)."""
    if result.entry is None:
        return "$p = " + latex(result.derivation.p) + "$"
    text = _escape(result.entry.title)
    text = re.sub(r"(?<=[a-z])-(?=[A-Z])", "--", text)
    text = re.sub(r"\b([a-z]) = (\d+)", r"$\1 = \2$", text)
    return text.replace("det H", r"$\det\mathbf{H}$")


def _causes_cell(validity: ValidityText) -> str:
    """The singularities of one row as short math, grouped by angle (the bound's group first,
    without its angle, which the validity range already gives)."""
    if not validity.singularities:
        return "none"
    groups: dict[tuple[bool, str], list[str]] = {}
    for cause in validity.singularities:
        groups.setdefault((not cause.at_edge, cause.angle), []).append(f"${cause.condition}$")
    parts = [("" if not later else rf"at $\varphi = {angle}$: ") + ", ".join(conditions)
             for (later, angle), conditions in groups.items()]
    return "; ".join(parts)


def _caption(keys: list[str], causes: bool) -> str:
    symbols = [rf"${QUANTITY_SYMBOLS[k]}$~({SCALAR_EQUATIONS[k]})" for k in keys]
    listed = ", ".join(symbols[:-1]) + " and " + symbols[-1]
    text = (rf"Generating functions $p(\varphi)$, the scalar functions {listed} derived from "
            r"them, and the range of validity (Section~3.4)")
    if causes:
        text += " with the singularities that bound it"
    return text + ". Equation numbers refer to Bauchau and Trainelli (2003)."


FITS = ("none", "resize", "landscape")
"""How ``table`` fits the page: natural width at body size (default), scaled to the line width,
or rotated (``sidewaystable``). Only the default keeps the body font size."""


def table(results: Sequence[NamedDerivation], extra_columns: tuple[str, ...] = (),
          paper_validity: dict[str, sp.Expr] | None = None, fit: str = "none") -> str:
    """Table 1 (name, p, p′, ν (15), ε (16), validity) plus optional μ (21), det H (24) and causes.

    ``paper_validity`` maps registry identifiers to the bound printed in the paper's Table 1;
    rows where symrot's derived range differs get a table note generated from the data. Causes
    are short math (``\\nu \\to 0``) explained in a legend below the table.
    """
    if fit not in FITS:
        raise ValueError(f"fit must be one of {', '.join(FITS)}")
    keys = ["p_prime", "nu", "epsilon"] + [k for k in ("mu", "det_H") if k in extra_columns]
    causes = "causes" in extra_columns
    rows: list[dict[str, Any]] = []
    notes: list[str] = []
    legend: dict[str, str] = {}
    for result in results:
        d = result.derivation
        validity = validity_text(d)
        name = title_of(result)
        identifier = result.entry.identifier if result.entry else ""
        printed = (paper_validity or {}).get(identifier)
        marker = ""
        if printed is not None and sp.simplify(printed - validity.phi_max) != 0:
            marker = chr(ord("a") + len(notes))
            edge = [c for c in validity.singularities if c.at_edge]
            where = "; ".join(rf"${c.condition}$: {c.meaning}" for c in edge)
            notes.append(rf"\item[{marker}] {name}: the paper's Table~1 prints "
                         rf"$|\varphi| < {angle_latex(printed)}$; symrot finds "
                         rf"${validity.range}$" + (f" ({where})" if where else "") + ".")
            name += rf"\tnote{{{marker}}}"
        cells = [latex(value) for value in (d.p, *(d.scalars[k] for k in keys))]
        cells.append(validity.range)
        if causes:
            cells.append(_causes_cell(validity))
            legend.update((c.condition, c.meaning) for c in validity.singularities)
        tiers = _tiers(cells)
        if causes:  # text, wrapped in the rest of its line
            span = TIER_COLUMNS - len(tiers[-1]) + 1 if len(tiers) > 1 else 1
            tiers[-1][-1] = (rf"\multicolumn{{{span}}}{{>{{\raggedright\arraybackslash}}"
                             rf"p{{{3 * span}cm}}}}{{{tiers[-1][-1]}}}")
        rows.append({"name": name, "tiers": tiers})
    headers = [r"p(\varphi)"] + [QUANTITY_SYMBOLS[k] for k in keys] + [r"\text{Validity}"]
    if causes:
        headers.append(r"\text{Singular as}")
    return render("latex/table.tex.j2", header_tiers=_tiers(headers), rows=rows, notes=notes,
                  columns=min(len(headers), TIER_COLUMNS), legend=sorted(legend.items()),
                  caption=_caption(keys, causes), fit=fit)


TIER_COLUMNS = 5
"""Math columns per line of a row. Up to this many, the table has the paper's layout (a name
column); with more, each row is a name line followed by lines of at most this many values under
as many header lines, so the table keeps the body font size at any ``--columns`` (≤ 15 cm wide
at 11 pt for every named row)."""


def _tiers(cells: list[str]) -> list[list[str]]:
    return [cells[i:i + TIER_COLUMNS] for i in range(0, len(cells), TIER_COLUMNS)]


def sheet(result: NamedDerivation, series_terms: int = 4) -> str:
    """A derivation sheet: every derived formula, tagged with the paper equation it instantiates
    (p (30–36), κ (12), p′ and μ (21), ν (15), ε (16), det H (24); tensors (14), (22), (26),
    (81), (83) and their components in {u, v, w}, (17), (23), (27))."""
    d = result.derivation
    scalars = [(QUANTITY_SYMBOLS[k], latex(d.scalars[k]), SCALAR_EQUATIONS[k])
               for k in ("p_prime", "nu", "epsilon", "mu", "det_H")]
    tensors = [{
        "symbol": TENSOR_SYMBOLS[name],
        "equation": TENSOR_EQUATIONS[name],
        "canonical_equation": CANONICAL_EQUATIONS[name],
        "coefficients": [latex(c) for c in d.tensors[name].simplified],
        "canonical": latex(d.tensors[name].canonical),
    } for name in TENSOR_NAMES]
    series = [(symbol, series_latex(d.series_in_x(name, series_terms)))
              for name, symbol in SERIES]
    # the slopes as exact series (their closed forms dc/dφ / (2 p p′) can be wider than the page)
    slopes = [(TENSOR_SYMBOLS[name], [series_latex(d.series_in_x(slope_name(f"{name}_{k}"), series_terms))
                                      for k in range(3)])
              for name in (*DIFFERENTIATED, *ROOT_DIFFERENTIATED)]
    return render(
        "latex/sheet.tex.j2",
        title=title_of(result),
        equation=result.entry.equation if result.entry else None,
        p=latex(d.p),
        kappa=latex(d.kappa),
        scalars=scalars,
        tensors=tensors,
        series=series,
        terms=series_terms,
        validity=validity_text(d),
        derivative=derivative_latex(),
        rate=rate_latex(),
        slopes=slopes,
    )


_BASIS_LATEX = {"a*p": r"\mathbf{a}\otimes\mathbf{p}",
                "(p x a)*p": r"(\mathbf{p}\times\mathbf{a})\otimes\mathbf{p}",
                "(p x (p x a))*p": r"(\mathbf{p}\times(\mathbf{p}\times\mathbf{a}))\otimes\mathbf{p}",
                "[a x]": r"(\mathbf{a}\times)", "[(p x a) x]": r"((\mathbf{p}\times\mathbf{a})\times)",
                "[p x][a x]": r"(\mathbf{p}\times)(\mathbf{a}\times)",
                "a (p.a)": r"(\mathbf{p}\cdot\dot{\mathbf{p}})\,\dot{\mathbf{p}}",
                "(p x a) (p.a)": r"(\mathbf{p}\cdot\dot{\mathbf{p}})\,\mathbf{p}\times\dot{\mathbf{p}}",
                "(p x (p x a)) (p.a)": r"(\mathbf{p}\cdot\dot{\mathbf{p}})\,"
                                       r"\mathbf{p}\times(\mathbf{p}\times\dot{\mathbf{p}})",
                "(p x a) x a": r"(\mathbf{p}\times\dot{\mathbf{p}})\times\dot{\mathbf{p}}"}


def _combination(terms: dict[sp.Symbol, dict[str, sp.Rational]], symbols: dict[sp.Symbol, str],
                 break_after: int) -> tuple[str, str]:
    """Σ_s Σ_b k s b as LaTeX in the order the core derived it, split into two lines after
    ``break_after`` terms (the sheet's lines stay within the page)."""
    printed: list[str] = []
    for scalar, combination in terms.items():
        for name, factor in combination.items():
            magnitude = "" if abs(factor) == 1 else latex(abs(factor)) + r"\,"
            sign = "-" if factor < 0 else ("+" if printed else "")
            printed.append(rf"{sign} {magnitude}{symbols[scalar]}\,{_BASIS_LATEX[name]}".strip())
    return " ".join(printed[:break_after]), " ".join(printed[break_after:])


def derivative_latex() -> tuple[str, str]:
    """∂(T a)/∂p as derived by :func:`symrot.core.derivatives.tensor_derivative` (c_k′ = dc_k/dx): the
    rank-one terms, then the others."""
    symbols = {**{v: f"c_{k}" for k, v in enumerate(VALUES)}, **{s: f"c_{k}'" for k, s in enumerate(SLOPES)}}
    terms = tensor_derivative().terms
    rank_one = sum(name.endswith("*p") for combination in terms.values() for name in combination)
    return _combination(terms, symbols, rank_one)


def rate_latex() -> tuple[str, str]:
    """Ḣ ṗ as derived by :func:`symrot.core.derivatives.rate_vector` (coefficients of H), in two lines."""
    symbols = {**{v: rf"c_{k}^{{\mathbf{{H}}}}" for k, v in enumerate(VALUES)},
               **{s: rf"c_{k}^{{\mathbf{{H}}\prime}}" for k, s in enumerate(SLOPES)}}
    return _combination(rate_vector(), symbols, 2)


def standalone(body: str) -> str:
    """A complete article (11 pt, 2 cm margins) around ``body``, with every package the
    fragments need; PDF output carries no date or trailer ID, so it is reproducible."""
    return render("latex/standalone.tex.j2", body=body)


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
