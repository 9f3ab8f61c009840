"""``symrot audit``: check the paper's equations by machine and write the errata (issue 8)."""

from __future__ import annotations

import argparse
import json
from pathlib import Path
from typing import Any

EXIT_CHECK_FAILED = 1


def register(subparsers: Any) -> None:
    parser = subparsers.add_parser(
        "audit", help="check the paper's equations and Table 1 by machine; report errata",
        description="Run every audit check (symbolic or 50-digit numeric) and print equation, "
        "status (holds / definition / erratum) and time. Exit 1 if a check could not run.",
    )
    parser.add_argument("--json", action="store_true", help="print one JSON list")
    parser.add_argument("--write", metavar="PATH", help="write the errata markdown (docs/errata.md)")
    parser.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    from ..audit import run_all
    from ..audit.report import as_json, errata_markdown, table

    results = run_all()
    if args.json:
        print(json.dumps(as_json(results), indent=2))
    else:
        print(table(results))
    if args.write:
        Path(args.write).write_text(errata_markdown(results), encoding="utf-8")
    return EXIT_CHECK_FAILED if any(r.outcome is None for r in results) else 0
