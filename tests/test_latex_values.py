"""The formulas that the LaTeX sheets and Table 1 print have the right values (issue 61).

Each printed formula is read back by :mod:`tests.latex_reader` (no SymPy, no symrot) and evaluated
at several angles inside the validity range, against values from the definitions: ν = 2 sin(φ/2)/p
(eq 15), ε = 2 tan(φ/2)/p (16), μ = 1/p′ (21), det H = μν² (24), p′ by numerical differentiation
of p, κ = lim p/φ (12), and the tensors R, H, H⁻¹, G, K of :mod:`tests.reference` at p = (0, 0, s):
T = c₀ I + c₁ (p×) + c₂ (p×)² gives c₀ = T₂₂, c₁ = T₁₀/s, c₂ = (T₂₂ − T₀₀)/s², and [T] is T in the
basis {u, v, w} = {e_z, e_x, e_y}. A sign, a factor or a swapped fraction in the printer changes a
value and fails here, where tests/test_latex.py only checks that the documents compile.
"""

from __future__ import annotations

import functools
import re
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import mpmath
import pytest

import symrot
import symrot.core.parsing
from symrot.backends.latex import sheet
from symrot.core.registry import NAMED, TABLE_1

from .corpus import by_expression
from .latex_reader import LatexSyntaxError, read
from .reference import PHI, GeneratingFunction, Reference, mp_function, parse

LATEX = Path(__file__).resolve().parent.parent / "generated" / "latex"
DIGITS = 40
"""Working precision of the reader's evaluation (the reference has 60 digits)."""
TOLERANCE = mpmath.mpf("1e-10")
ANGLES = ("0.3", "1.1", "2.0")
LARGE = mpmath.mpf("0.9")
"""Besides ANGLES (those below LARGE φ_max), every formula is checked at LARGE φ_max."""


@dataclass(frozen=True)
class Family:
    """A named parameterization as the paper defines it (not from symrot's registry)."""

    expression: str
    label: str
    """A word its Table 1 row names it by."""


FAMILIES = {
    "rotation_vector": Family("phi", "Rotation vector"),
    "linear": Family("sin(phi)", "Linear"),
    "euler_rodrigues": Family("2*sin(phi/2)", "Euler--Rodrigues"),
    "cayley_gibbs_rodrigues": Family("2*tan(phi/2)", "Cayley--Gibbs--Rodrigues"),
    "wiener_milenkovic": Family("4*tan(phi/4)", "Wiener--Milenkovic"),
    "det_h_one": Family("cbrt(6*(phi - sin(phi)))", "det"),
    "sine_m4": Family("4*sin(phi/4)", "Sine"),
}
CORPUS_SHEETS = ("phi + phi**3/6", "2*tanh(phi/2)")
"""Two cheap user functions of tests/corpus.py whose sheets are made fresh (polynomial, hyperbolic)."""

SCALARS = {"p(\\varphi)": "p", "\\kappa": "kappa", "p'": "p_prime", "\\nu": "nu",
           "\\varepsilon": "epsilon", "\\mu": "mu", "\\det\\mathbf{H}": "det_H"}
TENSORS = {"\\mathbf{R}": "R", "\\mathbf{H}": "H", "\\mathbf{H}^{-1}": "H_inverse",
           "\\mathbf{G}": "G", "\\mathbf{K}": "K"}
BASIS = (2, 0, 1)
"""{u, v, w} = {e_z, e_x, e_y}: u along p = (0, 0, s), right-handed."""
KEYS = {*SCALARS.values(), *(f"{t}_{k}" for t in TENSORS.values() for k in range(3)),
        *(f"{t}[{i}][{j}]" for t in TENSORS.values() for i in range(3) for j in range(3))}
"""Every formula of a sheet: 7 scalars (p and κ among them), 15 coefficients, 45 matrix cells."""
END_TAG = re.compile(r"\s*(?:\\notag|\\tag\*?\{[^{}]*\})\s*$")


@functools.cache
def reference(expression: str) -> tuple[GeneratingFunction, Reference]:
    """The reference of ``expression``, φ_max from its own validity scan (:func:`validity_edge`)."""
    function = GeneratingFunction(expression)
    return function, Reference(function)


def angles(function: GeneratingFunction) -> list[mpmath.mpf]:
    top = LARGE * function.phi_max
    return [mpmath.mpf(a) for a in ANGLES if mpmath.mpf(a) < top] + [top]


@functools.cache
def expected(expression: str, angle: mpmath.mpf) -> dict[str, mpmath.mpf]:
    """Every checked quantity at φ = ``angle``: the scalars by name, ``R_1``, ``H_inverse[1][2]``…"""
    function, ref = reference(expression)
    values: dict[str, mpmath.mpf] = {}
    with mpmath.workdps(60):
        phi = +angle
        p = function.value(phi)
        slope = mpmath.diff(function.value, phi)
        nu, mu = 2 * mpmath.sin(phi / 2) / p, 1 / slope
        values.update(p=p, kappa=ref.kappa(), p_prime=slope, nu=nu, mu=mu, det_H=mu * nu**2,
                      epsilon=2 * mpmath.tan(phi / 2) / p)
        state = ref.state([0, 0, p])
        assert mpmath.almosteq(state.angle, phi, TOLERANCE), (state.angle, phi)
        for name in TENSORS.values():
            tensor = getattr(state, name)
            values[f"{name}_0"] = tensor[2, 2]
            values[f"{name}_1"] = tensor[1, 0] / p
            values[f"{name}_2"] = (tensor[2, 2] - tensor[0, 0]) / p**2
            for i, a in enumerate(BASIS):
                for j, b in enumerate(BASIS):
                    values[f"{name}[{i}][{j}]"] = tensor[a, b]
    return values


def matrix_cells(text: str) -> list[list[str]]:
    """The 3×3 cells of ``\\begin{bmatrix} … \\end{bmatrix}``."""
    match = re.fullmatch(r"\\begin\{bmatrix\}(.*)\\end\{bmatrix\}", text)
    assert match, text
    rows = [row.split("&") for row in match.group(1).split(r"\\[2ex]")]
    assert len(rows) == 3 and all(len(row) == 3 for row in rows), text
    return rows


def sheet_formulas(text: str) -> dict[str, str]:
    """The formulas of a sheet's generating function, scalar and tensor sections, keyed as in
    :func:`expected`; every line there must be one of them (or a tensor's defining sum)."""
    body = text.split(r"\subsection*{Derivatives")[0]
    formulas: dict[str, str] = {}

    def add(key: str, formula: str) -> None:
        assert key not in formulas, f"{key} printed twice"
        formulas[key] = formula.strip()

    for line in body.splitlines():
        if "&=" not in line:
            continue
        left, right = (part.strip() for part in line.split("&=", 1))
        right = END_TAG.sub("", right.removesuffix("\\\\").rstrip())
        coefficient = re.fullmatch(r"c_(\d)\^\{(.+)\}", left)
        matrix = re.fullmatch(r"\[(.+)\]", left)
        if left == "\\kappa":
            add("kappa", right.rsplit("=", 1)[1])
        elif left in SCALARS:
            add(SCALARS[left], right)
        elif left in TENSORS:
            terms = [rf"c_{k}^{{{left}}}" for k in range(3)]
            assert right == (rf"{terms[0]}\,\mathbf{{I}} + {terms[1]}\,(\mathbf{{p}}\times) + "
                             rf"{terms[2]}\,(\mathbf{{p}}\times)^2"), line
        elif coefficient and coefficient.group(2) in TENSORS:
            add(f"{TENSORS[coefficient.group(2)]}_{coefficient.group(1)}", right)
        elif matrix and matrix.group(1) in TENSORS:
            for i, row in enumerate(matrix_cells(right)):
                for j, cell in enumerate(row):
                    add(f"{TENSORS[matrix.group(1)]}[{i}][{j}]", cell)
        else:
            raise AssertionError(f"a line this test cannot place: {line}")
    assert set(formulas) == KEYS, sorted(KEYS ^ set(formulas))
    return formulas


def mismatches(formulas: dict[str, str], expression: str) -> list[str]:
    """Each formula that differs from the reference at one of the angles (all of them listed)."""
    function, _ = reference(expression)
    wrong = []
    for key, formula in formulas.items():
        value = read(formula)
        for angle in angles(function):
            want = expected(expression, angle)[key]
            with mpmath.workdps(DIGITS):
                got = value(+angle)
            if not mpmath.almosteq(got, want, TOLERANCE, mpmath.mpf("1e-25")):
                wrong.append(f"{key} = {formula} at φ = {mpmath.nstr(angle, 6)}: "
                             f"{mpmath.nstr(got, 15)}, expected {mpmath.nstr(want, 15)}")
    return wrong


def check_validity(text: str, function: GeneratingFunction) -> None:
    """``Valid for $|\\varphi| < φ_max$, where $\\|\\mathbf{p}\\| < p_max$`` against the reference."""
    match = re.search(r"Valid for \$\|\\varphi\| < (.+?)\$, where \$\\\|\\mathbf\{p\}\\\| < (.+?)\$",
                      text)
    assert match, "no validity range"
    with mpmath.workdps(DIGITS):
        assert mpmath.almosteq(read(match.group(1))(0), function.phi_max, TOLERANCE), match.group(0)
        p_max = function.p_max()
        if match.group(2) == r"\infty":
            assert p_max == mpmath.inf or p_max > 1e15, match.group(0)
        else:  # printed to 6 significant digits
            assert mpmath.almosteq(read(match.group(2))(0), p_max, mpmath.mpf("1e-5")), match.group(0)


def test_every_named_sheet_is_checked() -> None:
    assert set(FAMILIES) == set(NAMED)
    sheets = {path.stem for path in LATEX.glob("*.tex")} - {"table1"}
    assert {name for name in sheets if not name.endswith("_standalone")} == set(NAMED)


@pytest.mark.parametrize("name", sorted(FAMILIES))
def test_generated_sheet_values(name: str) -> None:
    text = (LATEX / f"{name}.tex").read_text()
    expression = FAMILIES[name].expression
    assert mismatches(sheet_formulas(text), expression) == []
    check_validity(text, reference(expression)[0])
    assert (LATEX / f"{name}_standalone.tex").read_text().count(text.strip()) == 1


@pytest.mark.parametrize("expression", CORPUS_SHEETS)
def test_fresh_sheet_values(expression: str) -> None:
    text = sheet(symrot.derive(expression))
    entry = by_expression(expression)
    assert mismatches(sheet_formulas(text), expression) == []
    function = reference(expression)[0]
    assert mpmath.almosteq(function.phi_max, entry.declared_phi_max(), TOLERANCE)
    check_validity(text, function)


def test_table_1_values() -> None:
    """Every cell of generated/latex/table1.tex: p and the scalar columns at the angles, the
    validity bound against the reference's own scan; the rows in the paper's order."""
    text = (LATEX / "table1.tex").read_text()
    body = text.split("\\midrule\n")[1].split("\\bottomrule")[0]
    header = text.split("\\toprule\n")[1].split("\\midrule")[0]
    columns = [cell.strip() for cell in header.strip().removesuffix("\\\\").split("&")]
    assert columns[0] == "Parameterization" and columns[-1] == r"\text{Validity}", columns
    keys = [SCALARS[c] for c in columns[1:-1]]
    assert keys[:4] == ["p", "p_prime", "nu", "epsilon"], keys
    rows = [line for line in body.splitlines() if line.strip()]
    assert len(rows) == len(TABLE_1)
    for name, row in zip(TABLE_1, rows, strict=True):
        cells = [cell.strip() for cell in row.strip().removesuffix("\\\\").split(" & ")]
        assert len(cells) == len(columns), row
        assert FAMILIES[name].label in cells[0], (name, cells[0])
        expression = FAMILIES[name].expression
        assert mismatches(dict(zip(keys, cells[1:-1], strict=True)), expression) == []
        bound = re.fullmatch(r"\|\\varphi\| < (.+)", cells[-1])
        assert bound, cells[-1]
        with mpmath.workdps(DIGITS):
            assert mpmath.almosteq(read(bound.group(1))(0), reference(expression)[0].phi_max,
                                   TOLERANCE), (name, cells[-1])


PRINTED = {
    "a rational term inside a fraction": "(phi + 1/2)/cos(phi)",
    "a negative rational term": "(phi - 3/4)/(1 + sin(phi/3))",
    "a slashed fraction and a rational": "(1/3 - sin(phi)/(2*phi + 1))/tan(phi/5)",
    "a negative slashed fraction first": "(-sin(phi/2)/(phi**2 + 1) + 2)/(3 + cos(phi))",
    "a negative product over a rational sum": "-cos(3*phi/4)/(phi**2 + 5/2)",
    "a sum over a product inside a fraction": "(2 + (phi + 1)/(2*cos(phi)))/(3 + phi)",
}
"""Forms of the printer's slashed inner fractions that the sheets above need not contain."""


@pytest.mark.parametrize("expression", PRINTED.values(), ids=list(PRINTED))
def test_printer_values(expression: str) -> None:
    """:func:`symrot.backends.latex.latex` of SymPy expressions, read back, at the angles."""
    from symrot.backends.latex import latex

    expr = parse(expression)
    text = latex(expr.subs(PHI, symrot.core.parsing.PHI))
    direct = mp_function(expr)
    for angle in ANGLES:
        with mpmath.workdps(DIGITS):
            got, want = read(text)(mpmath.mpf(angle)), direct(mpmath.mpf(angle))
        assert mpmath.almosteq(got, want, TOLERANCE), (text, angle, got, want)


ONE = mpmath.mpf(1)
READER_CASES = [
    (r"\frac{2 \sin(\varphi/2)}{\varphi}", lambda: 2 * mpmath.sin(ONE / 2)),
    (r"- \varphi \sin \varphi/\left(2 - 2 \cos \varphi\right) + 1",
     lambda: 1 - mpmath.sin(ONE) / (2 - 2 * mpmath.cos(ONE))),
    (r"\cos^{2}\frac{\varphi}{4} \cos\frac{\varphi}{2}",
     lambda: mpmath.cos(ONE / 4) ** 2 * mpmath.cos(ONE / 2)),
    (r"\left(\sqrt[3]{6 \left(\varphi - \sin \varphi\right)}\right)^{2}",
     lambda: mpmath.cbrt(6 * (1 - mpmath.sin(ONE))) ** 2),
    (r"- \sin\left(2 \varphi\right)/2 \,", lambda: -mpmath.sin(2 * ONE) / 2),
    (r"\operatorname{atan}^{2}{\left(\varphi \right)} \tanh{\left(\varphi/2 \right)}",
     lambda: mpmath.atan(ONE) ** 2 * mpmath.tanh(ONE / 2)),
    (r"\frac{\varphi^{3}}{6} + \sqrt{\varphi^{2} + 1} - 2 \pi",
     lambda: ONE / 6 + mpmath.sqrt(2) - 2 * mpmath.pi),
]


@pytest.mark.parametrize(("text", "value"), READER_CASES)
def test_reader(text: str, value: Callable[[], mpmath.mpf]) -> None:
    with mpmath.workdps(DIGITS):
        assert mpmath.almosteq(read(text)(ONE), value(), mpmath.mpf("1e-30"))


@pytest.mark.parametrize("text", [r"\sin \varphi^{2}", r"\varphi/2 \varphi",
                                  r"\foo{\varphi}", r"\left[\varphi\right]", r"2 \cdot \varphi",
                                  r"\frac{1}{2", r"\varphi &", r"\sin(\varphi)^{2}"])
def test_reader_refuses_what_it_cannot_read(text: str) -> None:
    with pytest.raises(LatexSyntaxError):
        read(text)
