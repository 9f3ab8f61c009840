"""Section 3.1, general formulation, eqs (20)–(29): the tangent tensors H and H⁻¹.

Proved for a generic p against the symbolic core (H from eq 10, H⁻¹ by inversion), checked at 50
digits over the generating functions of :mod:`symrot.audit.subjects` and against random
trajectories (:mod:`symrot.audit.kinematics`). Eqs (11)–(19) are in :mod:`symrot.audit.section31`.
"""

from __future__ import annotations

import functools
from collections.abc import Callable

import mpmath
import sympy as sp

from symrot.audit.claims import Claim, conclude, evidence, sweep_function
from symrot.audit.kinematics import describe, tensor_at, trajectory_sweep
from symrot.audit.numeric import (
    TOLERANCE,
    Trajectory,
    Vector,
    derivative,
    fmt,
    precision,
    relative,
    skew,
)
from symrot.audit.proof import DP, EPS, EYE, MU, NU, P, Verdict, at_e1, core_tensor, identity
from symrot.audit.records import ERRATUM, HOLDS, AuditInconsistency, Check, Outcome, definition
from symrot.audit.section31 import PX, canonical_matrix, canonical_outcome, series_limits
from symrot.audit.subjects import Subject, scope, subjects
from symrot.core.parsing import PHI

H22 = MU * EYE + NU**2 / 2 * PX + (MU - NU**2 / EPS) / P**2 * PX**2
H_INVERSE26 = EYE / MU - PX / 2 - (1 / EPS - 1 / MU) / P**2 * PX**2
HALF = PHI / 2
H23 = (
    canonical_matrix(MU, (MU - NU**2 / EPS) / P**2, -P * NU**2 / 2, P * NU**2 / 2),
    NU * canonical_matrix(MU / NU, sp.cos(HALF), -sp.sin(HALF), sp.sin(HALF)),
)
H23_CORRECTED = canonical_matrix(MU, NU**2 / EPS, -P * NU**2 / 2, P * NU**2 / 2)
H_INVERSE27 = (
    canonical_matrix(1 / MU, 1 / EPS, P / 2, -P / 2),
    P / 2 * canonical_matrix(2 * DP / P, 1 / sp.tan(HALF), 1, -1),
)


def _tangent(label: str, printed: sp.Matrix, core_name: str, inverse: bool) -> Outcome:
    """Printed H (22) or H⁻¹ (26) against the core and against trajectories."""
    holds, verdict, numeric = Claim(printed, core_tensor(core_name)).settle(label)
    path = trajectory_sweep(label, tensor_at(printed), inverse=inverse)
    if path.holds is not holds:
        raise AuditInconsistency(
            f"{label}: the core and the trajectories disagree ({describe(path, 'printed tensor')})"
        )
    relation = "p_dot = H^-1 omega" if inverse else "omega = H p_dot"
    text = (
        f"against the core: {evidence(verdict, numeric, Claim(printed, printed))}; {describe(path, relation)}"
    )
    if not holds:
        raise AuditInconsistency(f"{label} fails: {text}")
    return Outcome(HOLDS, text)


def _composed(
    outer: Callable[[mpmath.mpf], mpmath.mpf], inner: Callable[[mpmath.mpf], mpmath.mpf], t: mpmath.mpf
) -> mpmath.mpf:
    return outer(inner(t))


def _velocity_text(printed: bool) -> Outcome:
    """Before (21): ω = μ ṗ u + p((ν²/ε) I + (ν²/2)(p×)) [u̇ missing]; φ̇ u = μ (I + (u×)²) ṗ."""
    worst = mpmath.mpf(0)
    with precision():
        for fn in subjects():
            path = Trajectory(f"velocity:{fn.name}", bound=fn.bound)
            phi, u = path.phi(path.t), path.u(path.t)
            s = fn.scalars(phi)
            omega, p_vec_dot = path.spin(), derivative(path.parameter_vector(fn.p), path.t)
            if printed:
                p_dot = derivative(functools.partial(_composed, fn.p, path.phi), path.t)
                u_dot = derivative(path.u, path.t)
                bracket = s["nu"] ** 2 / s["eps"] * mpmath.eye(3) + s["nu"] ** 2 / 2 * skew(s["p"] * u)
                value = s["mu"] * p_dot * u + s["p"] * bracket * u_dot  # with u_dot appended
                worst = max(worst, relative(value - omega, omega))
            else:
                phi_dot_u = derivative(path.phi, path.t) * u
                value = s["mu"] * (mpmath.eye(3) + skew(u) ** 2) * p_vec_dot
                worst = max(worst, relative(value - phi_dot_u, phi_dot_u))
    if worst > TOLERANCE:
        raise AuditInconsistency(f"velocity text: residual {fmt(worst)}")
    count = len(subjects())
    if not printed:
        return Outcome(
            HOLDS, f"trajectories: relative residual < 1e-45 on {count} random trajectories [{scope()}]"
        )
    return Outcome(
        ERRATUM,
        "as printed the right-hand side is mu p_dot u (a vector) plus "
        "p ((nu^2/eps) I + (nu^2/2)(p x)), a second-order tensor: the sum has no meaning. "
        "Applied to u_dot (as eq 10 requires, sin(phi) = p nu^2/eps, 1 - cos(phi) = "
        "p^2 nu^2/2) it equals omega = axial(R_dot R^T): relative residual < 1e-45 on "
        f"{count} random trajectories [{scope()}]",
        r"\boldsymbol{\omega} = \mu \dot{p} \mathbf{u} + p \left( (\nu^2 / \varepsilon) "
        r"\mathbf{I} + (\nu^2 / 2) (\mathbf{p} \times) \right) \dot{\mathbf{u}}",
    )


def _determinant() -> Outcome:
    h = core_tensor("H")
    verdict = identity(at_e1(h).det(), MU * NU**2)
    tensor = tensor_at(h)

    def evaluate(fn: Subject | None, phi: mpmath.mpf, u: Vector) -> tuple[object, object]:
        assert fn is not None
        det = mpmath.det(tensor(fn, phi, u))
        s = fn.scalars(phi)
        return det - s["mu"] * s["nu"] ** 2, det

    numeric = sweep_function("24", evaluate, subjects())
    if not conclude("24", verdict, numeric):
        raise AuditInconsistency("det H != mu nu^2")
    return Outcome(HOLDS, "det of the core's H: " + evidence(verdict, numeric, Claim(h, h)))


def _product_identity(
    label: str, symbolic_pairs: list[tuple[sp.Matrix, sp.Matrix]], numeric_pairs: list[tuple[str, str]]
) -> Outcome:
    """(28), (29): identities between the core's R and H, symbolic at u = e₁ and numeric."""
    verdicts = [identity(lhs, rhs) for lhs, rhs in symbolic_pairs]
    tensors = {name: tensor_at(core_tensor(name)) for name in ("R", "H")}

    def value(expression: str, fn: Subject, phi: mpmath.mpf, u: Vector) -> mpmath.matrix:
        r, h = tensors["R"](fn, phi, u), tensors["H"](fn, phi, u)
        px = skew(fn.p(phi) * u)
        table = {
            "R": r,
            "R-I": r - mpmath.eye(3),
            "HH-T": h * mpmath.inverse(h).T,
            "H-TH": mpmath.inverse(h).T * h,
            "pxH": px * h,
            "Hpx": h * px,
        }
        return table[expression]

    def evaluate(fn: Subject | None, phi: mpmath.mpf, u: Vector) -> tuple[object, object]:
        assert fn is not None
        worst, reference = mpmath.mpf(0), value(numeric_pairs[0][0], fn, phi, u)
        for lhs, rhs in numeric_pairs:
            worst = max(worst, max(abs(x) for x in value(lhs, fn, phi, u) - value(rhs, fn, phi, u)))
        return worst, reference

    numeric = sweep_function(label, evaluate, subjects())
    symbolic = Verdict(
        all(v.holds for v in verdicts) if all(v.holds is not None for v in verdicts) else None, sp.zeros(1)
    )
    if not conclude(label, symbolic, numeric):
        raise AuditInconsistency(f"{label} fails: {numeric.describe()}")
    return Outcome(
        HOLDS,
        f"symbolic: residual = 0 for each equality (core R, H; u = e1); {numeric.describe()} [{scope()}]",
    )


def _eigen_h() -> Outcome:
    """After (23): λ₁(H) = μ, λ₂,₃ = ν²(1/ε ± i p/2) = ν(cos(φ/2) ± i sin(φ/2)); H u = μ u."""
    h = at_e1(core_tensor("H"))
    real, imag = h[1, 1], h[2, 1]  # (a − c) ± i b in a canonical basis
    pairs = [
        (h[0, 0], MU),
        (real, NU**2 / EPS),
        (imag, NU**2 * P / 2),
        (NU**2 / EPS, NU * sp.cos(HALF)),
        (NU**2 * P / 2, NU * sp.sin(HALF)),
    ]
    for lhs, rhs in pairs:
        holds = Claim(lhs, rhs).settle("eigen-H")[0]
        if not holds:
            raise AuditInconsistency(f"eigenvalues of H: {lhs} != {rhs}")
    return Outcome(
        HOLDS,
        "real and imaginary parts of the eigenvalues of the core's H in a canonical "
        "basis equal the printed ones (symbolic, generic p; numeric < 1e-45); H u = mu u is "
        f"its first column [{scope()}]",
    )


def _mu_limit() -> Outcome:
    h = core_tensor("H")
    return series_limits(
        "after (22)",
        {
            "mu": (MU, 1),
            "H_0": (at_e1(h)[0, 0], 1),
            "(H - I) canonical (2,2)": (at_e1(h)[1, 1] - 1, 0),
            "(H - I) canonical (3,2)": (at_e1(h)[2, 1], 0),
        },
    )


CHECKS = [
    Check(
        "20",
        r"\boldsymbol{\omega} = \mathbf{H}(\mathbf{p})\,\dot{\mathbf{p}}",
        "definition",
        lambda: definition(
            "defines H as the tensor mapping p_dot to omega; (22), (25), (26) are "
            "checked against omega = axial(R_dot R^T) on trajectories"
        ),
    ),
    Check(
        "text before (21): omega",
        r"\boldsymbol{\omega} = \mu \dot{p} \mathbf{u} + p \left( (\nu^2 / \varepsilon) \mathbf{I} + "
        r"(\nu^2 / 2) (\mathbf{p} \times) \right)",
        "numeric trajectory",
        lambda: _velocity_text(printed=True),
    ),
    Check(
        "text before (21): phi_dot u",
        r"\dot{\varphi} \mathbf{u} = \mu \left( \mathbf{I} + (\mathbf{u} \times)^2 \right) "
        r"\dot{\mathbf{p}}",
        "numeric trajectory",
        lambda: _velocity_text(printed=False),
    ),
    Check(
        "21",
        r"\mu(\varphi) := \frac{1}{p'(\varphi)}",
        "definition",
        lambda: definition(
            "defines mu; used by (22)-(27), (35), (37), (39), (83), (85) and the "
            "statements after (75) and (98)"
        ),
    ),
    Check(
        "22",
        r"\mathbf{H} = \mu \,\mathbf{I} + \frac{\nu^2}{2} \,(\mathbf{p} \times) + \frac{1}{p^2} "
        r"\,\left(\mu - \frac{\nu^2}{\varepsilon}\right) \,(\mathbf{p} \times)^2",
        "symbolic + numeric + trajectory",
        lambda: _tangent("22", H22, "H", inverse=False),
    ),
    Check(
        "text after (22): limits",
        r"\lim_{\varphi \to 0} \mu = 1, \lim_{\varphi \to 0} \mathbf{H} = "
        r"\mathbf{I}",
        "exact series",
        _mu_limit,
    ),
    Check(
        "23",
        r"[\mathbf{H}]_{\mathcal{B}} = \begin{bmatrix} \mu & 0 & 0\\ 0 & (\mu - \nu^2/\varepsilon)"
        r"/p^2 & -p\nu^2/2\\ 0 & p\nu^2/2 & (\mu - \nu^2/\varepsilon)/p^2 \end{bmatrix} = \nu "
        r"\begin{bmatrix} \mu/\nu & 0 & 0\\ 0 & \cos(\varphi/2) & -\sin(\varphi/2)\\ 0 & \sin(\varphi/2)"
        r" & \cos(\varphi/2) \end{bmatrix}",
        "symbolic + numeric",
        lambda: canonical_outcome(
            "23",
            "H",
            H23,
            H23_CORRECTED,
            r"[\mathbf{H}]_{\mathcal{B}} = \begin{bmatrix} \mu & 0 & 0\\ 0 & "
            r"\nu^2/\varepsilon & -p\nu^2/2\\ 0 & p\nu^2/2 & \nu^2/\varepsilon "
            r"\end{bmatrix} = \nu \begin{bmatrix} \mu/\nu & 0 & 0\\ 0 & \cos(\varphi/2) "
            r"& -\sin(\varphi/2)\\ 0 & \sin(\varphi/2) & \cos(\varphi/2) \end{bmatrix}",
            " (the printed diagonal entries of the first form are the (p x)^2 coefficient of "
            "(22); in a canonical basis they are nu^2/eps = sin(phi)/p)",
        ),
    ),
    Check(
        "text after (23): eigenvalues of H",
        r"\lambda_{2,3}(\mathbf{H}) = \nu^2 (1/\varepsilon \pm i p/2) = \nu (\cos(\varphi/2) \pm i "
        r"\sin(\varphi/2))",
        "symbolic + numeric",
        _eigen_h,
    ),
    Check("24", r"\det(\mathbf{H}) = \mu \,\nu^2", "symbolic + numeric", _determinant),
    Check(
        "25",
        r"\dot{\mathbf{p}} = \mathbf{H}(\mathbf{p})^{-1}\boldsymbol{\omega}",
        "numeric trajectory",
        lambda: _tangent("25", core_tensor("H_inverse"), "H_inverse", inverse=True),
    ),
    Check(
        "26",
        r"\mathbf{H}^{-1} = \frac{1}{\mu} \mathbf{I} - \frac{1}{2} \left( \mathbf{p} \times "
        r"\right) - \frac{1}{p^2} \left( \frac{1}{\varepsilon} - \frac{1}{\mu} \right) \left( "
        r"\mathbf{p} \times \right)^2",
        "symbolic + numeric + trajectory",
        lambda: _tangent("26", H_INVERSE26, "H_inverse", inverse=True),
    ),
    Check(
        "27",
        r"[\mathbf{H}^{-1}]_{\mathcal{B}} = \begin{bmatrix} 1/\mu & 0 & 0\\ 0 & 1/\varepsilon & "
        r"p/2\\ 0 & -p/2 & 1/\varepsilon \end{bmatrix} = \frac{p}{2} \begin{bmatrix} 2p'/p & 0 & 0\\ "
        r"0 & 1/\tan(\varphi/2) & 1\\ 0 & -1 & 1/\tan(\varphi/2) \end{bmatrix}",
        "symbolic + numeric",
        lambda: canonical_outcome("27", "H_inverse", H_INVERSE27),
    ),
    Check(
        "28",
        r"\mathbf{R} = \mathbf{H} \, \mathbf{H}^{-T} = \mathbf{H}^{-T} \, \mathbf{H}",
        "symbolic + numeric",
        lambda: _product_identity(
            "28",
            [
                (at_e1(core_tensor("R")), at_e1(core_tensor("H")) * at_e1(core_tensor("H")).inv().T),
                (at_e1(core_tensor("R")), at_e1(core_tensor("H")).inv().T * at_e1(core_tensor("H"))),
            ],
            [("R", "HH-T"), ("R", "H-TH")],
        ),
    ),
    Check(
        "29",
        r"\mathbf{R} - \mathbf{I} = (\mathbf{p} \times)\mathbf{H} = \mathbf{H}(\mathbf{p} \times)",
        "symbolic + numeric",
        lambda: _product_identity(
            "29",
            [
                (at_e1(core_tensor("R")) - EYE, at_e1(PX) * at_e1(core_tensor("H"))),
                (at_e1(core_tensor("R")) - EYE, at_e1(core_tensor("H")) * at_e1(PX)),
            ],
            [("R-I", "pxH"), ("R-I", "Hpx")],
        ),
    ),
]
