"""``symrot plot``: the paper's Figures 1–4 (PDF and PNG), optionally with user curves."""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import Any

from symrot.api import resolve
from symrot.backends.figures import DEFAULT_STYLE, FIGURES, STYLES, render
from symrot.cli.output import output_directory, write_file
from symrot.cli.progress import each
from symrot.core.budget import stage
from symrot.core.errors import SymrotError
from symrot.core.validation import validate


def register(subparsers: Any) -> None:
    parser = subparsers.add_parser(
        "plot", help="write Figures 1-4 of the paper (p, nu, p', det H for the families)",
        description="Reproduce Figures 1-4: p(phi) for the sine and tangent families m = 1..5 "
        "(Figs 1-2) and nu, p', det H versus phi (Figs 3-4), as PDF (TrueType fonts) and 300 dpi "
        "PNG, without titles (captions belong to the document).",
    )
    parser.add_argument("--figure", type=int, action="append", choices=sorted(FIGURES),
                        help="figure number (repeatable; default: all four)")
    parser.add_argument("--add", action="append", default=[], metavar="EXPR",
                        help="an extra generating function drawn on every figure (repeatable)")
    parser.add_argument("--format", default="pdf,png", help="comma separated: pdf, png")
    parser.add_argument("--style", choices=sorted(STYLES), default=DEFAULT_STYLE,
                        help="journal width: one-column (3.5 in) or two-column (7 in)")
    parser.add_argument("--out", type=Path, default=Path("."), help="output directory")
    parser.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    formats = [f.strip() for f in args.format.split(",") if f.strip()]
    if not formats or any(f not in ("pdf", "png") for f in formats):
        raise SymrotError("--format takes pdf, png or pdf,png")
    extra = []
    for text in args.add:
        expression = resolve(text)[0]
        with stage("validation"):
            extra.append(validate(expression).expression)
    output_directory(args.out)
    jobs = [(number, fmt) for number in args.figure or sorted(FIGURES) for fmt in formats]
    for number, fmt in each(jobs, "symrot plot"):
        with stage("printing"):
            image = render(number, fmt, tuple(extra), args.style)
        write_file(args.out, f"figure{number}.{fmt}", image)
    return 0
