"""Sections 3.2–3.3, special generating functions: eqs (30)–(39) and the statements around them.

Each generating function of Section 3.2 is derived from its defining property: the property is
reduced to an ODE p′ = g(φ) p (or (p³)′ = g(φ)), whose solutions are C·h(φ) because h′ − g h ≡ 0
(checked symbolically) and first-order linear ODEs have one-parameter solution families; the
limit condition (13), κ = 1, then fixes C.
"""

from __future__ import annotations

import sympy as sp

from symrot.audit.claims import Claim, settle
from symrot.audit.proof import DP, EPS, MU, NU, P, is_zero
from symrot.audit.records import ERRATUM, HOLDS, AuditInconsistency, Check, Outcome, definition
from symrot.core.derivation import root_tangent, root_tensor
from symrot.core.functions import RealCbrt
from symrot.core.parsing import PHI
from symrot.core.registry import family_member, lookup
from symrot.core.validation import validate

C = sp.Symbol("c", positive=True)
P0 = sp.cos(PHI / 4)
"""p₀ = cos(φ/4) of Section 3.3 (sine family, m = 4)."""
SINE_M4 = 4 * sp.sin(PHI / 4)
FAMILY_ORDERS = range(1, 7)


def _require(what: str, verdict: bool | None) -> None:
    if verdict is not True:
        raise AuditInconsistency(f"could not prove: {what}")


def _kappa(expr: sp.Expr) -> sp.Expr:
    return validate(expr).kappa


def _linear_ode(g: sp.Expr, h: sp.Expr) -> None:
    """p′ = g p has the solutions C h: h′ − g h ≡ 0."""
    _require(f"h' = g h for h = {h}", is_zero(sp.diff(h, PHI) - g * h))


def _eq31() -> Outcome:
    [solution] = sp.solve(sp.Eq(NU**2, C * EPS), P)
    _require("p = sin(phi)/c", is_zero(solution - sp.sin(PHI) / C))
    kappa = _kappa(sp.sin(PHI))
    if kappa != 1:
        raise AuditInconsistency("kappa(sin phi) != 1")
    holds = Claim(NU**2 / EPS, sp.Integer(1), p=sp.sin(PHI)).settle("31")[0]
    _require("nu^2 = eps for sin(phi)", holds)
    return Outcome(
        HOLDS,
        "symbolic: nu^2 = c eps (15, 16) solved for p gives p = sin(phi)/c, kappa = 1/c, "
        "so the limit condition (13) gives c = 1 (as printed) and p = sin(phi); "
        "nu^2/eps = 1 for p = sin(phi) (symbolic and numeric)",
    )


def _eq32() -> Outcome:
    solutions = sp.solve(sp.Eq(NU**2, 2 * C), P)
    _require(
        "nu^2 = 2c <=> p^2 = (2/c) sin^2(phi/2)",
        (len(solutions) == 2 and all(is_zero(s**2 - 2 * sp.sin(PHI / 2) ** 2 / C) for s in solutions))
        or None,
    )
    _require("nu = 1 for p = 2 sin(phi/2)", is_zero((NU - 1).subs(P, 2 * sp.sin(PHI / 2))))
    return Outcome(
        HOLDS,
        "symbolic: nu^2 = 2c solved for p gives p = ±sqrt(2/c) sin(phi/2), so every "
        "generating function with constant nu is a multiple of sin(phi/2) and kappa = 1 "
        "gives p = 2 sin(phi/2) (nu = 1), as printed; the constant is checked separately",
    )


def _c_of_32() -> Outcome:
    [c_value] = sp.solve(sp.Eq(sp.simplify(NU.subs(P, 2 * sp.sin(PHI / 2))) ** 2, 2 * C), C)
    printed_p = [s for s in sp.solve(sp.Eq(NU**2, 2 * C), P) if (s / sp.sin(PHI / 2)).is_positive]
    with_two = printed_p[0].subs(C, 2)
    if c_value != sp.Rational(1, 2) or _kappa(with_two) != sp.Rational(1, 2):
        raise AuditInconsistency(f"c = {c_value}")
    return Outcome(
        ERRATUM,
        "symbolic: p = 2 sin(phi/2) gives nu = 1, so nu^2 = 2c holds with "
        f"c = {c_value}; with c = 2 the condition gives p = {with_two}, whose kappa is "
        f"{_kappa(with_two)}, not 1",
        r"\nu^2 = 2c \text{ leading to } p(\varphi) = 2\sin\frac{\varphi}{2} \text{ and } "
        r"c = 1/2 \text{ (equivalently } \nu^2 = c/2 \text{ with } c = 2)",
    )


def _kappa_citation() -> Outcome:
    kappa = _kappa(sp.sin(PHI / 2))
    if kappa != sp.Rational(1, 2):
        raise AuditInconsistency(f"kappa(sin(phi/2)) = {kappa}")
    return Outcome(
        ERRATUM,
        "kappa = 1/2 is right (eq (12) on the exact Taylor series of sin(phi/2)), "
        "but the normalization factor is defined by eq (12); eq (32) is the generating "
        "function p = 2 sin(phi/2)",
        r"\text{the normalization factor, equation (12), is } \kappa = 1/2",
    )


def _h_inverse_condition() -> Outcome:
    """2p′ tan(φ/2) = p ⟺ last term of (26) vanishes; solution 2 sin(φ/2)."""
    _require(
        "(1/eps - 1/mu) 2 tan(phi/2) = p - 2 p' tan(phi/2)",
        is_zero((1 / EPS - 1 / MU) * 2 * sp.tan(PHI / 2) - (P - 2 * DP * sp.tan(PHI / 2))),
    )
    _linear_ode(1 / (2 * sp.tan(PHI / 2)), sp.sin(PHI / 2))
    if _kappa(2 * sp.sin(PHI / 2)) != 1:
        raise AuditInconsistency("kappa")
    return Outcome(
        HOLDS,
        "symbolic: (1/eps - 1/mu) 2 tan(phi/2) = p - 2 p' tan(phi/2) for any p; the "
        "ODE p' = p/(2 tan(phi/2)) has the solutions C sin(phi/2) (h' - g h = 0), and "
        "kappa = 1 gives C = 2",
    )


def _eq33() -> Outcome:
    _require(
        "mu - nu^2/eps = 0 <=> p' sin(phi) = p", is_zero((MU - NU**2 / EPS) * DP * P - (P - DP * sp.sin(PHI)))
    )
    _linear_ode(1 / sp.sin(PHI), sp.tan(PHI / 2))
    cgr = 2 * sp.tan(PHI / 2)
    _require("eps = 1 for 2 tan(phi/2)", is_zero(EPS.subs(P, cgr) - 1))
    if _kappa(cgr) != 1 or _kappa(sp.tan(PHI / 2)) != sp.Rational(1, 2):
        raise AuditInconsistency("kappa")
    return Outcome(
        HOLDS,
        "symbolic: (mu - nu^2/eps) p p' = p - p' sin(phi) for any p, so the last term "
        "of (22) vanishes iff p' sin(phi) = p; its solutions are C tan(phi/2) and kappa = 1 "
        "gives C = 2. Also eps = 1 for 2 tan(phi/2), and tan(phi/2) has kappa = 1/2, as stated",
    )


def _eq34() -> Outcome:
    wm = 4 * sp.tan(PHI / 4)
    alpha = sp.cos(PHI / 4) ** 2
    h = root_tangent(wm, 1)
    r = root_tensor(wm, 1)
    square = h @ h
    canonical = [square.a - alpha**2 * r.a, square.b - alpha**2 * r.b, square.c - alpha**2 * r.c]
    _require("H^2 = alpha^2 R", all(is_zero(x) for x in canonical))
    _require("p' = 1/alpha", is_zero(sp.diff(wm, PHI) - 1 / alpha))
    _require("p alpha = 2 sin(phi/2)", is_zero(wm * alpha - 2 * sp.sin(PHI / 2)))
    _linear_ode(1 / (2 * sp.sin(PHI / 2)), sp.tan(PHI / 4))
    if _kappa(wm) != 1:
        raise AuditInconsistency("kappa")
    return Outcome(
        HOLDS,
        "symbolic: for p = 4 tan(phi/4) the core's H satisfies H^2 = alpha^2 R with "
        "alpha = cos^2(phi/4) (axial-tensor algebra), p' = 1/alpha, p alpha = 2 sin(phi/2); "
        "the ODE 2 p' sin(phi/2) = p has the solutions C tan(phi/4) and kappa = 1 gives C = 4",
    )


def _eq35() -> Outcome:
    p = RealCbrt(6 * (PHI - sp.sin(PHI)))
    _require("det H = mu nu^2 = c <=> c p' = nu^2", is_zero((MU * NU**2 - C) * DP - (NU**2 - C * DP)))
    # c p' = nu^2 <=> (p^3)' = (12/c) sin^2(phi/2); p^3 = (6/c)(phi - sin phi) (+0 since p is odd)
    _require(
        "(6(phi - sin phi))' = 12 sin^2(phi/2)",
        is_zero(sp.diff(6 * (PHI - sp.sin(PHI)), PHI) - 12 * sp.sin(PHI / 2) ** 2),
    )
    if _kappa(p) != 1:
        raise AuditInconsistency("kappa of eq 35")
    holds = settle("35", Claim(MU * NU**2, sp.Integer(1), p=p))
    return Outcome(
        HOLDS,
        "symbolic: det H = c <=> c p' = nu^2 <=> (p^3)' = (12/c) sin^2(phi/2), so "
        "p^3 = (6/c)(phi - sin phi) (odd p), kappa = c^(-1/3) = 1 gives c = 1; det H = 1 for "
        f"eq (35): {holds.evidence}",
    )


def _eq37() -> Outcome:
    notes = []
    for m in FAMILY_ORDERS:
        sine, tangent = family_member("sine", m).expression, family_member("tangent", m).expression
        first = Claim(MU, 1 / sp.cos(PHI / m), p=sine)
        second = Claim(MU, 1 / sp.sqrt(1 - P**2 / m**2), p=sine, symbolic=False)
        third = Claim(MU, sp.cos(PHI / m) ** 2, p=tangent)
        fourth = Claim(MU, 1 / (1 + P**2 / m**2), p=tangent)
        for index, claim in enumerate((first, second, third, fourth)):
            if not claim.settle(f"37:{m}:{index}")[0]:
                raise AuditInconsistency(f"(37) fails for m = {m}, form {index}")
    notes.append(
        "sine family: mu = 1/cos(phi/m) symbolic; = 1/sqrt(1 - p^2/m^2) numeric (< 1e-45) for "
        "|phi| < m pi/2, where p is invertible (for m = 1 and pi/2 < |phi| <= pi the root is "
        "-mu: the expression in p presupposes the validity range of Table 1, see the linear "
        "row)"
    )
    notes.append("tangent family: both forms symbolic and numeric")
    return Outcome(HOLDS, "m = 1..6: " + "; ".join(notes))


def _coincidences() -> Outcome:
    pairs = [
        ("sine", 1, "linear"),
        ("sine", 2, "euler_rodrigues"),
        ("tangent", 2, "cayley_gibbs_rodrigues"),
        ("tangent", 4, "wiener_milenkovic"),
    ]
    for family, m, name in pairs:
        if family_member(family, m).expression != lookup(name).expression:
            raise AuditInconsistency(f"{family} m = {m} is not {name}")
    return Outcome(
        HOLDS,
        "structurally equal registry expressions: sine m = 1 = sin(phi) (31), sine m = 2 = "
        "2 sin(phi/2) (32), tangent m = 2 = 2 tan(phi/2) (33), tangent m = 4 = 4 tan(phi/4) (34)",
    )


def _p0() -> Outcome:
    printed = sp.sqrt(1 - P**2 / 4)
    corrected = sp.sqrt(1 - P**2 / 16)
    at_pi = printed.subs(P, SINE_M4).subs(PHI, sp.pi)
    fixed = settle("p0", Claim(P0, corrected, p=SINE_M4))
    if at_pi.is_real is not False or fixed.status != HOLDS:
        raise AuditInconsistency("p0 check inconsistent")
    return Outcome(
        ERRATUM,
        f"exact: at phi = pi, p = 4 sin(pi/4) = 2 sqrt(2) and sqrt(1 - p^2/4) = "
        f"{sp.simplify(at_pi)}, while p0 = cos(pi/4) = sqrt(2)/2; in general p^2/4 = "
        "4 sin^2(phi/4). Corrected form: sqrt(1 - p^2/16) = sqrt(1 - sin^2(phi/4)) = cos(phi/4) where "
        "cos(phi/4) >= 0, i.e. |phi| <= 2 pi; " + fixed.evidence + ". The range p0 in [1/sqrt(2), 1] "
        "for |phi| <= pi holds (cos(phi/4) decreasing on [0, pi])",
        r"p_0 = \cos \varphi/4 = \sqrt{1 - p^2/16}",
    )


def _eq38() -> Outcome:
    nu = settle("38:nu", Claim(NU, P0, p=SINE_M4))
    eps = settle(
        "38:eps",
        Claim(EPS, P0**3 / (2 * P0**2 - 1), p=SINE_M4),
        (r"\varepsilon = \frac{p_0}{2p_0^2 - 1}", Claim(EPS, P0 / (2 * P0**2 - 1), p=SINE_M4)),
    )
    if nu.status != HOLDS or eps.status != ERRATUM:
        raise AuditInconsistency("(38) inconsistent")
    residual = sp.factor(sp.simplify(P0**3 / (2 * P0**2 - 1) - P0 / (2 * P0**2 - 1)))
    return Outcome(
        ERRATUM,
        f"nu = p0 holds ({nu.evidence}). epsilon: printed - corrected = {residual} "
        f"(= -cos(phi/4) sin^2(phi/4)/cos(phi/2) != 0); {eps.evidence}",
        r"\nu \equiv p_0; \quad \varepsilon = \frac{p_0}{2p_0^2 - 1} "
        r"\;(= \cos(\varphi/4)/\cos(\varphi/2), \text{ as in Table 1})",
    )


CHECKS = [
    Check(
        "30",
        r"p(\varphi) = \varphi",
        "definition",
        lambda: definition(
            "chooses the rotation vector (kappa = 1); a Table-1 row and one of the "
            "generating functions of every 'any p' check"
        ),
    ),
    Check("31", r"p(\varphi) = \sin \varphi", "symbolic", _eq31),
    Check("32", r"p(\varphi) = 2\,\sin\frac{\varphi}{2}", "symbolic", _eq32),
    Check(
        "text after (32): c",
        r"\nu^2 = 2c, \text{ leading to } p(\varphi) = 2\,\sin\frac{\varphi}{2} "
        r"\text{ and } c = 2",
        "symbolic",
        _c_of_32,
    ),
    Check(
        "text after (32): kappa",
        r"p(\varphi) = \sin(\varphi/2), \text{ in which case the "
        r"normalization factor, equation (32), is } \kappa = 1/2",
        "symbolic",
        _kappa_citation,
    ),
    Check(
        "text after (32): H^-1",
        r"2p' \tan(\varphi/2) = p \text{ whose solution is } p(\varphi) = "
        r"2 \sin \varphi/2",
        "symbolic",
        _h_inverse_condition,
    ),
    Check("33", r"p(\varphi) = 2\tan\frac{\varphi}{2}", "symbolic", _eq33),
    Check("34", r"p(\varphi) = 4 \tan \frac{\varphi}{4}", "symbolic", _eq34),
    Check("35", r"p(\varphi) = \sqrt[3]{6(\varphi - \sin \varphi)}", "symbolic + numeric", _eq35),
    Check(
        "36",
        r"p(\varphi) = m \sin \frac{\varphi}{m}, \quad \text{and} \quad p(\varphi) = m \tan "
        r"\frac{\varphi}{m}",
        "definition",
        lambda: definition(
            "defines the sine and tangent families; members m = 1..6 are generating "
            "functions of every 'any p' check"
        ),
    ),
    Check(
        "37",
        r"\mu(\varphi) = \frac{1}{\cos\frac{\varphi}{m}} = \frac{1}{\sqrt{1 - \frac{p(\varphi)^2}"
        r"{m^2}}}, \quad \text{and} \quad \mu(\varphi) = \cos^2\frac{\varphi}{m} = \frac{1}{1 + "
        r"\frac{p(\varphi)^2}{m^2}}",
        "symbolic + numeric",
        _eq37,
    ),
    Check(
        "text after (37): family members",
        r"\text{linear} = \text{sine } m = 1, \dots",
        "structural",
        _coincidences,
    ),
    Check("text before (38): p0", r"p_0 = \cos \varphi/4 = \sqrt{(1 - p^2/4)}", "exact + numeric", _p0),
    Check("38", r"\nu \equiv p_0; \quad \varepsilon = \frac{p_0^3}{2p_0^2 - 1}", "symbolic + numeric", _eq38),
    Check("39", r"\mu = 1/p_0", "symbolic + numeric", lambda: settle("39", Claim(MU, 1 / P0, p=SINE_M4))),
]
