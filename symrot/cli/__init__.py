"""The ``symrot`` command line. Each subcommand is a small module with ``register(subparsers)``.

Any :class:`~symrot.core.errors.SymrotError` becomes one line on stderr and exit status 2; nothing
the user types produces a traceback. Every command runs under one time budget (``--timeout``,
default :data:`DEFAULT_TIMEOUT` s, at most :data:`MAX_TIMEOUT` s) that covers everything from
parsing to writing files; from
the real command line (``main()`` without arguments) it runs in a worker process that also has
an address-space limit (:mod:`symrot.cli.worker`). Exit status 70 is kept for genuine bugs;
SIGINT ends a command with 130 and SIGTERM with 143, in both cases after the temporary files are
removed and with every output file whole (:mod:`symrot.core.atomic`).
Conventions: ``symrot`` alone prints the help (exit 0, as ``--help``); misuse is exit 2;
``--version``; ``--quiet`` silences the progress that long steps draw on stderr (drawn only when
stderr is a terminal).
"""

from __future__ import annotations

import argparse
import math
import os
import sys
import warnings
from collections.abc import Sequence

from symrot.cli import audit, derive, latex_commands, plot, progress, solve, worker
from symrot.core import budget
from symrot.core.errors import SymrotError

COMMANDS = [derive, solve, latex_commands, plot, audit]
"""Subcommand modules, in the order ``symrot --help`` lists them."""

EXIT_USAGE = 2
EXIT_INTERNAL = 70
EXIT_INTERRUPTED = 130
"""Exit status after SIGINT (Ctrl-C), as a shell reports it: 128 + 2."""
EXIT_TERMINATED = worker.EXIT_TERMINATED
"""Exit status after SIGTERM: 128 + 15, once the files are whole and the scratch files removed."""
MAX_TIMEOUT = 1e6
"""The largest ``--timeout`` in seconds (about 11.6 days); past it, exit 2 before any work."""
DEFAULT_TIMEOUT = 60.0
"""Seconds per command unless the command sets its own ``default_timeout`` (audit)."""
INT_DIGITS = 20_000
"""Decimal digits an exact number may print with (Python's default stops at 4300). The parser
keeps numbers below 2**512, so series coefficients stay far below this, and printing is fast."""
WORKER_VARIABLE = "SYMROT_WORKER"
"""1 forces the worker process, 0 disables it (default: only for the real command line)."""


def _seconds(text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"invalid number of seconds: {text!r}") from None
    if not math.isfinite(value) or value < 0:
        raise argparse.ArgumentTypeError("seconds must be a finite number >= 0 (0: no budget)")
    if value > MAX_TIMEOUT:
        raise argparse.ArgumentTypeError(f"{text} seconds is more than the maximum of {MAX_TIMEOUT:g} s "
                                         "(0: no budget)")
    return value


def _timeout_option(parser: argparse.ArgumentParser, default: object) -> None:
    parser.add_argument(
        "--timeout", type=_seconds, default=default, metavar="SECONDS",
        help=f"time budget of the whole command, parse to written files (default "
        f"{DEFAULT_TIMEOUT:g} s, audit {audit.AUDIT_TIMEOUT:g} s; 0: none; at most "
        f"{MAX_TIMEOUT:g} s); on expiry: exit 2 naming the stage",
    )


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="symrot",
        description="Verified formulas and Taylor-safe code for vectorial parameterizations "
        "of rotation (Bauchau & Trainelli 2003).",
    )
    parser.add_argument("--version", action="version", version=f"%(prog)s {version()}")
    parser.add_argument("-q", "--quiet", action="store_true",
                        help="no progress on stderr (it is drawn only when stderr is a terminal)")
    _timeout_option(parser, None)
    subparsers = parser.add_subparsers(dest="command", metavar="COMMAND")
    for module in COMMANDS:
        module.register(subparsers)
    for subparser in subparsers.choices.values():
        # also accepted after the command; SUPPRESS keeps a global value from being reset
        _timeout_option(subparser, argparse.SUPPRESS)
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
        from symrot import __version__

        return __version__


def expressions_as_arguments(argv: Sequence[str], parser: argparse.ArgumentParser) -> list[str]:
    """Keep argparse from reading an expression such as ``-phi`` as an option.

    An argument that starts with ``-`` but is no option of any (sub)command gets a leading
    space; the parsers strip it. ``--`` ends the rewriting, as it ends option parsing.
    """
    options = _option_strings(parser)
    out: list[str] = []
    for index, arg in enumerate(argv):
        if arg == "--":
            return out + list(argv[index:])
        is_option = arg.split("=", 1)[0] in options or (
            arg.startswith("--") and any(o.startswith(arg.split("=", 1)[0]) for o in options))
        out.append(f" {arg}" if arg.startswith("-") and len(arg) > 1 and not is_option else arg)
    return out


def _option_strings(parser: argparse.ArgumentParser) -> set[str]:
    found: set[str] = set()
    for action in parser._actions:  # argparse offers no public walk over options
        found.update(action.option_strings)
        if isinstance(action, argparse._SubParsersAction):
            for subparser in action.choices.values():
                found |= _option_strings(subparser)
    return found


def _use_worker(argv: Sequence[str] | None) -> bool:
    setting = os.environ.get(WORKER_VARIABLE, "")
    if setting in ("0", "1"):
        return setting == "1" and worker.available()
    return argv is None and worker.available()


def main(argv: Sequence[str] | None = None) -> int:
    parser = build_parser()
    raw = sys.argv[1:] if argv is None else list(argv)
    args = parser.parse_args(expressions_as_arguments(raw, parser))
    if args.command is None:
        parser.print_help()
        return 0
    progress.set_quiet(args.quiet)
    seconds = args.timeout if args.timeout is not None else getattr(
        args, "default_timeout", DEFAULT_TIMEOUT)
    if _use_worker(argv):
        return worker.run(lambda: run(args, seconds), seconds)
    return run(args, seconds)


def run(args: argparse.Namespace, seconds: float | None) -> int:
    """Run the parsed command in this process under the time budget; the exit status."""
    budget.reset()
    try:
        with worker.terminate_raises(), budget.enforce(seconds), warnings.catch_warnings():
            # overflow in a numeric scan is handled where it happens; it is no message for users
            warnings.simplefilter("ignore", RuntimeWarning)
            sys.set_int_max_str_digits(max(sys.get_int_max_str_digits(), INT_DIGITS))
            return int(args.run(args) or 0)
    except budget.BudgetExceeded as exc:
        print(f"symrot: error: {exc} (--timeout changes it)", file=sys.stderr)
        return EXIT_USAGE
    except SymrotError as exc:
        print(f"symrot: error: {exc}", file=sys.stderr)
        return EXIT_USAGE
    except KeyboardInterrupt:
        print("symrot: interrupted", file=sys.stderr)
        return EXIT_INTERRUPTED
    except worker.Terminated:
        print("symrot: terminated", file=sys.stderr)
        return EXIT_TERMINATED
    except BrokenPipeError:
        return 0
    except RecursionError:
        print("symrot: error: expression is too deeply nested", file=sys.stderr)
        return EXIT_USAGE
    except MemoryError:
        print(f"symrot: error: out of memory during {budget.failed()}", file=sys.stderr)
        return EXIT_USAGE
    except Exception as exc:
        print(f"symrot: internal error ({type(exc).__name__}: {exc}); please report it",
              file=sys.stderr)
        return EXIT_INTERNAL
