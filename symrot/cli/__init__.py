"""The ``symrot`` command line. Each subcommand is a small module with ``register(subparsers)``.

Any :class:`~symrot.errors.SymrotError` becomes one line on stderr and exit status 2; nothing
the user types produces a traceback.
"""

from __future__ import annotations

import argparse
import sys
from collections.abc import Sequence

from ..errors import SymrotError
from . import audit, derive, latex_commands, plot, solve

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
    subparsers = parser.add_subparsers(dest="command", metavar="COMMAND", required=True)
    for module in COMMANDS:
        module.register(subparsers)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
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
