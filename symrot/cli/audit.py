"""``symrot audit``: check every numbered equation of the paper by machine and write the errata."""

from __future__ import annotations

import argparse
import difflib
import sys
from pathlib import Path
from typing import Any

from symrot.cli import strict_json
from symrot.cli.output import write_file
from symrot.core.budget import stage

EXIT_CHECK_FAILED = 1
DEFAULT_ERRATA = "docs/errata.md"
AUDIT_TIMEOUT = 1800.0
"""The audit runs hundreds of bounded checks: its budget is larger than the other commands'."""


def register(subparsers: Any) -> None:
    parser = subparsers.add_parser(
        "audit",
        help="check the paper's equations (1)-(102) and Table 1 by machine; report errata",
        description="Prove or refute every numbered equation of Bauchau & Trainelli (2003), the formula "
        "statements of its text and every cell of Table 1 (symbolic under time limits, or at 50+ digits on "
        "random points and trajectories). Prints equation, status (holds / definition / erratum) and time. "
        "Exit status 0 when every check ran (errata are findings), 1 when a check could not run.",
    )
    parser.add_argument("--json", action="store_true", help="print one JSON list instead of the table")
    parser.add_argument("--write", metavar="PATH", help=f"write the errata markdown (e.g. {DEFAULT_ERRATA})")
    parser.add_argument(
        "--check",
        metavar="PATH",
        help="exit 1 with a diff if PATH differs from the errata markdown of this run",
    )
    parser.add_argument(
        "--only",
        metavar="KEYS",
        help="comma-separated equation keys to run (e.g. 14,22,45); no errata written",
    )
    parser.set_defaults(run=run, default_timeout=AUDIT_TIMEOUT)


def run(args: argparse.Namespace) -> int:
    from symrot.audit import all_checks, run_all
    from symrot.audit.report import REGENERATE, as_json, errata_markdown, table
    from symrot.cli.progress import each
    from symrot.core.errors import SymrotError

    only = {key.strip() for key in args.only.split(",")} if args.only else None
    selected = [c for c in all_checks() if only is None or c.equation in only]
    with stage("audit checks"):
        results = [result for check in each(selected, "symrot audit") for result in run_all([check])]
    if only is not None and not results:
        raise SymrotError(
            f"no check has the key(s) {args.only!r} (keys: 1-102, 'text after (N): ...', "
            "'Table 1 <row> <column>'; see symrot audit --json)"
        )
    print(strict_json.dumps(as_json(results), indent=2) if args.json else table(results))
    failed = any(r.outcome is None for r in results)
    if only is None:
        text = errata_markdown(results)
        if args.write:
            path = Path(args.write)
            write_file(path.parent, path.name, text, announce=False)
        if args.check:
            current = _read(Path(args.check))
            if current != text:
                sys.stdout.writelines(
                    difflib.unified_diff(
                        current.splitlines(keepends=True), text.splitlines(keepends=True), args.check, "audit"
                    )
                )
                print(f"{args.check} is stale: run `{REGENERATE}`", file=sys.stderr)
                return EXIT_CHECK_FAILED
    return EXIT_CHECK_FAILED if failed else 0


def _read(path: Path) -> str:
    """The text of ``path`` ('' when it does not exist); exit 2 with one line when unreadable."""
    from symrot.core.errors import SymrotError

    try:
        return path.read_text(encoding="utf-8") if path.exists() else ""
    except (OSError, UnicodeDecodeError) as exc:
        raise SymrotError(f"cannot read {path}: {getattr(exc, 'strerror', None) or exc}") from None
