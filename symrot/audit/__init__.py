"""Machine audit of the paper's numbered equations (issue 8).

Each :class:`~symrot.audit.checks.Check` states an equation as printed and proves or refutes it;
:func:`run_all` runs the registry :data:`CHECKS` and :mod:`symrot.audit.report` writes the errata.
"""

from .checks import CHECKS, Check, Outcome, run_all

__all__ = ["CHECKS", "Check", "Outcome", "run_all"]
