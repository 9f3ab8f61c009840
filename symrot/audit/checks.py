"""The registry of every check of the audit, in the paper's order, and the runner.

The records (:class:`Check`, :class:`Outcome`, :class:`Result` and the statuses) live in
:mod:`symrot.audit.records` and are re-exported here.
"""

from __future__ import annotations

import time

from symrot.audit.records import (
    DEFINITION,
    ERRATUM,
    HOLDS,
    NOT_RUN,
    AuditInconsistency,
    Check,
    Outcome,
    Result,
)


def _registry() -> list[Check]:
    from symrot.audit import (
        appendix_a,
        appendix_a_rates,
        appendix_b,
        appendix_c,
        appendix_d,
        rescaling,
        section2,
        section31,
        section31_tangent,
        section32,
        table1,
    )

    return [
        *section2.CHECKS,
        *section31.CHECKS,
        *section31_tangent.CHECKS,
        *section32.CHECKS,
        *table1.CHECKS,
        *rescaling.CHECKS,
        *appendix_a.CHECKS,
        *appendix_a_rates.CHECKS,
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


__all__ = ["DEFINITION", "ERRATUM", "HOLDS", "NOT_RUN", "AuditInconsistency", "Check", "Outcome", "Result",
           "all_checks", "run_all"]
