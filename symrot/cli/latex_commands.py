"""``symrot table`` and ``symrot sheet``: LaTeX for papers (Table 1, derivation sheets)."""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import Any

from symrot.api import derive
from symrot.backends.latex import FITS, sheet, standalone, table
from symrot.cli.output import write_file
from symrot.core.budget import stage
from symrot.core.errors import SymrotError
from symrot.core.registry import PAPER_TABLE_1_VALIDITY, TABLE_1

EXTRA_COLUMNS = ("mu", "det_H", "causes")


def register(subparsers: Any) -> None:
    table_parser = subparsers.add_parser(
        "table", help="write table.tex: the paper's Table 1, derived (booktabs)",
        description="Write Table 1 of the paper (name, p, p', nu, epsilon, validity) for the "
        "six rows of the paper, or for the given names/expressions, as table.tex. The table keeps "
        "the body font size; --fit resize or landscape are explicit choices for wide tables.",
    )
    table_parser.add_argument("items", nargs="*", metavar="NAME_OR_EXPR",
                              help="registry names or expressions (default: the paper's six rows)")
    table_parser.add_argument("--columns", default="", metavar="LIST",
                              help="extra columns, comma separated: mu, det_H, causes")
    table_parser.add_argument("--fit", choices=FITS, default="none",
                              help="none: natural width at body size (default); resize: scale to "
                              "the line width; landscape: a sidewaystable")
    _common(table_parser)
    table_parser.set_defaults(run=run_table)

    sheet_parser = subparsers.add_parser(
        "sheet", help="write NAME.tex: a derivation sheet for one parameterization",
        description="Write a derivation sheet (every formula, labelled with the paper's equation).",
    )
    sheet_parser.add_argument("expression", help="p(phi) or a registry identifier")
    sheet_parser.add_argument("--name", help="output file stem (default: registry name or 'sheet')")
    _common(sheet_parser)
    sheet_parser.set_defaults(run=run_sheet)


def _common(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--out", type=Path, default=Path("."), help="output directory")
    parser.add_argument("--standalone", action="store_true",
                        help="a complete document instead of a fragment to \\input")


def run_table(args: argparse.Namespace) -> int:
    columns = tuple(c.strip() for c in args.columns.split(",") if c.strip())
    unknown = [c for c in columns if c not in EXTRA_COLUMNS]
    if unknown:
        raise SymrotError(f"unknown column(s) {', '.join(unknown)} (allowed: {', '.join(EXTRA_COLUMNS)})")
    results = [derive(item) for item in (args.items or TABLE_1)]
    with stage("printing"):
        body = table(results, columns, PAPER_TABLE_1_VALIDITY, fit=args.fit)
    write_file(args.out, "table.tex", standalone(body) if args.standalone else body)
    return 0


def run_sheet(args: argparse.Namespace) -> int:
    result = derive(args.expression)
    stem = args.name or (result.entry.identifier if result.entry else "sheet")
    if not stem.replace("_", "").isalnum():
        raise SymrotError("--name must contain only letters, digits and underscores")
    with stage("printing"):
        body = sheet(result)
    write_file(args.out, f"{stem}.tex", standalone(body) if args.standalone else body)
    return 0
