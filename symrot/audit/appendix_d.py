"""Appendix D, the Cayley transform: eqs (92)–(102) and the statements around them.

Each tensor formula is transcribed once as a function of an operations object, evaluated
symbolically at u = e₁ and numerically at random φ, u (:func:`symrot.audit.claims.settle_dual`).
"""

from __future__ import annotations

from typing import Any

import mpmath
import sympy as sp

from symrot.audit.claims import Claim, dual_outcome, evidence, settle, settle_dual, sweep_function
from symrot.audit.kinematics import describe, tensor_at, trajectory_sweep
from symrot.audit.numeric import (
    TOLERANCE,
    Vector,
    cross,
    dot,
    fmt,
    precision,
    random_angle,
    random_axis,
    relative,
    rng,
    rotation,
    skew,
)
from symrot.audit.proof import EPS, EYE, MU, NU, U_CROSS, P, at_e1, core_tensor, identity
from symrot.audit.records import ERRATUM, HOLDS, AuditInconsistency, Check, Outcome, definition
from symrot.audit.subjects import Subject, scope, subject, subjects
from symrot.core.parsing import PHI
from symrot.core.registry import family_member
from symrot.core.validation import validate

ORDERS = range(1, 7)
ZETA = sp.tan(PHI / 2)


def _r(o: Any, phi: Any, u: Any) -> Any:
    k = o.skew(u)
    return o.eye() + o.sin(phi) * k + (1 - o.cos(phi)) * k * k


def _z(o: Any, phi: Any, u: Any, m: int = 1) -> Any:
    """(ζ_(m)×) with ζ_(m) = tan(φ/(2m)) u (93, 101)."""
    return o.skew(o.tan(phi / (2 * m)) * u)


def _cay(o: Any, z: Any, m: int = 1) -> Any:
    """(99) cay_(m)(A) = (I + A)^m (I − A)^(−m); (92) for m = 1 with (I + A)^(−T) = (I − A)^(−1)."""
    return (o.eye() + z) ** m * o.inverse(o.eye() - z) ** m


def _eq92() -> Outcome:
    def first(o: Any, phi: Any, u: Any) -> Any:
        z = _z(o, phi, u)
        return (o.eye() + z) * o.inverse((o.eye() + z).T)

    def second(o: Any, phi: Any, u: Any) -> Any:
        z = _z(o, phi, u)
        return o.inverse((o.eye() + z).T) * (o.eye() + z)

    outcome = dual_outcome("92", first, second)
    return Outcome(
        HOLDS,
        "the two products agree ((I + Z) and (I + Z)^-T = (I - Z)^-1 commute); the := part "
        "defines cay: " + outcome.evidence,
    )


def _cayley_zeta(o: Any, phi: Any, u: Any) -> Any:
    return o.tan(phi / 2) ** 2


def _eq94_printed(o: Any, phi: Any, u: Any) -> Any:
    z = _z(o, phi, u)
    return o.eye() + (o.eye() + z) * z / (1 + _cayley_zeta(o, phi, u))


def _eq94_corrected(o: Any, phi: Any, u: Any) -> Any:
    z = _z(o, phi, u)
    return o.eye() + 2 * (o.eye() + z) * z / (1 + _cayley_zeta(o, phi, u))


def _eq95() -> Outcome:
    """Any p: (I + (ε/2)(p×))(I + (ε/2)(p×))^−T = R, both orders; ζ = (ε/2) p."""
    half = sp.eye(3) + EPS / 2 * P * sp.Matrix([[0, 0, 0], [0, 0, -1], [0, 1, 0]])
    r = at_e1(core_tensor("R"))
    verdicts = [
        identity(half * half.T.inv(), r),
        identity(half.T.inv() * half, r),
        identity(EPS / 2 * P, ZETA),
    ]

    def evaluate(fn: Subject | None, phi: mpmath.mpf, u: Vector) -> tuple[object, object]:
        assert fn is not None
        s = fn.scalars(phi)
        a = mpmath.eye(3) + s["eps"] / 2 * skew(s["p"] * u)
        exact = rotation(phi, u)
        left, right = a * mpmath.inverse(a.T), mpmath.inverse(a.T) * a
        return max(max(abs(x) for x in left - exact), max(abs(x) for x in right - exact)), exact

    numeric = sweep_function("95", evaluate, subjects())
    if not all(v.holds for v in verdicts) or not numeric.holds:
        raise AuditInconsistency(f"(95): {numeric.describe()}")
    return Outcome(
        HOLDS,
        "symbolic (generic p, u = e1): both products equal R and eps p/2 = tan(phi/2) "
        f"(= zeta of (93)); {numeric.describe()} [{scope()}]",
    )


def _eq96(o: Any, phi: Any, u: Any, order: int) -> Any:
    e0, e = o.cos(phi / 2), o.sin(phi / 2) * u
    a = o.eye() + o.skew(e) / e0
    return a * o.inverse(a.T) if order == 0 else o.inverse(a.T) * a


def _eq97() -> Outcome:
    def compose(z1: Vector, z2: Vector, corrected: bool) -> Vector:
        z3 = z1 + z2 - cross(z1, z2)
        return z3 / (1 - dot(z1, z2)) if corrected else z3

    def cay(z: Vector) -> mpmath.matrix:
        return (mpmath.eye(3) + skew(z)) * mpmath.inverse(mpmath.eye(3) - skew(z))

    def evaluate_with(corrected: bool) -> Any:
        def evaluate(fn: Subject | None, phi1: mpmath.mpf, u1: Vector) -> tuple[object, object]:
            r = rng(f"97:{phi1}")
            phi2, u2 = random_angle(r, 2.5), random_axis(r)
            z1, z2 = mpmath.tan(phi1 / 2) * u1, mpmath.tan(phi2 / 2) * u2
            exact = rotation(phi2, u2) * rotation(phi1, u1)
            return cay(compose(z1, z2, corrected)) - exact, exact

        return evaluate

    printed = sweep_function("97", evaluate_with(False), bound=2.5)
    fixed = sweep_function("97:corrected", evaluate_with(True), bound=2.5)
    # exact: zeta1 = zeta2 = (1/2) e1 (same axis): the composed angle is 4 atan(1/2)
    half = sp.Rational(1, 2)
    exact_zeta = sp.tan(2 * sp.atan(half)).expand(trig=True)
    printed_zeta, corrected_zeta = half + half, (half + half) / (1 - half * half)
    if (
        printed.holds is not False
        or not fixed.holds
        or exact_zeta != corrected_zeta
        or printed_zeta == exact_zeta
    ):
        raise AuditInconsistency("(97) check inconsistent")
    return Outcome(
        ERRATUM,
        f"exact: for zeta1 = zeta2 = (1/2) u (two rotations by 2 atan(1/2) about u) the "
        f"composition has zeta3 = tan(2 atan(1/2)) u = {exact_zeta} u, while (97) gives "
        f"{printed_zeta} u. Numeric (phi, u of the first rotation of a random pair): as printed, "
        f"{printed.describe()}; corrected form "
        f"(from (53) with zeta = e/e0): {fixed.describe()}",
        r"\boldsymbol{\zeta}_3 = \frac{\boldsymbol{\zeta}_1 + \boldsymbol{\zeta}_2 - \boldsymbol"
        r"{\zeta}_1 \times \boldsymbol{\zeta}_2}{1 - \boldsymbol{\zeta}_1 \cdot \boldsymbol{\zeta}_2}",
    )


def _eq98() -> Outcome:
    z_cross = ZETA * U_CROSS
    printed = (EYE + z_cross) / (1 + ZETA**2)
    corrected = 2 * (EYE + z_cross) / (1 + ZETA**2)
    cayley = sp.tan(PHI / 2)
    claim, fixed = Claim(printed, core_tensor("H"), p=cayley), Claim(corrected, core_tensor("H"), p=cayley)
    holds, verdict, numeric = claim.settle("98")
    fixed_holds, fixed_verdict, fixed_numeric = fixed.settle("98:corrected")
    functions = [subject("p = tan(phi/2)", cayley)]
    path = trajectory_sweep("98", tensor_at(printed), functions=functions)
    fixed_path = trajectory_sweep("98:corrected", tensor_at(corrected), functions=functions)
    if holds or path.holds is not False or not fixed_holds or not fixed_path.holds:
        raise AuditInconsistency("(98) check inconsistent")
    return Outcome(
        ERRATUM,
        f"H for p = zeta = tan(phi/2) (core, eq 22) against Y as printed: "
        f"{evidence(verdict, numeric, claim)}; {describe(path, 'omega = Y zeta_dot')} "
        "(Y is half of H: at zeta = 0, H = 2 I since kappa = 1/2, and mu = 2/(1 + zeta^2) stated "
        f"right after it is the axial eigenvalue of H, not of Y). Corrected form: "
        f"{evidence(fixed_verdict, fixed_numeric, fixed)}; {describe(fixed_path, 'omega = Y zeta_dot')}",
        r"\mathbf{Y} := \operatorname{dcay}(\boldsymbol{\zeta} \times) = \frac{2}{1 + \zeta^2} "
        r"\left( \mathbf{I} + (\boldsymbol{\zeta} \times) \right)",
    )


def _after98() -> Outcome:
    cayley = sp.tan(PHI / 2)
    kappa = validate(cayley).kappa
    results = [
        settle("after98:mu", Claim(MU, 2 / (1 + ZETA**2), p=cayley)),
        settle("after98:nu", Claim(NU, sp.sqrt(2 * MU), p=cayley)),
        settle("after98:eps", Claim(EPS, sp.Integer(2), p=cayley)),
    ]
    if kappa != sp.Rational(1, 2) or any(r.status != HOLDS for r in results):
        raise AuditInconsistency("statement after (98)")
    return Outcome(
        HOLDS,
        f"p = tan(phi/2): kappa = {kappa} (exact series); mu = 2/(1 + zeta^2), "
        "nu = sqrt(2 mu) (for |phi| < pi, where cos(phi/2) > 0), eps = 2: "
        + "; ".join(r.evidence for r in results),
    )


def _after99() -> Outcome:
    worst = mpmath.mpf(0)
    with precision():
        r = rng("99")
        for m in ORDERS:
            for _ in range(3):
                a = skew(mpmath.mpf(r.uniform(0.1, 3)) * random_axis(r))
                c = (mpmath.eye(3) + a) ** m * mpmath.inverse(mpmath.eye(3) - a) ** m
                worst = max(worst, relative(c * c.T - mpmath.eye(3), c), abs(mpmath.det(c) - 1))
    if worst > TOLERANCE:
        raise AuditInconsistency(f"cay_(m) not in SO(3): {fmt(worst)}")
    return Outcome(
        HOLDS,
        "numeric: cay_(m)(A) C^T C = I and det = 1 for random skew A (|a| < 3), m = 1..6, "
        "3 each (residual < 1e-45)",
    )


def _orders(label: str, lhs: Any, rhs: Any, bound: float = 3.0) -> Outcome:
    for m in ORDERS:
        holds, _, numeric = settle_dual(
            f"{label}:{m}",
            lambda o, phi, u, m=m: lhs(o, phi, u, m),
            lambda o, phi, u, m=m: rhs(o, phi, u, m),
            bound,
        )
        if not holds:
            raise AuditInconsistency(f"({label}) fails for m = {m}: {numeric.describe()}")
    return Outcome(
        HOLDS,
        "m = 1..6: symbolic (u = e1, residual = 0) and numeric (relative residual < 1e-45 "
        "at 4 random points each)",
    )


def _both_orders(label: str, product: Any) -> Outcome:
    """Both factor orders of (96) equal R (symbolic at u = e₁ and numeric)."""
    for order in (0, 1):
        holds, _, numeric = settle_dual(
            f"{label}:{order}", lambda o, phi, u, k=order: product(o, phi, u, k), _r
        )
        if not holds:
            raise AuditInconsistency(f"({label}) fails: {numeric.describe()}")
    return Outcome(
        HOLDS,
        "both orders: symbolic (u = e1, residual = 0) and numeric (relative residual < 1e-45 "
        "at 4 random points each); (1/e0) e = tan(phi/2) u = zeta",
    )


def _root(o: Any, phi: Any, u: Any, m: int) -> Any:
    k = o.skew(u)
    return o.eye() + o.sin(phi / m) * k + (1 - o.cos(phi / m)) * k * k


def _eq101() -> Outcome:
    for m in ORDERS:
        entry = family_member("cayley", m)
        tangent = family_member("tangent", 2 * m).expression
        if (
            validate(entry.expression).kappa != sp.Rational(1, 2 * m)
            or sp.simplify(2 * m * entry.expression - tangent) != 0
        ):
            raise AuditInconsistency(f"cayley m = {m}")
    outcome = _orders(
        "101", lambda o, phi, u, m: _cay(o, _z(o, phi, u, m), m), lambda o, phi, u, m: _r(o, phi, u)
    )
    return Outcome(
        HOLDS,
        "with zeta_(m) = tan(phi/(2m)) u, (100) holds (" + outcome.evidence + "); 2m zeta_(m) "
        "is the tangent member m' = 2m and kappa = 1/(2m) (exact series), as stated after it",
    )


CHECKS = [
    Check(
        "92",
        r"\mathbf{R} = \operatorname{cay}(\boldsymbol{\zeta} \times) := \left(\mathbf{I} + (\boldsymbol"
        r"{\zeta} \times)\right) \left(\mathbf{I} + (\boldsymbol{\zeta} \times)\right)^{-T} \equiv \left("
        r"\mathbf{I} + (\boldsymbol{\zeta} \times)\right)^{-T} \left(\mathbf{I} + (\boldsymbol{\zeta} "
        r"\times)\right)",
        "symbolic + numeric",
        _eq92,
    ),
    Check(
        "93",
        r"\boldsymbol{\zeta} = \tan \frac{\varphi}{2} \, \mathbf{u}",
        "symbolic + numeric",
        lambda: dual_outcome(
            "93",
            lambda o, phi, u: _cay(o, _z(o, phi, u)),
            _r,
            note="cay(zeta x) of (92) with this zeta is R of eq (1)",
        ),
    ),
    Check(
        "94",
        r"\mathbf{R} = \mathbf{I} + \frac{1}{1+\zeta^2} \left( \mathbf{I} + (\boldsymbol{\zeta} "
        r"\times) \right) (\boldsymbol{\zeta} \times)",
        "symbolic + numeric",
        lambda: dual_outcome(
            "94",
            _eq94_printed,
            _r,
            corrected=(
                r"\mathbf{R} = \mathbf{I} + \frac{2}{1+\zeta^2} \left( \mathbf{I} + "
                r"(\boldsymbol{\zeta} \times) \right) (\boldsymbol{\zeta} \times)",
                _eq94_corrected,
            ),
        ),
    ),
    Check(
        "text after (94): average",
        r"(\mathbf{I} + (\boldsymbol{\zeta} \times))^{-T} = (\mathbf{I} + "
        r"\mathbf{R})/2",
        "symbolic + numeric",
        lambda: dual_outcome(
            "after94",
            lambda o, phi, u: o.inverse((o.eye() + _z(o, phi, u)).T),
            lambda o, phi, u: (o.eye() + _r(o, phi, u)) / 2,
        ),
    ),
    Check(
        "95",
        r"\mathbf{R} = \left(\mathbf{I} + \frac{\varepsilon}{2} \left(\mathbf{p} \times\right)\right) "
        r"\left(\mathbf{I} + \frac{\varepsilon}{2} \left(\mathbf{p} \times\right)\right)^{-T} = \dots",
        "symbolic + numeric",
        _eq95,
    ),
    Check(
        "96",
        r"\mathbf{R} = \left(\mathbf{I} + \frac{1}{e_0} \left(\mathbf{e}\times\right)\right) \left("
        r"\mathbf{I} + \frac{1}{e_0} \left(\mathbf{e}\times\right)\right)^{-T} = \dots",
        "symbolic + numeric",
        lambda: _both_orders("96", _eq96),
    ),
    Check(
        "97",
        r"\boldsymbol{\zeta}_3 = \boldsymbol{\zeta}_1 + \boldsymbol{\zeta}_2 - \boldsymbol{\zeta}_1 "
        r"\times \boldsymbol{\zeta}_2",
        "exact + numeric",
        _eq97,
    ),
    Check(
        "98",
        r"\mathbf{Y} := \operatorname{dcay}(\boldsymbol{\zeta} \times) = \frac{1}{1 + \zeta^2} \left( "
        r"\mathbf{I} + (\boldsymbol{\zeta} \times) \right)",
        "symbolic + numeric + trajectory",
        _eq98,
    ),
    Check(
        "text after (98): mu, nu, eps",
        r"\mu = 2/(1 + \zeta^2), \nu = \sqrt{2\mu}, \text{ and } "
        r"\varepsilon = 2",
        "symbolic + numeric",
        _after98,
    ),
    Check(
        "99",
        r"\operatorname{cay}_{(m)}(\mathbf{A}) := (\mathbf{I} + \mathbf{A})^m (\mathbf{I} - "
        r"\mathbf{A})^{-m}",
        "definition",
        lambda: definition("defines the m-th order Cayley transform; used by (100)-(102)"),
    ),
    Check(
        "text after (99): codomain",
        r"\text{the domain and codomain of } \operatorname{cay}_{(m)} \text{ are }"
        r" \operatorname{so}(\mathbb{E}^3) \text{ and } \operatorname{SO}(\mathbb{E}^3)",
        "numeric",
        _after99,
    ),
    Check(
        "100",
        r"\mathbf{R} = \operatorname{cay}_{(m)}(\boldsymbol{\zeta}_{(m)} \times)",
        "symbolic + numeric",
        lambda: _orders(
            "100", lambda o, phi, u, m: _cay(o, _z(o, phi, u, m), m), lambda o, phi, u, m: _r(o, phi, u)
        ),
    ),
    Check(
        "101",
        r"\boldsymbol{\zeta}_{(m)} = \tan \frac{\varphi}{2m} \, \mathbf{u}",
        "symbolic + numeric",
        _eq101,
    ),
    Check(
        "102",
        r"\mathbf{G}_{(m)} = \operatorname{cay}(\boldsymbol{\zeta}_{(m)} \times)",
        "symbolic + numeric",
        lambda: _orders("102", lambda o, phi, u, m: _cay(o, _z(o, phi, u, m)), _root),
    ),
    Check(
        "text after (102): powers",
        r"cay_{(m)}(\mathbf{A}) = cay(\mathbf{A})^m",
        "symbolic + numeric",
        lambda: _orders(
            "after102",
            lambda o, phi, u, m: _cay(o, _z(o, phi, u), m),
            lambda o, phi, u, m: _cay(o, _z(o, phi, u)) ** m,
        ),
    ),
]
