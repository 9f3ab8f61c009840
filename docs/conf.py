"""Sphinx configuration of symrot's documentation site (``make docs``)."""

from __future__ import annotations

import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

import symrot  # noqa: E402  (imported from this tree, whatever is installed)

project = "symrot"
author = "The symrot developers"
copyright = "2026, The symrot developers"
release = version = symrot.__version__

extensions = [
    "myst_parser",
    "sphinx.ext.autodoc",
    "sphinx.ext.napoleon",
    "sphinx.ext.doctest",
]

source_suffix = {".rst": "restructuredtext", ".md": "markdown"}
root_doc = "index"
# docs/paper/ is the paper's text for the audit (tests/test_audit.py), not a page of the site.
exclude_patterns = ["_build", "paper", "Thumbs.db", ".DS_Store"]

myst_heading_anchors = 3
# The measurement reports are written by bench/*.py; some step from a title straight to a level-3
# heading, which is not worth a warning.
suppress_warnings = ["myst.header"]

autodoc_member_order = "bysource"
autodoc_typehints = "description"
autodoc_default_options = {"members": True, "undoc-members": False}

# The guide's examples write no plan cache into the home directory.
doctest_global_setup = """
import os
os.environ["SYMROT_NO_CACHE"] = "1"
"""

html_theme = "alabaster"
html_title = f"symrot {release}"


def _list_mutations(app: object, docname: str, source: list[str]) -> None:
    """docs/mutations.md exists once `make mutations` has run: list it with the reports then (a
    toctree entry for a missing page, or a page in no toctree, is a warning)."""
    if docname == "index" and (Path(__file__).parent / "mutations.md").exists():
        source[0] = source[0].replace("*_time\n", "*_time\nmutations\n")


def setup(app: object) -> None:
    app.connect("source-read", _list_mutations)  # type: ignore[attr-defined]
