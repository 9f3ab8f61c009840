"""Entry point of the commands: one hash seed for every run, so that equal input gives equal files.

SymPy's simplification, factorization and polynomial algorithms iterate over sets of expressions,
and their forms (the sign arrangement of a sum, which common factor is pulled out) follow that
order. It depends on two per-process random values: Python's string hashes (``PYTHONHASHSEED``)
and the base number of SymPy's ``Dummy`` symbols. The plan measures the candidate forms' rounding,
and equally accurate forms are ranked by their order, so ``symrot derive 'sinh(phi)' --emit
numpy`` wrote four different (equally accurate) modules in 16 runs. :mod:`symrot.core.parsing` fixes
the Dummy base when symrot is imported; the commands (``symrot``, ``python -m symrot``,
``python -m symrot.generate``) re-execute themselves once with ``PYTHONHASHSEED=0`` before SymPy
is imported. A program that calls the Python API gets the same forms when it is started with
``PYTHONHASHSEED=0`` (docs/architecture.md).
"""

from __future__ import annotations

import os
import sys

SEED = "0"


def run_with_fixed_hash_seed(module: str) -> None:
    """Return if this process runs with ``PYTHONHASHSEED=SEED``; otherwise replace it by
    ``python -m module`` with the same arguments and that seed (never returns then)."""
    if os.environ.get("PYTHONHASHSEED") == SEED or not sys.executable:
        return
    environment = dict(os.environ, PYTHONHASHSEED=SEED)
    sys.stdout.flush()
    sys.stderr.flush()
    os.execve(sys.executable, [sys.executable, "-m", module, *sys.argv[1:]], environment)


def command() -> int:
    """The ``symrot`` command (console script and ``python -m symrot``)."""
    run_with_fixed_hash_seed("symrot")
    from symrot.cli import main

    return main()
