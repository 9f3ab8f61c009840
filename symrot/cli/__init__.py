"""The ``symrot`` command line. Each subcommand is a small module with ``register(subparsers)``.

Any :class:`~symrot.errors.SymrotError` becomes one line on stderr and exit status 2; nothing
the user types produces a traceback. Conventions: ``symrot`` alone prints the help (exit 0, as
``--help``); misuse is exit 2; ``--version``; ``--quiet`` silences the progress that long steps
draw on stderr (drawn only when stderr is a terminal).
"""

from __future__ import annotations

import argparse
import sys
from collections.abc import Sequence

from ..errors import SymrotError
from . import audit, derive, latex_commands, plot, progress, solve

COMMANDS = [derive, solve, latex_commands, plot, audit]
"""Subcommand modules, in the order ``symrot --help`` lists them."""

EXIT_USAGE = 2
EXIT_INTERNAL = 70


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="symrot",
        description="Verified formulas and Taylor-safe code for vectorial parameterizations "
        "of rotation (Bauchau & Trainelli 2003).",
    )
    parser.add_argument("--version", action="version", version=f"%(prog)s {version()}")
    parser.add_argument("-q", "--quiet", action="store_true",
                        help="no progress on stderr (it is drawn only when stderr is a terminal)")
    subparsers = parser.add_subparsers(dest="command", metavar="COMMAND")
    for module in COMMANDS:
        module.register(subparsers)
    for subparser in subparsers.choices.values():
        # also accepted after the subcommand; SUPPRESS keeps a global --quiet from being reset
        subparser.add_argument("-q", "--quiet", action="store_true", default=argparse.SUPPRESS,
                               help="no progress on stderr")
    return parser


def version() -> str:
    """The installed distribution's version (the source tree's when not installed)."""
    from importlib.metadata import PackageNotFoundError
    from importlib.metadata import version as distribution_version

    try:
        return distribution_version("symrot")
    except PackageNotFoundError:
        from .. import __version__

        return __version__


def main(argv: Sequence[str] | None = None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    if args.command is None:
        parser.print_help()
        return 0
    progress.set_quiet(args.quiet)
    try:
        return int(args.run(args) or 0)
    except SymrotError as exc:
        print(f"symrot: error: {exc}", file=sys.stderr)
        return EXIT_USAGE
    except KeyboardInterrupt:
        print("symrot: interrupted", file=sys.stderr)
        return 130
    except BrokenPipeError:
        return 0
    except RecursionError:
        print("symrot: error: expression is too deeply nested", file=sys.stderr)
        return EXIT_USAGE
    except Exception as exc:
        print(f"symrot: internal error ({type(exc).__name__}: {exc}); please report it",
              file=sys.stderr)
        return EXIT_INTERNAL
