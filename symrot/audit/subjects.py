"""The generating functions that "any p" checks run over.

The six rows of Table 1, eq (35) (det H = 1) and the sine and tangent families m = 1..6 (36),
without repetitions (sine m = 1, 2, 4 and tangent m = 2, 4 are Table-1 rows): 14 functions.
Each gets numeric p, p′ and a sampling bound: 0.9 × the first angle in (0, π] where p leaves
its regular range (p ≤ 0, p′ ≤ 0 or p infinite), so samples avoid every singularity.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache

import mpmath
import sympy as sp

from symrot.audit.numeric import Scalar, mp_function, precision
from symrot.core.parsing import PHI
from symrot.core.registry import TABLE_1, family_member, lookup

FAMILY_ORDERS = range(1, 7)
SCAN_POINTS = 400


@dataclass(frozen=True)
class Subject:
    name: str
    expression: sp.Expr
    p: Scalar
    dp: Scalar
    bound: float
    """Samples take 0.05 ≤ |φ| ≤ bound."""

    def scalars(self, phi: mpmath.mpf) -> dict[str, mpmath.mpf]:
        """p, p′, ν (15), ε (16), μ (21) at φ."""
        p, dp = self.p(phi), self.dp(phi)
        return {
            "p": p,
            "dp": dp,
            "nu": 2 * mpmath.sin(phi / 2) / p,
            "eps": 2 * mpmath.tan(phi / 2) / p,
            "mu": 1 / dp,
        }


def _sampling_bound(p: Scalar, dp: Scalar) -> float:
    with mpmath.workdps(15):
        previous = 0.0
        for k in range(1, SCAN_POINTS + 1):
            phi = float(mpmath.pi) * k / SCAN_POINTS
            try:
                value, slope = p(mpmath.mpf(phi)), dp(mpmath.mpf(phi))
            except (ValueError, ZeroDivisionError):
                break
            if (
                not (mpmath.isfinite(value) and mpmath.isfinite(slope))
                or value <= 0
                or slope <= 0
                or abs(value) > 1e6
                or isinstance(value, mpmath.mpc)
            ):
                break
            previous = phi
    return 0.9 * previous


def subject(name: str, expression: sp.Expr) -> Subject:
    p, dp = mp_function(expression), mp_function(sp.diff(expression, PHI))
    return Subject(name, expression, p, dp, _sampling_bound(p, dp))


@lru_cache(maxsize=1)
def subjects() -> tuple[Subject, ...]:
    """Table 1, eq (35), sine and tangent m = 1..6, each expression once (paper's order)."""
    entries = [lookup(identifier) for identifier in (*TABLE_1, "det_h_one")]
    entries += [family_member(family, m) for family in ("sine", "tangent") for m in FAMILY_ORDERS]
    seen: list[sp.Expr] = []
    out = []
    with precision():
        for entry in entries:
            if any(entry.expression == other for other in seen):
                continue
            seen.append(entry.expression)
            out.append(subject(entry.identifier, entry.expression))
    return tuple(out)


def scope() -> str:
    return f"{len(subjects())} generating functions"


def names() -> str:
    """The generating functions, listed once in the report header."""
    return ", ".join(f"{s.name} (p = {s.expression})" for s in subjects())
