"""The check record, the registry and the runner."""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass

HOLDS = "holds"
DEFINITION = "definition"
ERRATUM = "erratum"


@dataclass(frozen=True)
class Outcome:
    status: str
    evidence: str
    corrected: str = ""


@dataclass(frozen=True)
class Check:
    equation: str
    printed: str
    kind: str
    verify: Callable[[], Outcome]


@dataclass(frozen=True)
class Result:
    check: Check
    outcome: Outcome | None
    seconds: float
    error: str = ""


def _registry() -> list[Check]:
    from . import appendix, composition, definitions, rescaling, section2, section31, table1

    return [*section2.CHECKS[:2], *composition.CHECKS[:2], *section2.CHECKS[2:], *definitions.CHECKS,
            *section31.CHECKS, *rescaling.CHECKS,
            *composition.CHECKS[2:], *table1.CHECKS, *appendix.CHECKS]


CHECKS: list[Check] = _registry()


def run_all(checks: list[Check] | None = None) -> list[Result]:
    """Run every check; a check that raises is recorded with its error (it "could not run")."""
    results = []
    for check in checks if checks is not None else CHECKS:
        start = time.perf_counter()
        try:
            outcome: Outcome | None = check.verify()
            error = ""
        except Exception as exc:  # a check that cannot run is reported, not fatal
            outcome, error = None, f"{type(exc).__name__}: {exc}"
        results.append(Result(check, outcome, time.perf_counter() - start, error))
    return results
