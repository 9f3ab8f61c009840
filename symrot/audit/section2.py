"""Section 2, Euler's theorem: eqs (1)–(10) and the eigenvalue statement after (6).

Eq (1) is transcribed once (``R_EQ1``); the others are compared with it symbolically (u = e₁,
see :mod:`symrot.audit.proof`) and at random angles and axes. Composition (7), (8) and the
time derivatives (9), (10) are numeric: random rotation pairs and random smooth trajectories.
"""

from __future__ import annotations

import mpmath
import sympy as sp

from symrot.audit.claims import Claim, settle
from symrot.audit.numeric import (
    REFUTED,
    TOLERANCE,
    Trajectory,
    cross,
    derivative,
    dot,
    fmt,
    fmt_vector,
    precision,
    random_angle,
    random_axis,
    relative,
    rng,
    rotation,
    skew,
)
from symrot.audit.proof import EYE, U_CROSS, U_VECTOR, at_e1, is_zero, matrix_is_zero
from symrot.audit.records import ERRATUM, HOLDS, AuditInconsistency, Check, Outcome
from symrot.core.parsing import PHI

R_EQ1 = EYE + sp.sin(PHI) * U_CROSS + (1 - sp.cos(PHI)) * U_CROSS**2
"""Eq (1) as printed: R = I + sin φ (u×) + (1 − cos φ)(u×)²."""
SAMPLES = 4


def _free(lhs: sp.Expr | sp.Matrix, rhs: sp.Expr | sp.Matrix) -> Claim:
    return Claim(lhs, rhs, any_p=False)


def axial_of(m: sp.Matrix) -> sp.Matrix:
    """axial(A): the vector a with (a×) = skw(A)."""
    return sp.Matrix([m[2, 1] - m[1, 2], m[0, 2] - m[2, 0], m[1, 0] - m[0, 1]]) / 2


def _eq1() -> Outcome:
    """R of eq (1) is proper orthogonal and equals exp(φ (u×)), the rotation by φ about u."""
    orthogonal = matrix_is_zero(at_e1(R_EQ1.T * R_EQ1 - EYE))
    determinant = is_zero(at_e1(R_EQ1).det() - 1)
    worst = mpmath.mpf(0)
    with precision():
        r = rng("eq1")
        for _ in range(SAMPLES):
            phi, u = random_angle(r, 6.0), random_axis(r)
            exact = mpmath.expm(phi * skew(u))
            worst = max(worst, relative(rotation(phi, u) - exact, exact))
    if not (orthogonal and determinant) or worst > TOLERANCE:
        raise AuditInconsistency(f"eq (1) is not the rotation: residual {fmt(worst)}")
    return Outcome(
        HOLDS,
        "symbolic: R^T R = I and det R = 1 (u = e1); numeric: R = expm(phi (u x)) "
        f"(relative residual < 1e-45) at {SAMPLES} random points with |phi| < 6",
    )


def _eq7_8(vector_part: bool) -> Outcome:
    """(7), (8): the half-angle quaternion of R₃ = R₂R₁ (sign fixed by (7) and (8) together)."""
    worst = mpmath.mpf(0)
    with precision():
        r = rng("eq7-8")
        for _ in range(SAMPLES):
            phi1, u1, phi2, u2 = random_angle(r, 3.1), random_axis(r), random_angle(r, 3.1), random_axis(r)
            r3 = rotation(phi2, u2) * rotation(phi1, u1)
            c1, s1 = mpmath.cos(phi1 / 2), mpmath.sin(phi1 / 2)
            c2, s2 = mpmath.cos(phi2 / 2), mpmath.sin(phi2 / 2)
            cos3 = c1 * c2 - s1 * s2 * dot(u1, u2)  # (7) as printed
            sin3_u3 = c1 * s2 * u2 + c2 * s1 * u1 - s1 * s2 * cross(u1, u2)  # (8) as printed
            if not vector_part:  # 4 cos²(φ₃/2) − 1 = tr R₃ fixes cos(φ₃/2) up to sign
                worst = max(worst, abs(4 * cos3**2 - 1 - (r3[0, 0] + r3[1, 1] + r3[2, 2])))
                continue
            norm3 = mpmath.norm(sin3_u3)
            rebuilt = rotation(2 * mpmath.atan2(norm3, cos3), sin3_u3 / norm3)
            worst = max(worst, relative(rebuilt - r3, r3), abs(cos3**2 + norm3**2 - 1))
    if worst > TOLERANCE:
        raise AuditInconsistency(f"composition residual {fmt(worst)}")
    what = (
        "the rotation rebuilt from (cos(phi3/2), sin(phi3/2) u3) of (7), (8) equals R2 R1"
        if vector_part
        else "4 cos^2(phi3/2) - 1 = tr(R2 R1)"
    )
    return Outcome(
        HOLDS,
        f"numeric: {what}, relative residual < 1e-45 at {SAMPLES} random pairs "
        "(|phi1|, |phi2| < 3.1, random axes)",
    )


def _eigenvalues() -> Outcome:
    """Text after (6): λ₂,₃(R) = exp(±iφ) = cos φ ± sin φ (the i is missing)."""
    lam = sp.Symbol("lambda")
    charpoly = sp.expand((lam * EYE - at_e1(R_EQ1)).det())
    printed = [sp.cos(PHI) + sign * sp.sin(PHI) for sign in (1, -1)]
    corrected = [sp.cos(PHI) + sign * sp.I * sp.sin(PHI) for sign in (1, -1)]
    exponential = [sp.exp(sign * sp.I * PHI) for sign in (1, -1)]
    corrected_ok = all(is_zero(sp.expand(charpoly.subs(lam, v))) for v in corrected)
    same = all(is_zero(sp.expand(e.rewrite(sp.cos)) - c) for e, c in zip(exponential, corrected, strict=True))
    c, s = sp.symbols("c s")
    in_cs = sp.expand(charpoly.subs(lam, printed[0]).subs({sp.cos(PHI): c, sp.sin(PHI): s}))
    remainder = sp.reduced(in_cs, [c**2 + s**2 - 1], c, s)[1]
    residual = sp.factor(remainder).subs({c: sp.cos(PHI), s: sp.sin(PHI)})
    if not (corrected_ok and same) or is_zero(residual):
        raise AuditInconsistency("eigenvalue check inconsistent")
    with precision():
        phi = mpmath.mpf(1)
        values = mpmath.eig(rotation(phi, random_axis(rng("eigen"))))[0]
        planar = max(values, key=lambda v: mpmath.im(v))
        claimed = mpmath.cos(phi) + mpmath.sin(phi)
        distance = min(abs(v - claimed) for v in values)
    if distance < REFUTED:
        raise AuditInconsistency("cos 1 + sin 1 is an eigenvalue?")
    return Outcome(
        ERRATUM,
        "the characteristic polynomial of R, (lambda - 1)(lambda^2 - 2 cos(phi) "
        f"lambda + 1), at lambda = cos(phi) + sin(phi) equals {residual}, zero only "
        f"where sin(phi) = 0 or cos(phi) + sin(phi) = 1; at phi = 1 the eigenvalues are 1, "
        f"{fmt(mpmath.re(planar))} "
        f"± {fmt(mpmath.im(planar))} i, while cos 1 + sin 1 = {fmt(claimed)}. "
        "cos(phi) ± i sin(phi) = exp(±i phi) are roots (symbolic)",
        r"\lambda_{2,3}(\mathbf{R}) = \exp(\pm i\varphi) = \cos\varphi \pm i \sin\varphi",
    )


def _eq9() -> Outcome:
    """(9) printed R = ω × R; with ω := axial(Ṙ Rᵀ) the statement must be Ṙ = (ω×) R."""
    printed_best, corrected_worst, where = mpmath.mpf("inf"), mpmath.mpf(0), ""
    with precision():
        for k in range(SAMPLES):
            path = Trajectory(f"eq9:{k}")
            rot = path.rotation(path.t)
            rot_dot = derivative(path.rotation, path.t)
            spin = skew(path.spin())
            printed = relative(rot - spin * rot, rot)
            if printed < printed_best:
                printed_best, where = printed, f"phi = {fmt(path.phi0, 15)}, u = {fmt_vector(path.u(path.t))}"
            corrected_worst = max(corrected_worst, relative(rot_dot - spin * rot, rot_dot))
    if corrected_worst > TOLERANCE or printed_best < REFUTED:
        raise AuditInconsistency("eq (9) check inconsistent")
    return Outcome(
        ERRATUM,
        "numeric, random trajectories (phi(t), u(t)), omega = axial(R_dot R^T) by "
        f"mpmath.diff: as printed, R - (omega x) R != 0 (smallest relative residual "
        f"{fmt(printed_best)} at {where}); corrected form: relative residual < 1e-45 on "
        f"{SAMPLES} trajectories (R R^T = I makes R_dot R^T skew)",
        r"\dot{\mathbf{R}} = \boldsymbol{\omega} \times \mathbf{R}, \text{ i.e. } "
        r"\dot{\mathbf{R}} = (\boldsymbol{\omega}\times)\,\mathbf{R}",
    )


def _eq10() -> Outcome:
    """(10) ω = φ̇ u + (sin φ I + (1 − cos φ)(u×)) u̇, against ω = axial(Ṙ Rᵀ)."""
    worst = mpmath.mpf(0)
    with precision():
        for k in range(SAMPLES):
            path = Trajectory(f"eq10:{k}")
            phi, u = path.phi(path.t), path.u(path.t)
            phi_dot, u_dot = derivative(path.phi, path.t), derivative(path.u, path.t)
            printed = (
                phi_dot * u + (mpmath.sin(phi) * mpmath.eye(3) + (1 - mpmath.cos(phi)) * skew(u)) * u_dot
            )
            omega = path.spin()
            worst = max(worst, relative(printed - omega, omega))
    if worst > TOLERANCE:
        raise AuditInconsistency(f"eq (10) residual {fmt(worst)}")
    return Outcome(
        HOLDS,
        "numeric: omega = axial(R_dot R^T) of eq (1) on random trajectories, "
        f"relative residual < 1e-45 on {SAMPLES} trajectories",
    )


U_OUTER = U_VECTOR * U_VECTOR.T

CHECKS = [
    Check(
        "1",
        r"\mathbf{R} = \mathbf{I} + \sin\varphi \left(\mathbf{u} \times\right) + (1 - \cos\varphi) "
        r"\left(\mathbf{u} \times\right)^2",
        "symbolic + numeric",
        _eq1,
    ),
    Check(
        "2",
        r"\operatorname{sym}(\mathbf{R}) = \cos \varphi \, \mathbf{I} + (1 - \cos \varphi) \, "
        r"(\mathbf{u} \otimes \mathbf{u})",
        "symbolic + numeric",
        lambda: settle("2", _free((R_EQ1 + R_EQ1.T) / 2, sp.cos(PHI) * EYE + (1 - sp.cos(PHI)) * U_OUTER)),
    ),
    Check(
        "3",
        r"\operatorname{skw}(\mathbf{R}) = \sin\varphi\left(\mathbf{u}\times\right)",
        "symbolic + numeric",
        lambda: settle("3", _free((R_EQ1 - R_EQ1.T) / 2, sp.sin(PHI) * U_CROSS)),
    ),
    Check(
        "4",
        r"\operatorname{tr}(\mathbf{R}) = 1 + 2\,\cos\varphi",
        "symbolic + numeric",
        lambda: settle("4", _free(R_EQ1.trace(), 1 + 2 * sp.cos(PHI))),
    ),
    Check(
        "5",
        r"\operatorname{axial}(\mathbf{R}) = \sin \varphi \, \mathbf{u}",
        "symbolic + numeric",
        lambda: settle("5", _free(axial_of(R_EQ1), sp.sin(PHI) * U_VECTOR)),
    ),
    Check(
        "6",
        r"\mathbf{R}\,\mathbf{u}=\mathbf{u}",
        "symbolic + numeric",
        lambda: settle("6", _free(R_EQ1 * U_VECTOR, U_VECTOR)),
    ),
    Check(
        "text after (6): eigenvalues",
        r"\lambda_{2,3}(\mathbf{R}) = \exp(\pm i\varphi) = \cos \varphi \pm \sin \varphi",
        "symbolic + numeric",
        _eigenvalues,
    ),
    Check(
        "7",
        r"\cos\frac{\varphi_3}{2} = \cos\frac{\varphi_1}{2}\,\cos\frac{\varphi_2}{2} - "
        r"\sin\frac{\varphi_1}{2}\,\sin\frac{\varphi_2}{2}\,\mathbf{u}_1\cdot\mathbf{u}_2",
        "numeric",
        lambda: _eq7_8(vector_part=False),
    ),
    Check(
        "8",
        r"\sin\frac{\varphi_3}{2}\mathbf{u}_3 = \cos\frac{\varphi_1}{2}\sin\frac{\varphi_2}{2}"
        r"\mathbf{u}_2 + \cos\frac{\varphi_2}{2}\sin\frac{\varphi_1}{2}\mathbf{u}_1 - "
        r"\sin\frac{\varphi_1}{2}\sin\frac{\varphi_2}{2}\mathbf{u}_1 \times \mathbf{u}_2",
        "numeric",
        lambda: _eq7_8(vector_part=True),
    ),
    Check("9", r"\mathbf{R} = \boldsymbol{\omega} \times \mathbf{R}", "numeric trajectory", _eq9),
    Check(
        "10",
        r"\boldsymbol{\omega} = \dot{\varphi} \, \mathbf{u} + \left(\sin\varphi \, \mathbf{I} + "
        r"(1 - \cos\varphi) \, (\mathbf{u} \times)\right) \dot{\mathbf{u}}",
        "numeric trajectory",
        _eq10,
    ),
]
