"""Section 3.1–3.2 definitions (11)–(13) and the κ citation of Section 3.2.

Definitions are marked as such; each still confirms its consequence on the generating functions
the paper names: the Table-1 rows, det H = 1 (eq 35) and the sine/tangent families up to m = 6.
"""

from __future__ import annotations

import sympy as sp

from ..parsing import PHI
from ..registry import TABLE_1, family_member, lookup
from ..validation import validate
from .checks import DEFINITION, ERRATUM, Check, Outcome

FAMILY_ORDERS = range(1, 7)


def unit_normalized_functions() -> list[tuple[str, sp.Expr]]:
    """Table 1, det_h_one (eq 35) and sine/tangent family members m = 1..6."""
    entries = [lookup(identifier) for identifier in (*TABLE_1, "det_h_one")]
    entries += [family_member(family, m) for family in ("sine", "tangent") for m in FAMILY_ORDERS]
    return [(entry.identifier, entry.expression) for entry in entries]


def _eq11() -> Outcome:
    return Outcome(DEFINITION, "defines the parameter vector p = p(phi) u (used by every later check "
                   "through symrot.core.tensor_definitions)")


def _eq12() -> Outcome:
    return Outcome(DEFINITION, "defines kappa = lim p/phi; symrot.validation computes it from the exact "
                   "Taylor series")


def _eq13() -> Outcome:
    functions = unit_normalized_functions()
    failures = [name for name, expr in functions if validate(expr).kappa != 1]
    if failures:
        raise ArithmeticError(f"kappa != 1 for {failures}")
    return Outcome(DEFINITION, f"unit normalization kappa = 1; confirmed for all {len(functions)} "
                   "functions (Table 1, eq 35, sine/tangent m = 1..6)")


def _kappa_citation() -> Outcome:
    kappa = validate(sp.sin(PHI / 2)).kappa
    if kappa != sp.Rational(1, 2):
        raise ArithmeticError(f"kappa of sin(phi/2) is {kappa}")
    return Outcome(ERRATUM, "kappa of sin(phi/2) from eq (12) is 1/2 as stated, but eq (32) is "
                   "p = 2 sin(phi/2), not the definition of the normalization factor",
                   "'... the normalization factor, equation (12), is kappa = 1/2'")


CHECKS = [
    Check("11", "p = p(phi) u", "definition", _eq11),
    Check("12", "lim_{phi->0} p(phi)/phi = kappa", "definition", _eq12),
    Check("13", "lim_{phi->0} p(phi) = phi", "definition", _eq13),
    Check("text after (32)", "the normalization factor, equation (32), is kappa = 1/2", "citation",
          _kappa_citation),
]
