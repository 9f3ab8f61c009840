"""LaTeX output compiles with a real TeX engine, without warnings, and shows derived values."""

from __future__ import annotations

import re
import shutil
import subprocess
from pathlib import Path

import pytest

import symrot
from symrot.backends.latex import latex, sheet, standalone, table
from symrot.cli import main
from symrot.registry import NAMED, PAPER_TABLE_1_VALIDITY, TABLE_1

pytestmark = pytest.mark.skipif(shutil.which("pdflatex") is None or shutil.which("pdftotext") is None,
                                reason="needs pdflatex and pdftotext (make setup-system)")

BAD_LOG = re.compile(r"Overfull|Underfull|undefined|Undefined|! ")


def compile_pdf(tex: Path) -> str:
    """pdflatex ``tex``; fail on errors or box/reference warnings; return the PDF's text."""
    result = subprocess.run(["pdflatex", "-interaction=nonstopmode", "-halt-on-error", tex.name],
                            cwd=tex.parent, capture_output=True, text=True, timeout=120, check=False)
    log = tex.with_suffix(".log").read_text(encoding="latin-1")
    assert result.returncode == 0, log[-2000:]
    assert not BAD_LOG.search(log), BAD_LOG.findall(log)
    text = subprocess.run(["pdftotext", "-layout", str(tex.with_suffix(".pdf")), "-"],
                          capture_output=True, text=True, check=True).stdout
    return text


def test_generated_table_1_compiles_and_lists_every_row(tmp_path: Path) -> None:
    source = Path("generated/latex/table1_standalone.tex")
    target = tmp_path / source.name
    shutil.copy(source, target)
    text = compile_pdf(target)
    for name in TABLE_1:
        title = symrot.lookup(name).title
        assert title.split()[0] in text
    # Linear parameters: symrot's range pi/2 differs from the printed pi, with a footnote.
    assert "Table 1 prints" in text and "Linear parameters" in text


@pytest.mark.parametrize("name", NAMED)
def test_generated_sheets_compile(name: str, tmp_path: Path) -> None:
    source = Path(f"generated/latex/{name}_standalone.tex")
    target = tmp_path / source.name
    shutil.copy(source, target)
    text = compile_pdf(target)
    for label in ("(eq. 12)", "(eq. 15)", "(eq. 24)", "(eq. 26)", "(eq. 83)", "Validity range"):
        assert label in text, label


def test_table_cells_come_from_the_derivation() -> None:
    results = [symrot.derive(name) for name in TABLE_1]
    body = table(results, ("mu", "det_H"), PAPER_TABLE_1_VALIDITY)
    for result in results:
        for key in ("p_prime", "nu", "epsilon", "mu", "det_H"):
            assert latex(result.derivation.scalars[key]) in body


def test_cli_table_with_user_expression_and_extra_columns(tmp_path: Path) -> None:
    assert main(["table", "wiener_milenkovic", "cbrt(6*(phi-sin(phi)))", "3*tan(phi/3)",
                 "--columns", "mu,det_H,causes", "--standalone", "--out", str(tmp_path)]) == 0
    text = compile_pdf(tmp_path / "table.tex")
    assert "Wiener-Milenkovic" in text and "Constant det H" in text


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
