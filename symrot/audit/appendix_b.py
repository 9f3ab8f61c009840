"""Appendix B, rotation powers and roots: eqs (76)–(85).

G_(m) (76) is the rotation by φ/m; its spin γ_(m) (78) is computed from random trajectories, so the
printed γ_(m) (79), K (83) and K in Euler–Rodrigues parameters (85) are checked against an
independent numeric truth as well as against the core (K_(m) from eq 79).
"""

from __future__ import annotations

from typing import Any

import mpmath
import sympy as sp

from symrot.audit.claims import Claim, evidence, settle, settle_dual
from symrot.audit.kinematics import describe, tensor_at, trajectory_sweep
from symrot.audit.numeric import TOLERANCE, Trajectory, derivative, fmt, precision, relative, skew
from symrot.audit.proof import EPS, EYE, GENERIC_P, MU, NU, U_CROSS, P, core_tensor, generic
from symrot.audit.records import HOLDS, AuditInconsistency, Check, Outcome, definition
from symrot.audit.subjects import scope, subject
from symrot.core.derivation import root_tangent
from symrot.core.parsing import PHI

ORDERS = range(1, 7)
PX = P * U_CROSS
G81 = EYE + NU / 2 * PX + (1 - NU / EPS) / P**2 * PX**2
K83 = MU / 2 * EYE + (1 - NU / EPS) / P**2 * PX + (MU - NU) / 2 / P**2 * PX**2
E0 = sp.cos(PHI / 2)
E_CROSS = sp.sin(PHI / 2) * U_CROSS
G84 = EYE + E_CROSS + E_CROSS**2 / (1 + E0)
K85 = EYE / E0 + (EYE + E_CROSS / E0) * E_CROSS / (1 + E0)
TRAJECTORIES = 3


def _root(ops: Any, phi: Any, u: Any, m: int) -> Any:
    """(76): G_(m) = I + sin(φ/m)(u×) + (1 − cos(φ/m))(u×)²."""
    k = ops.skew(u)
    return ops.eye() + ops.sin(phi / m) * k + (1 - ops.cos(phi / m)) * k * k


def _eq77() -> Outcome:
    for m in ORDERS:
        holds, _, numeric = settle_dual(
            f"77:{m}",
            lambda o, phi, u, m=m: _root(o, phi, u, m) ** m,
            lambda o, phi, u: _root(o, phi, u, 1),
            bound=6.0,
        )
        if not holds:
            raise AuditInconsistency(f"G_(m)^m != R for m = {m}: {numeric.describe()}")
    return Outcome(
        HOLDS,
        "m = 1..6: symbolic (u = e1, residual = 0) and numeric (relative residual < 1e-45 at "
        "4 random points with |phi| < 6 each)",
    )


def _eq79() -> Outcome:
    worst = mpmath.mpf(0)
    with precision():
        for m in ORDERS:
            for k in range(TRAJECTORIES):
                path = Trajectory(f"79:{m}:{k}", bound=6.0)
                phi, u = path.phi(path.t), path.u(path.t)
                phi_dot, u_dot = derivative(path.phi, path.t), derivative(path.u, path.t)
                printed = (
                    phi_dot / m * u
                    + (mpmath.sin(phi / m) * mpmath.eye(3) + (1 - mpmath.cos(phi / m)) * skew(u)) * u_dot
                )
                gamma = path.spin(m)
                worst = max(worst, relative(printed - gamma, gamma))
    if worst > TOLERANCE:
        raise AuditInconsistency(f"(79) residual {fmt(worst)}")
    return Outcome(
        HOLDS,
        f"numeric: gamma_(m) = axial(G_dot G^T) of eq (76) on random trajectories, m = 1..6, "
        f"{TRAJECTORIES} trajectories each: relative residual < 1e-45",
    )


def _after80() -> Outcome:
    core_h = core_tensor("H")
    k1 = (
        generic(root_tangent(GENERIC_P, 1).a) * EYE
        + generic(root_tangent(GENERIC_P, 1).b) * U_CROSS
        + generic(root_tangent(GENERIC_P, 1).c) * U_CROSS**2
    )
    if (k1 - core_h).applyfunc(sp.simplify) != sp.zeros(3):
        raise AuditInconsistency("K_(1) != H in the core")
    notes = []
    for m in ORDERS[1:]:
        t = root_tangent(GENERIC_P, m)
        k_m = generic(t.a) * EYE + generic(t.b) * U_CROSS + generic(t.c) * U_CROSS**2
        path = trajectory_sweep(f"80:{m}", tensor_at(k_m), fraction=m)
        if not path.holds:
            raise AuditInconsistency(f"the core's K_({m}) fails: {describe(path, 'gamma = K p_dot')}")
        notes.append(str(m))
    return Outcome(
        HOLDS,
        "the core's K_(1) (eq 79 with m = 1) is its H (and gamma_(1) = omega by (79), (10)); "
        f"the core's K_(m) satisfies gamma_(m) = K_(m) p_dot on random trajectories for m = "
        f"{', '.join(notes)} (relative residual < 1e-45) [{scope()}]",
    )


def _eq83(label: str, printed: sp.Matrix, p: sp.Expr | None) -> Outcome:
    claim = Claim(printed, core_tensor("K"), p=p)
    holds, verdict, numeric = claim.settle(label)
    functions = [subject(f"p = {p}", p)] if p is not None else None
    path = trajectory_sweep(label, tensor_at(printed), fraction=2, functions=functions)
    if path.holds is not holds:
        raise AuditInconsistency(f"{label}: the core and the trajectories disagree")
    text = f"against the core's K: {evidence(verdict, numeric, claim)}; {describe(path, 'gamma = K p_dot')}"
    if not holds:
        raise AuditInconsistency(f"{label} fails: {text}")
    return Outcome(HOLDS, text)


CHECKS = [
    Check(
        "76",
        r"\mathbf{G}_{(m)} := \mathbf{I} + \sin \frac{\varphi}{m} \left( \mathbf{u} \times \right) + "
        r"\left( 1 - \cos \frac{\varphi}{m} \right) \left( \mathbf{u} \times \right)^2",
        "definition",
        lambda: definition(
            "defines the m-th root (the rotation by phi/m about u, eq 1); used by (77)-(85), "
            "(102) and the core (symrot.core.derivation.root_tensor)"
        ),
    ),
    Check("77", r"\mathbf{R} = \mathbf{G}_{(m)}{}^{m}", "symbolic + numeric", _eq77),
    Check(
        "78",
        r"\dot{\mathbf{G}}_{(m)} = \boldsymbol{\gamma}_{(m)} \times \mathbf{G}_{(m)}",
        "definition",
        lambda: definition(
            "defines gamma_(m) (as (9) defines omega, with the dot printed here); the "
            "audit computes it as axial(G_dot G^T) on trajectories for (79), (80), (83), (85)"
        ),
    ),
    Check(
        "79",
        r"\boldsymbol{\gamma}_{(m)} = \frac{\dot{\varphi}}{m} \mathbf{u} + \left(\sin\frac{\varphi}{m}"
        r"\mathbf{I} + \left(1 - \cos\frac{\varphi}{m}\right) (\mathbf{u}\times)\right) \dot{\mathbf{u}}",
        "numeric trajectory",
        _eq79,
    ),
    Check(
        "80",
        r"\boldsymbol{\gamma}_{(m)} = \mathbf{K}_{(m)} \dot{\mathbf{p}}",
        "definition",
        lambda: definition("defines K_(m); the core derives it from (79) "
                           "(symrot.core.derivation.root_tangent)"),
    ),
    Check(
        "text after (80): H = K_(1)",
        r"\boldsymbol{\omega} \equiv \boldsymbol{\gamma}_{(1)} \text{ and } "
        r"\mathbf{H} \equiv \mathbf{K}_{(1)}",
        "symbolic + trajectory",
        _after80,
    ),
    Check(
        "81",
        r"\mathbf{G} = \mathbf{I} + \frac{\nu}{2} \left( \mathbf{p} \times \right) + \frac{1}{p^2} "
        r"\left( 1 - \frac{\nu}{\varepsilon} \right) \ (\mathbf{p} \times)^2",
        "symbolic + numeric",
        lambda: settle("81", Claim(G81, core_tensor("G"))),
    ),
    Check(
        "82",
        r"\boldsymbol{\gamma} = \mathbf{K} \, \dot{\mathbf{p}}",
        "definition",
        lambda: definition("K = K_(2) and gamma = gamma_(2) (80 with m = 2); used by (83), (85)"),
    ),
    Check(
        "83",
        r"\mathbf{K} = \frac{\mu}{2}\mathbf{I} + \frac{1}{p^2}\left(1 - \frac{\nu}{\varepsilon}\right) "
        r"(\mathbf{p}\times) + \frac{1}{p^2}\frac{\mu - \nu}{2} (\mathbf{p}\times)^2",
        "symbolic + numeric + trajectory",
        lambda: _eq83("83", K83, None),
    ),
    Check(
        "84",
        r"\mathbf{G} = \mathbf{I} + (\mathbf{e} \times) + \frac{1}{1 + e_0} (\mathbf{e} \times)^2",
        "symbolic + numeric",
        lambda: settle("84", Claim(G84, core_tensor("G"), any_p=False)),
    ),
    Check(
        "85",
        r"\mathbf{K} = \frac{1}{e_0}\mathbf{I} + \frac{1}{1+e_0}\left(\mathbf{I} + \frac{1}{e_0}\left("
        r"\mathbf{e}\times\right)\right) (\mathbf{e}\times)",
        "symbolic + numeric + trajectory",
        lambda: _eq83("85", K85, sp.sin(PHI / 2)),
    ),
]
