"""The check record, the registry of every check, and the runner.

A :class:`Check` names an equation of Bauchau & Trainelli (2003) (``"14"``), a statement of the
running text (``"text after (32): c"``) or a cell of Table 1, quotes it as printed (the LaTeX of
our copy of the paper, verbatim) and proves or refutes it. Its ``verify`` returns an
:class:`Outcome`: ``holds``, ``definition`` (with the reason) or ``erratum`` (with the corrected
statement, itself proved, and the evidence). A check that cannot conclude raises; the runner
records it as "could not run" and the command exits non-zero.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass

HOLDS = "holds"
DEFINITION = "definition"
ERRATUM = "erratum"
NOT_RUN = "could not run"


class AuditInconsistency(ArithmeticError):
    """Two independent derivations disagree (e.g. the core and a 50-digit trajectory)."""


@dataclass(frozen=True)
class Outcome:
    status: str
    evidence: str
    corrected: str = ""


@dataclass(frozen=True)
class Check:
    equation: str
    """Key: the equation number, ``text after (N): topic`` or ``Table 1 <row> <column>``."""
    printed: str
    """The statement as printed in our copy of the paper (its LaTeX, verbatim where possible)."""
    kind: str
    """How it is settled: symbolic, numeric (50 digits), trajectory, definition."""
    verify: Callable[[], Outcome]


@dataclass(frozen=True)
class Result:
    check: Check
    outcome: Outcome | None
    seconds: float
    error: str = ""

    @property
    def status(self) -> str:
        return self.outcome.status if self.outcome else NOT_RUN


def _registry() -> list[Check]:
    from . import (
        appendix_a,
        appendix_b,
        appendix_c,
        appendix_d,
        rescaling,
        section2,
        section31,
        section32,
        table1,
    )

    return [
        *section2.CHECKS,
        *section31.CHECKS,
        *section32.CHECKS,
        *table1.CHECKS,
        *rescaling.CHECKS,
        *appendix_a.CHECKS,
        *appendix_b.CHECKS,
        *appendix_c.CHECKS,
        *appendix_d.CHECKS,
    ]


def all_checks() -> list[Check]:
    """Every check, in the paper's order (Table 1 after Section 3.3, where it is introduced)."""
    return _registry()


def run_all(checks: list[Check] | None = None, only: set[str] | None = None) -> list[Result]:
    """Run the checks (all, or those whose key is in ``only``); errors are recorded, not raised."""
    results = []
    for check in checks if checks is not None else all_checks():
        if only is not None and check.equation not in only:
            continue
        start = time.perf_counter()
        try:
            outcome: Outcome | None = check.verify()
            error = ""
        except Exception as exc:  # a check that cannot run is reported, not fatal
            outcome, error = None, f"{type(exc).__name__}: {exc}"
        results.append(Result(check, outcome, time.perf_counter() - start, error))
    return results
