"""Table 1, cell by cell, and the sentence of Section 3.3 that describes its columns.

Columns as printed: name, p(φ), p′, ν, ε, validity range. The p cell is checked against the
numbered equation of the named parameterization; p′, ν, ε against the core's scalar functions
(symbolic and numeric); the validity range against :func:`symrot.core.singularities.validity` (the
first singular angle), with an independent exact counterexample where the table is wrong.
"""

from __future__ import annotations

import functools
from collections.abc import Callable
from dataclasses import dataclass

import sympy as sp

from symrot.audit.claims import Claim, evidence
from symrot.audit.records import ERRATUM, HOLDS, AuditInconsistency, Check, Outcome
from symrot.audit.section2 import R_EQ1
from symrot.core.derivation import derive_expression, scalar_definitions
from symrot.core.parsing import PHI
from symrot.core.registry import lookup
from symrot.core.singularities import validity

HALF, QUARTER = PHI / 2, PHI / 4


@dataclass(frozen=True)
class Row:
    key: str
    name: str
    """The name cell as printed (empty in our copy for the last row)."""
    identifier: str
    equation: str
    p: sp.Expr
    cells: dict[str, tuple[str, sp.Expr]]
    """Column → (LaTeX as printed, transcription)."""
    validity: tuple[str, sp.Expr]


ROWS = (
    Row(
        "rotation_vector",
        "Exponential map",
        "rotation_vector",
        "30",
        PHI,
        {
            "p_prime": ("1", sp.Integer(1)),
            "nu": (r"\frac{\sin \varphi/2}{\varphi/2}", sp.sin(HALF) / HALF),
            "epsilon": (r"\frac{\tan \varphi/2}{\varphi/2}", sp.tan(HALF) / HALF),
        },
        (r"<\pm 2\pi", 2 * sp.pi),
    ),
    Row(
        "cayley_gibbs_rodrigues",
        "Cayley-Gibbs-Rodrigues",
        "cayley_gibbs_rodrigues",
        "33",
        2 * sp.tan(HALF),
        {
            "p_prime": (r"\frac{1}{\cos^2 \varphi/2}", 1 / sp.cos(HALF) ** 2),
            "nu": (r"\cos \varphi/2", sp.cos(HALF)),
            "epsilon": ("1", sp.Integer(1)),
        },
        (r"<\pm\pi", sp.pi),
    ),
    Row(
        "wiener_milenkovic",
        "Wiener-Milenkovic",
        "wiener_milenkovic",
        "34",
        4 * sp.tan(QUARTER),
        {
            "p_prime": (r"\frac{1}{\cos^2 \varphi/4}", 1 / sp.cos(QUARTER) ** 2),
            "nu": (r"\cos^2 \varphi/4", sp.cos(QUARTER) ** 2),
            "epsilon": (r"\frac{1}{1-\tan^2\varphi/4}", 1 / (1 - sp.tan(QUARTER) ** 2)),
        },
        (r"<\pm 2\pi", 2 * sp.pi),
    ),
    Row(
        "linear",
        "Linear Parameters",
        "linear",
        "31",
        sp.sin(PHI),
        {
            "p_prime": (r"\cos \varphi", sp.cos(PHI)),
            "nu": (r"\frac{1}{\cos \varphi/2}", 1 / sp.cos(HALF)),
            "epsilon": (r"\frac{1}{\cos^2 \varphi/2}", 1 / sp.cos(HALF) ** 2),
        },
        (r"<\pm\pi", sp.pi),
    ),
    Row(
        "euler_rodrigues",
        "Euler Rodrigues",
        "euler_rodrigues",
        "32",
        2 * sp.sin(HALF),
        {
            "p_prime": (r"\cos \varphi/2", sp.cos(HALF)),
            "nu": ("1", sp.Integer(1)),
            "epsilon": (r"\frac{1}{\cos \varphi/2}", 1 / sp.cos(HALF)),
        },
        (r"<\pm\pi", sp.pi),
    ),
    Row(
        "sine_m4",
        "",
        "sine_m4",
        "36 (sine family, m = 4)",
        4 * sp.sin(QUARTER),
        {
            "p_prime": (r"\cos \varphi/4", sp.cos(QUARTER)),
            "nu": (r"\cos \varphi/4", sp.cos(QUARTER)),
            "epsilon": (r"\frac{\cos \varphi/4}{\cos \varphi/2}", sp.cos(QUARTER) / sp.cos(HALF)),
        },
        (r"<\pm 2\pi", 2 * sp.pi),
    ),
)


def _name_cell(row: Row) -> Outcome:
    entry = lookup(row.identifier)
    if entry.expression != row.p:
        raise AuditInconsistency(f"{row.key}: p = {row.p} is not eq {row.equation}")
    named = (
        f"named '{row.name}' in the table"
        if row.name
        else "the name cell is empty in our copy; the row is the m = 4 member of the sine family "
        "discussed in Section 3.3"
    )
    return Outcome(HOLDS, f"p = {row.p} is eq ({row.equation}), {entry.title}; {named}")


def _scalar_cell(row: Row, column: str) -> Callable[[], Outcome]:
    def verify() -> Outcome:
        derived = scalar_definitions(row.p)["epsilon" if column == "epsilon" else column]
        claim = Claim(derived, row.cells[column][1], p=row.p)
        holds, verdict, numeric = claim.settle(f"table1:{row.key}:{column}")
        if not holds:
            raise AuditInconsistency(f"Table 1 {row.key} {column}: {evidence(verdict, numeric, claim)}")
        return Outcome(HOLDS, f"against the core's {column} = {derived}: {evidence(verdict, numeric, claim)}")

    return verify


def _linear_counterexample() -> str:
    """Exact: sin(π/3) = sin(2π/3), so one p vector stands for two different rotations."""
    first, second = sp.pi / 3, 2 * sp.pi / 3
    same_p = sp.simplify(sp.sin(first) - sp.sin(second)) == 0
    u_e1 = {sp.Symbol("u1"): 1, sp.Symbol("u2"): 0, sp.Symbol("u3"): 0}
    r1, r2 = (R_EQ1.subs(PHI, angle).subs(u_e1) for angle in (first, second))
    difference = sp.simplify(r1 - r2)
    if not same_p or difference == sp.zeros(3):
        raise AuditInconsistency("linear counterexample")
    return (
        f"exact: p(pi/3) = p(2 pi/3) = sqrt(3)/2, so p = (sqrt(3)/2) u stands for rotations by pi/3 "
        f"and 2 pi/3 about u, whose tensors differ by {difference.tolist()} (u = e1); at pi/2, "
        "p' = cos(pi/2) = 0"
    )


def _validity_cell(row: Row) -> Callable[[], Outcome]:
    def verify() -> Outcome:
        result = validity(derive_expression(row.p))
        first = [s for s in result.singularities if sp.simplify(s.phi - result.phi_max) == 0]
        causes = "; ".join(sorted({s.cause for s in first}))
        found = f"first singular angle phi = {result.phi_max} ({causes})"
        if sp.simplify(result.phi_max - row.validity[1]) == 0:
            return Outcome(HOLDS, f"symrot.core.singularities: {found}")
        if row.key != "linear":
            raise AuditInconsistency(f"{row.key}: validity {row.validity[1]} vs {found}")
        return Outcome(
            ERRATUM,
            f"symrot.core.singularities: {found}. {_linear_counterexample()}",
            rf"<\pm {sp.latex(result.phi_max)} \text{{ (mu = 1/cos(phi) is infinite and p = "
            r"sin(phi) stops being monotonic at |phi| = pi/2)}",
        )

    return verify


def _caption() -> Outcome:
    """Section 3.3: 'the relevant scalar functions p′(φ), ν(φ), and det(H)(φ)' — the column is ε."""
    differs = []
    for row in ROWS:
        scalars = scalar_definitions(row.p)
        printed = row.cells["epsilon"][1]
        claim = Claim(scalars["det_H"], printed, p=row.p)
        holds = claim.settle(f"caption:{row.key}")[0]
        if not holds:
            differs.append(row.key)
    if not differs:
        raise AuditInconsistency("every fifth-column cell equals det H")
    return Outcome(
        ERRATUM,
        "every cell of the fifth column equals epsilon = 2 tan(phi/2)/p (the Table 1 "
        "epsilon checks) and differs from det H = mu nu^2 (eq 24) for "
        f"{', '.join(differs)} (symbolic and numeric; they coincide only for "
        f"{', '.join(r.key for r in ROWS if r.key not in differs)})",
        r"\text{Table 1 lists ... the relevant scalar functions } p'(\varphi), \nu(\varphi), "
        r"\text{ and } \varepsilon(\varphi)",
    )


def _checks() -> list[Check]:
    checks = [
        Check(
            "text before Table 1: columns",
            r"\text{the relevant scalar functions } p'(\varphi), \nu(\varphi), \text{ and } "
            r"\det(\mathbf{H})(\varphi)",
            "symbolic + numeric",
            _caption,
        )
    ]
    for row in ROWS:
        checks.append(
            Check(
                f"Table 1 {row.key} p",
                f"{row.name or '(no name)'}: p(\\varphi) = {sp.latex(row.p)}",
                "structural",
                functools.partial(_name_cell, row),
            )
        )
        for column in ("p_prime", "nu", "epsilon"):
            checks.append(
                Check(
                    f"Table 1 {row.key} {column}",
                    row.cells[column][0],
                    "symbolic + numeric",
                    _scalar_cell(row, column),
                )
            )
        checks.append(
            Check(f"Table 1 {row.key} validity", row.validity[0], "singularities", _validity_cell(row))
        )
    return checks


CHECKS = _checks()
