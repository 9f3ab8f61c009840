"""Named parameterizations of the paper, with stable identifiers.

Eqs (30)-(35), the sine and tangent families p = m sin(φ/m), m tan(φ/m) of any order m (36), and
the m-th order Cayley vector ζ_(m) = tan(φ/(2m)) u (101, κ = 1/(2m)). Each entry also records the
property of Section 3.2 that defines it, so that ``symrot solve`` can derive it back.
"""

from __future__ import annotations

import difflib
import re
from dataclasses import dataclass

import sympy as sp

from symrot.core.errors import UnknownName
from symrot.core.functions import RealCbrt
from symrot.core.parsing import FUNCTIONS, PHI

MAX_FAMILY_ORDER = 1000
MAX_SHOWN_NAME = 60
"""An unknown name is quoted, and compared with the registry's, by its first characters only."""


@dataclass(frozen=True)
class NamedParameterization:
    identifier: str
    title: str
    equation: str
    expression: sp.Expr
    defining_property: str | None = None
    """The property of Section 3.2 that yields it (input of ``symrot solve``), if any."""


_FIXED = {
    "rotation_vector": NamedParameterization(
        "rotation_vector", "Rotation vector (exponential map)", "30", PHI, "mu = 1"
    ),
    "linear": NamedParameterization(
        "linear", "Linear parameters", "31", sp.sin(PHI), "nu**2 = c*eps"
    ),
    "euler_rodrigues": NamedParameterization(
        "euler_rodrigues", "Reduced Euler-Rodrigues parameters", "32", 2 * sp.sin(PHI / 2),
        "nu**2 = 2*c",
    ),
    "cayley_gibbs_rodrigues": NamedParameterization(
        "cayley_gibbs_rodrigues", "Cayley-Gibbs-Rodrigues parameters", "33",
        2 * sp.tan(PHI / 2), "mu = nu**2/eps",
    ),
    "wiener_milenkovic": NamedParameterization(
        "wiener_milenkovic", "Wiener-Milenkovic parameters", "34", 4 * sp.tan(PHI / 4),
        "2*p_prime*sin(phi/2) = p",
    ),
    "det_h_one": NamedParameterization(
        "det_h_one", "Constant det H parameterization", "35",
        RealCbrt(6 * (PHI - sp.sin(PHI))), "det_H = const",
    ),
}

TABLE_1 = (
    "rotation_vector",
    "cayley_gibbs_rodrigues",
    "wiener_milenkovic",
    "linear",
    "euler_rodrigues",
    "sine_m4",
)
"""The six rows of the paper's Table 1, in its order."""

PAPER_TABLE_1_VALIDITY = {
    "rotation_vector": 2 * sp.pi,
    "cayley_gibbs_rodrigues": sp.pi,
    "wiener_milenkovic": 2 * sp.pi,
    "linear": sp.pi,
    "euler_rodrigues": sp.pi,
    "sine_m4": 2 * sp.pi,
}
"""The validity bound |φ| < … as *printed* in the paper's Table 1 (transcribed, for comparison
only: symrot's own ranges come from :mod:`symrot.core.singularities`)."""

NAMED = (*_FIXED, "sine_m4")
"""The named parameterizations that ``make generate`` writes (Table 1 and eq 35)."""

_FAMILY = re.compile(r"^(sine|tangent|cayley)_m([1-9][0-9]*)$")
_WORD = re.compile(r"[A-Za-z_][A-Za-z0-9_]*")
_EXPRESSION_WORDS = {"phi", "pi", *FUNCTIONS}


def family_member(family: str, m: int) -> NamedParameterization:
    """m sin(φ/m), m tan(φ/m) (eq 36) or the m-th order Cayley vector tan(φ/(2m)) (eq 101)."""
    if not 1 <= m <= MAX_FAMILY_ORDER:
        raise UnknownName(f"family order m must be between 1 and {MAX_FAMILY_ORDER}")
    if family == "sine":
        return NamedParameterization(
            f"sine_m{m}", f"Sine family, m = {m}", "36", m * sp.sin(PHI / m),
            f"mu = 1/sqrt(1 - p**2/{m ** 2})",
        )
    if family == "tangent":
        return NamedParameterization(
            f"tangent_m{m}", f"Tangent family, m = {m}", "36", m * sp.tan(PHI / m),
            f"mu = 1/(1 + p**2/{m ** 2})",
        )
    return NamedParameterization(
        f"cayley_m{m}", f"Cayley vector of order {m}", "101", sp.tan(PHI / (2 * m)), None
    )


def lookup(identifier: str) -> NamedParameterization:
    """The named parameterization ``identifier`` (raises :class:`UnknownName`)."""
    if identifier in _FIXED:
        return _FIXED[identifier]
    match = _FAMILY.match(identifier)
    if match and len(match.group(2)) <= 4:
        return family_member(match.group(1), int(match.group(2)))
    raise UnknownName(unknown_name_message(identifier))


def unknown_name_message(identifier: str) -> str:
    """"unknown parameterization …", with the closest registry names and the list of all of them."""
    shown = identifier[:MAX_SHOWN_NAME]
    # Trailing digits by rstrip, in linear time: re.search(r"([0-9]+)$") retried every run of
    # digits from each of its positions, quadratic ('a' + '9' * 200000 + 'b' ran for minutes).
    order = shown[len(shown.rstrip("0123456789")):]
    families = [f"{family}_m{order or 'N'}" for family in ("sine", "tangent", "cayley")]
    close = difflib.get_close_matches(shown.lower(), [*_FIXED, *families], n=3, cutoff=0.6)
    hint = f"; did you mean {' or '.join(close)}?" if close else ""
    known = ", ".join([*_FIXED, "sine_mN", "tangent_mN", "cayley_mN"])
    return f"unknown parameterization '{shown}'{hint} (registry names: {known})"


def is_identifier(text: str) -> bool:
    return text in _FIXED or bool(_FAMILY.match(text))


def looks_like_a_name(text: str) -> bool:
    """A bare word that is no part of the expression language (phi, pi, function names): a
    registry identifier, possibly misspelt."""
    return bool(_WORD.fullmatch(text)) and text not in _EXPRESSION_WORDS


def find_by_expression(expr: sp.Expr) -> NamedParameterization | None:
    """The registry entry whose p(φ) is structurally ``expr`` (fixed entries and m ≤ 12)."""
    candidates = [*_FIXED.values()] + [
        family_member(f, m) for f in ("sine", "tangent", "cayley") for m in range(1, 13)
    ]
    expanded = sp.expand(expr)
    for entry in candidates:
        if entry.expression == expr or sp.expand(entry.expression) == expanded:
            return entry
    return None
