"""Settle an identity ``lhs = rhs`` both ways: symbolically and at 50 digits on random points.

Expressions are written in φ (``PHI``), the generic ``p``, ``dp`` (= p′) of
:mod:`symrot.audit.proof` and a symbolic unit axis u (``U_VECTOR``). The symbolic proof sets
u = e₁ (single-axis identities, see :mod:`symrot.audit.proof`); the numeric sweep evaluates both
sides at random angles and axes, with p, p′ of each generating function of
:mod:`symrot.audit.subjects` (or of one given p). The two verdicts must agree, otherwise the
check raises :class:`AuditInconsistency` ("could not run"); an undecided symbolic step leaves the
numeric verdict alone.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

import mpmath
import sympy as sp

from symrot.audit.numeric import (
    REFUTED,
    TOLERANCE,
    Vector,
    fmt,
    fmt_vector,
    precision,
    random_angle,
    random_axis,
    relative,
    rng,
)
from symrot.audit.proof import DP, U1, U2, U3, P, Verdict, at_e1, identity
from symrot.audit.records import ERRATUM, HOLDS, AuditInconsistency, Outcome
from symrot.audit.subjects import Subject, subject, subjects
from symrot.core.parsing import PHI

ARGUMENTS = (PHI, P, DP, U1, U2, U3)
POINTS = 3
"""Random points per generating function (or per check when no p is involved)."""


@dataclass(frozen=True)
class Sweep:
    worst: mpmath.mpf
    where: str
    points: int

    @property
    def holds(self) -> bool | None:
        if self.worst < TOLERANCE:
            return True
        if self.worst > REFUTED:
            return False
        return None

    def describe(self) -> str:
        if self.holds:
            return f"numeric: relative residual < 1e-45 at {self.points} random points (60 digits)"
        return f"numeric counterexample: {self.where}: relative residual {fmt(self.worst)}"


def compile_numeric(expr: sp.Expr | sp.Matrix) -> Callable[..., Any]:
    """``expr`` as an mpmath function of ``ARGUMENTS``."""
    return sp.lambdify(ARGUMENTS, expr, modules="mpmath")


Evaluator = Callable[[Subject | None, mpmath.mpf, Vector], tuple[Any, Any]]
"""(generating function or None, φ, u) → (residual, reference) at working precision."""


def sweep_function(
    label: str,
    evaluate: Evaluator,
    functions: Sequence[Subject] | None = None,
    bound: float = 3.0,
    points: int = POINTS,
) -> Sweep:
    """Worst relative residual of ``evaluate`` over random φ, u (and each generating function)."""
    worst, where, count = mpmath.mpf(-1), "", 0
    with precision():
        for fn in functions if functions is not None else [None]:
            r = rng(f"{label}:{fn.name if fn else '-'}")
            for _ in range(points):
                phi = random_angle(r, fn.bound if fn else bound)
                u = random_axis(r)
                residual, reference = evaluate(fn, phi, u)
                value = relative(residual, reference)
                count += 1
                if value > worst:
                    worst = value
                    place = f"{fn.name}, " if fn else ""
                    where = f"{place}phi = {fmt(phi, 15)}, u = {fmt_vector(u)}"
    return Sweep(worst, where, count)


def numeric_arguments(fn: Subject | None, phi: mpmath.mpf, u: Vector) -> tuple[mpmath.mpf, ...]:
    """Values of ``ARGUMENTS``: (φ, p, p′, u₁, u₂, u₃); without a generating function p = φ."""
    p, dp = (fn.p(phi), fn.dp(phi)) if fn else (phi, mpmath.mpf(1))
    return (phi, p, dp, u[0], u[1], u[2])


def sweep(
    lhs: sp.Expr | sp.Matrix,
    rhs: sp.Expr | sp.Matrix,
    label: str,
    functions: Sequence[Subject] | None = None,
    bound: float = 3.0,
    points: int = POINTS,
) -> Sweep:
    """Worst relative residual of lhs − rhs over random φ, u (and each generating function)."""
    residual_at, reference_at = compile_numeric(lhs - rhs), compile_numeric(lhs)

    def evaluate(fn: Subject | None, phi: mpmath.mpf, u: Vector) -> tuple[Any, Any]:
        args = numeric_arguments(fn, phi, u)
        return residual_at(*args), reference_at(*args)

    return sweep_function(label, evaluate, functions, bound, points)


def conclude(what: str, symbolic: Verdict | None, numeric: Sweep | None) -> bool:
    """The common verdict of the symbolic and numeric checks (they must not disagree)."""
    if numeric is not None and numeric.holds is None:
        raise AuditInconsistency(f"{what}: numeric residual {fmt(numeric.worst)} is inconclusive")
    verdicts = {
        v for v in (symbolic.holds if symbolic else None, numeric.holds if numeric else None) if v is not None
    }
    if len(verdicts) > 1:
        raise AuditInconsistency(
            f"{what}: symbolic and numeric verdicts disagree "
            f"({symbolic.describe() if symbolic else ''}; "
            f"{numeric.describe() if numeric else ''})"
        )
    if not verdicts:
        raise AuditInconsistency(f"{what}: neither a symbolic nor a numeric verdict")
    return verdicts.pop()


@dataclass(frozen=True)
class Claim:
    """lhs = rhs, for every generating function (``p=None``, generic) or one given p."""

    lhs: sp.Expr | sp.Matrix
    rhs: sp.Expr | sp.Matrix
    p: sp.Expr | None = None
    any_p: bool = True
    bound: float = 3.0
    symbolic: bool = True

    def _concrete(self, expr: sp.Expr | sp.Matrix) -> sp.Expr | sp.Matrix:
        if self.p is None:
            return expr
        return expr.subs({DP: sp.diff(self.p, PHI)}).subs({P: self.p})

    def settle(self, label: str) -> tuple[bool, Verdict | None, Sweep]:
        lhs, rhs = self._concrete(self.lhs), self._concrete(self.rhs)
        verdict = identity(at_e1(lhs), at_e1(rhs)) if self.symbolic else None
        functions: Sequence[Subject] | None = None
        if self.p is not None:
            functions = [subject(f"p = {self.p}", self.p)]
        elif self.any_p:
            functions = list(subjects())
        numeric = sweep(lhs, rhs, label, functions, self.bound)
        return conclude(label, verdict, numeric), verdict, numeric


def scope_text(claim: Claim) -> str:
    if claim.p is not None:
        return f"p = {claim.p}"
    if claim.any_p:
        return f"any p: generic symbols p, p'; numerically {len(subjects())} generating functions"
    return ""


def evidence(verdict: Verdict | None, numeric: Sweep, claim: Claim) -> str:
    parts = []
    if verdict is not None:
        parts.append(f"symbolic: {verdict.describe()}")
    parts.append(numeric.describe())
    scope = scope_text(claim)
    return "; ".join(parts) + (f" [{scope}]" if scope else "")


def settle(label: str, claim: Claim, corrected: tuple[str, Claim] | None = None) -> Outcome:
    """HOLDS, or ERRATUM with the corrected statement proved; raises when undecidable."""
    holds, verdict, numeric = claim.settle(label)
    if holds:
        return Outcome(HOLDS, evidence(verdict, numeric, claim))
    if corrected is None:
        raise AuditInconsistency(
            f"{label} fails and no correction is known: {evidence(verdict, numeric, claim)}"
        )
    text, fixed = corrected
    fixed_holds, fixed_verdict, fixed_numeric = fixed.settle(label + ":corrected")
    if not fixed_holds:
        raise AuditInconsistency(
            f"{label}: the corrected form fails too: {evidence(fixed_verdict, fixed_numeric, fixed)}"
        )
    return Outcome(
        ERRATUM,
        f"as printed: {evidence(verdict, numeric, claim)}. Corrected form: "
        f"{evidence(fixed_verdict, fixed_numeric, fixed)}",
        text,
    )


class SymbolicOps:
    """Operations for a transcription evaluated symbolically at u = e₁ (single-axis identities)."""

    sin, cos, tan, sqrt = sp.sin, sp.cos, sp.tan, sp.sqrt
    pi = sp.pi

    @staticmethod
    def eye() -> sp.Matrix:
        return sp.eye(3)

    @staticmethod
    def skew(v: sp.Matrix) -> sp.Matrix:
        return sp.Matrix([[0, -v[2], v[1]], [v[2], 0, -v[0]], [-v[1], v[0], 0]])

    @staticmethod
    def inverse(m: sp.Matrix) -> sp.Matrix:
        return m.inv()

    @staticmethod
    def dot(a: sp.Matrix, b: sp.Matrix) -> sp.Expr:
        return (a.T * b)[0, 0]


class NumericOps:
    """The same operations at working precision (mpmath)."""

    sin, cos, tan, sqrt = mpmath.sin, mpmath.cos, mpmath.tan, mpmath.sqrt
    pi = mpmath.pi

    @staticmethod
    def eye() -> mpmath.matrix:
        return mpmath.eye(3)

    @staticmethod
    def skew(v: Vector) -> mpmath.matrix:
        return mpmath.matrix([[0, -v[2], v[1]], [v[2], 0, -v[0]], [-v[1], v[0], 0]])

    @staticmethod
    def inverse(m: mpmath.matrix) -> mpmath.matrix:
        return mpmath.inverse(m)

    @staticmethod
    def dot(a: Vector, b: Vector) -> mpmath.mpf:
        return sum(a[i] * b[i] for i in range(3))


Transcription = Callable[..., Any]
"""f(ops, phi, u) → scalar or 3×3 tensor, written once for both SymbolicOps and NumericOps."""


def settle_dual(
    label: str, lhs: Transcription, rhs: Transcription, bound: float = 3.0, points: int = 4
) -> tuple[bool, Verdict, Sweep]:
    """lhs = rhs symbolically (φ, u = e₁) and numerically (random φ, u); verdicts must agree."""
    e1 = sp.Matrix([1, 0, 0])
    verdict = identity(lhs(SymbolicOps, PHI, e1), rhs(SymbolicOps, PHI, e1))

    def evaluate(fn: Subject | None, phi: mpmath.mpf, u: Vector) -> tuple[Any, Any]:
        left = lhs(NumericOps, phi, u)
        return left - rhs(NumericOps, phi, u), left

    numeric = sweep_function(label, evaluate, None, bound, points)
    return conclude(label, verdict, numeric), verdict, numeric


def dual_outcome(
    label: str,
    lhs: Transcription,
    rhs: Transcription,
    bound: float = 3.0,
    corrected: tuple[str, Transcription] | None = None,
    note: str = "",
) -> Outcome:
    """HOLDS, or ERRATUM with the corrected left-hand side ``corrected`` proved equal to rhs."""
    holds, verdict, numeric = settle_dual(label, lhs, rhs, bound)
    text = f"symbolic (u = e1): {verdict.describe()}; {numeric.describe()}"
    if holds:
        return Outcome(HOLDS, text + (f"; {note}" if note else ""))
    if corrected is None:
        raise AuditInconsistency(f"{label} fails and no correction is known: {text}")
    fixed_text, fixed = corrected
    fixed_holds, fixed_verdict, fixed_numeric = settle_dual(label + ":corrected", fixed, rhs, bound)
    if not fixed_holds:
        raise AuditInconsistency(f"{label}: the corrected form fails too")
    return Outcome(
        ERRATUM,
        f"as printed: {text}. Corrected form: symbolic (u = e1): "
        f"{fixed_verdict.describe()}; {fixed_numeric.describe()}" + (f"; {note}" if note else ""),
        fixed_text,
    )
