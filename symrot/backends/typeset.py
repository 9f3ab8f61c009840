"""Typeset the LaTeX outputs with pdflatex and render their pages with poppler's pdftoppm.

Used by ``make generate`` (PNG renderings of Table 1 and the derivation sheets, so a reader sees
them without a TeX installation) and by the tests. Reproducible: the standalone documents set
``\\pdfinfoomitdate`` and an empty ``\\pdftrailerid``, and pdflatex runs with
``SOURCE_DATE_EPOCH=0`` and ``FORCE_SOURCE_DATE=1``, so the PDF carries no date or random ID and
pdftoppm (which writes no time chunk) gives the same PNG bytes on every run.
"""

from __future__ import annotations

import os
import shutil
import subprocess
import tempfile
from dataclasses import dataclass
from pathlib import Path

from symrot.core.errors import SymrotError

TOOLS = ("pdflatex", "pdftoppm")
TIMEOUT = 120


@dataclass(frozen=True)
class Typeset:
    pdf: Path
    log: str
    returncode: int


def missing_tools() -> list[str]:
    return [tool for tool in TOOLS if shutil.which(tool) is None]


def typeset(tex: Path) -> Typeset:
    """Run pdflatex once on ``tex`` (in its directory), reproducibly; the PDF and the log."""
    env = {**os.environ, "SOURCE_DATE_EPOCH": "0", "FORCE_SOURCE_DATE": "1"}
    result = subprocess.run(["pdflatex", "-interaction=nonstopmode", "-halt-on-error", tex.name],
                            cwd=tex.parent, capture_output=True, text=True, timeout=TIMEOUT,
                            check=False, env=env)
    log = tex.with_suffix(".log").read_text(encoding="latin-1")
    return Typeset(tex.with_suffix(".pdf"), log, result.returncode)


def page_pngs(source: str, dpi: int = 100) -> list[bytes]:
    """Every page of the standalone LaTeX ``source`` as PNG bytes at ``dpi``."""
    missing = missing_tools()
    if missing:
        raise SymrotError(f"rendering LaTeX needs {', '.join(missing)} (make setup-system)")
    with tempfile.TemporaryDirectory() as directory:
        tex = Path(directory) / "page.tex"
        tex.write_text(source, encoding="utf-8")
        result = typeset(tex)
        if result.returncode != 0:
            raise SymrotError(f"pdflatex failed:\n{result.log[-1500:]}")
        subprocess.run(["pdftoppm", "-r", str(dpi), "-png", str(result.pdf), str(tex.with_suffix(""))],
                       check=True, timeout=TIMEOUT, capture_output=True)
        pages = sorted(Path(directory).glob("page-*.png"), key=lambda p: int(p.stem.split("-")[-1]))
        return [page.read_bytes() for page in pages]
