"""LaTeX output compiles with a real TeX engine, without warnings, and shows derived values."""

from __future__ import annotations

import re
import shutil
import subprocess
from pathlib import Path

import pytest

import symrot
from symrot.backends.latex import cause_latex, latex, sheet, standalone, table
from symrot.backends.typeset import typeset
from symrot.cli import main
from symrot.core.registry import NAMED, PAPER_TABLE_1_VALIDITY, TABLE_1

pytestmark = pytest.mark.skipif(
    any(shutil.which(tool) is None for tool in ("pdflatex", "pdftotext", "pdftohtml", "pdftoppm")),
    reason="needs pdflatex and poppler-utils (make setup-system)")

BAD_LOG = re.compile(r"Overfull|Underfull|undefined|Undefined|! ")
ASCII_STAND_INS = re.compile(r"\boo\b|->|\^-1|\bmu\b|\bnu\b|_")
"""What the outputs used to show instead of math: oo, ->, ^-1, mu, nu, code identifiers."""
MIN_FONT_PT = 7


def font_sizes(pdf: Path) -> set[int]:
    """The font sizes (pt) poppler reports for the text of ``pdf`` (pdftohtml -xml fontspecs)."""
    xml = subprocess.run(["pdftohtml", "-xml", "-i", "-stdout", str(pdf)],
                         capture_output=True, text=True, check=True).stdout
    return {int(size) for size in re.findall(r'<fontspec[^>]* size="(-?\d+)"', xml)}


def assert_publishable(tex: Path, text: str) -> None:
    """No ASCII stand-in in the PDF's text; no glyph below 7 pt; page renders (pdftoppm)."""
    assert not ASCII_STAND_INS.search(text), ASCII_STAND_INS.findall(text)
    sizes = font_sizes(tex.with_suffix(".pdf"))
    assert sizes and min(sizes) >= MIN_FONT_PT, sorted(sizes)
    subprocess.run(["pdftoppm", "-r", "40", "-png", "-f", "1", "-l", "1",
                    str(tex.with_suffix(".pdf")), str(tex.with_suffix(""))], check=True)
    assert tex.parent.glob("*.png")


def compile_pdf(tex: Path) -> str:
    """pdflatex ``tex`` (reproducibly); fail on errors or box/reference warnings; the PDF's text."""
    result = typeset(tex)
    assert result.returncode == 0, result.log[-2000:]
    assert not BAD_LOG.search(result.log), BAD_LOG.findall(result.log)
    return subprocess.run(["pdftotext", "-layout", str(result.pdf), "-"],
                          capture_output=True, text=True, check=True).stdout


def test_generated_table_1_compiles_and_lists_every_row(tmp_path: Path) -> None:
    source = Path("generated/latex/table1_standalone.tex")
    target = tmp_path / source.name
    shutil.copy(source, target)
    text = compile_pdf(target)
    assert_publishable(target, text)
    for name in TABLE_1:
        title = symrot.lookup(name).title
        assert title.split()[0].split("-")[0] in text
    # Linear parameters: symrot's range pi/2 differs from the printed pi, with a table note.
    assert "Table 1 prints" in text and "Linear parameters" in text
    assert "Wiener\u2013" in text and "Cayley\u2013" in text and "m=4" in text.replace(" ", "")


@pytest.mark.parametrize("name", NAMED)
def test_generated_sheets_compile(name: str, tmp_path: Path) -> None:
    source = Path(f"generated/latex/{name}_standalone.tex")
    target = tmp_path / source.name
    shutil.copy(source, target)
    text = compile_pdf(target)
    assert_publishable(target, text)
    for label in ("(12)", "(15)", "(24)", "(26)", "cf. (83)", "Validity range"):
        assert label in text, label
    source_text = source.read_text()
    assert "\\begin{align}" in source_text and "adjustbox" not in source_text
    assert "\\texttt" not in source_text


def test_table_cells_come_from_the_derivation() -> None:
    results = [symrot.derive(name) for name in TABLE_1]
    body = table(results, ("mu", "det_H"), PAPER_TABLE_1_VALIDITY)
    for result in results:
        for key in ("p_prime", "nu", "epsilon", "mu", "det_H"):
            assert latex(result.derivation.scalars[key]) in body


@pytest.mark.parametrize("columns", ["", "mu", "mu,det_H", "causes", "mu,det_H,causes"])
def test_cli_table_any_columns_stays_at_body_size(columns: str, tmp_path: Path) -> None:
    items = ["wiener_milenkovic", "cbrt(6*(phi-sin(phi)))", "3*tan(phi/3)", "linear"]
    assert main(["table", *items, "--columns", columns, "--standalone", "--out", str(tmp_path)]) == 0
    source = (tmp_path / "table.tex").read_text()
    assert "resizebox" not in source and "adjustbox" not in source and "landscape" not in source
    text = compile_pdf(tmp_path / "table.tex")  # no Overfull box: it fits at body size
    assert_publishable(tmp_path / "table.tex", text)
    assert "Wiener\u2013" in text and "Constant" in text


def test_causes_are_those_derive_lists() -> None:
    from symrot.core.singularities import validity

    for item in ("3*tan(phi/3)", "linear", "det_h_one"):
        result = symrot.derive(item)
        body = table([result], ("causes",))
        listed = validity(result.derivation).listed()
        conditions = [cause_latex(s.quantity, s.limit) for s in listed]
        assert sum(body.count(f"${c}$") for c in set(conditions)) >= len(conditions)
        cell = body.split(r"\multicolumn{5}{>{\raggedright\arraybackslash}p{15cm}}{")[1]
        cell = cell.split("} \\\\")[0]
        assert cell.count(r"\to") + cell.count(r"\gtrless") == len(listed)


def test_row_uses_one_form_of_p() -> None:
    body = table([symrot.derive("cbrt(6*(phi-sin(phi)))")], ("mu", "det_H"))
    assert r"\sqrt[3]{6 \left(\varphi - \sin \varphi\right)}" in body
    assert r"6 \varphi - 6" not in body


def test_nested_fractions_are_slashed() -> None:
    text = latex(symrot.derive("wiener_milenkovic").derivation.scalars["epsilon"])
    assert text == r"\frac{\cos^{2}(\varphi/4)}{\cos(\varphi/2)}"
    assert text.count(r"\frac") == 1


@pytest.mark.parametrize("fit", ["resize", "landscape"])
def test_fit_options_are_explicit_and_compile(fit: str, tmp_path: Path) -> None:
    results = [symrot.derive("linear"), symrot.derive("det_h_one")]
    body = table(results, ("mu", "det_H", "causes"), fit=fit)
    assert (r"\resizebox" in body) == (fit == "resize")
    assert ("sidewaystable" in body) == (fit == "landscape")
    plain = table(results)
    assert r"\resizebox" not in plain and "sidewaystable" not in plain
    document = tmp_path / "table.tex"
    document.write_text(standalone(body))
    assert "Linear parameters" in compile_pdf(document)


def test_cli_sheet_fragment_inputs_into_a_document(tmp_path: Path) -> None:
    assert main(["sheet", "4*tan(phi/3)", "--name", "mine", "--out", str(tmp_path)]) == 0
    fragment = (tmp_path / "mine.tex").read_text()
    document = tmp_path / "doc.tex"
    document.write_text(standalone(r"\input{mine}"))
    text = compile_pdf(document)
    assert "Validity range" in text
    assert fragment == sheet(symrot.derive("4*tan(phi/3)"))


def test_cli_rejects_bad_columns(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    assert main(["table", "--columns", "bogus", "--out", str(tmp_path)]) == 2
    assert "unknown column" in capsys.readouterr().err
