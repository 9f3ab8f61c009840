"""The check record, its outcome and result: what every audit section builds and the runner reports.

A :class:`Check` names an equation of Bauchau & Trainelli (2003) (``"14"``), a statement of the
running text (``"text after (32): c"``) or a cell of Table 1, quotes it as printed (the LaTeX of
our copy of the paper, verbatim) and proves or refutes it. Its ``verify`` returns an
:class:`Outcome`: ``holds``, ``definition`` (with the reason) or ``erratum`` (with the corrected
statement, itself proved, and the evidence). A check that cannot conclude raises; the runner
(:mod:`symrot.audit.checks`) records it as "could not run" and the command exits non-zero.

This module sits below the sections and the registry of :mod:`symrot.audit.checks`, so that the
sections import it and the registry imports the sections without a circle.
"""

from __future__ import annotations

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


def definition(reason: str) -> Outcome:
    """The outcome of a statement that defines a symbol (nothing to prove; ``reason`` says where
    the definition is used)."""
    return Outcome(DEFINITION, reason)
