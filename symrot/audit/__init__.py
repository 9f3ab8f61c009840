"""Machine audit of every numbered equation of Bauchau & Trainelli (2003) and of Table 1 (issue 8).

Each :class:`~symrot.audit.records.Check` quotes a statement as printed and proves or refutes it,
symbolically under a time limit or at 50 digits on random points and trajectories;
:func:`run_all` runs them and :mod:`symrot.audit.report` renders the table and ``docs/errata.md``.
"""

from symrot.audit.checks import Check, Outcome, Result, all_checks, run_all

__all__ = ["Check", "Outcome", "Result", "all_checks", "run_all"]
