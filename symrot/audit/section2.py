"""Section 2 (Euler-Rodrigues formula, eigenvalues, angular velocity) and §3.1 definitions."""

from __future__ import annotations

import mpmath
import sympy as sp

from ..parsing import PHI
from ..timeouts import time_limit
from .checks import DEFINITION, ERRATUM, HOLDS, Check, Outcome
from .numeric import DIGITS, TOLERANCE, Trajectory, axial, norm, rng, rotation, skew, unit

SEEDS = (1, 2, 3)


def _eq1() -> Outcome:
    """Definition of R; we still confirm R Rᵀ = I and det R = 1 at random points (50 digits)."""
    worst = mpmath.mpf(0)
    with mpmath.workdps(DIGITS):
        for seed in SEEDS:
            r = rng(seed)
            u = unit([mpmath.mpf(r.uniform(-1, 1)) for _ in range(3)])
            rot = rotation(mpmath.mpf(r.uniform(-3, 3)), u)
            worst = max(worst, norm(rot * rot.T - mpmath.eye(3)), abs(mpmath.det(rot) - 1))
    if worst > TOLERANCE:
        raise ArithmeticError(f"eq (1) is not orthogonal: residual {mpmath.nstr(worst, 5)}")
    return Outcome(DEFINITION, f"defines R; R R^T = I, det R = 1 at {len(SEEDS)} random points "
                   f"(max residual {mpmath.nstr(worst, 3)})")


def _eigenvalues() -> Outcome:
    """Text after (7): λ₂,₃ = exp(±iφ) = cos φ ± sin φ."""
    with time_limit(10, "eigenvalues of R"):
        printed = sp.cos(PHI) + sp.sin(PHI)
        exact = sp.expand(sp.exp(sp.I * PHI), complex=True)
        residual = sp.simplify(exact - printed)
        corrected = sp.simplify(exact - (sp.cos(PHI) + sp.I * sp.sin(PHI)))
    if residual == 0 or corrected != 0:
        raise ArithmeticError("eigenvalue check inconsistent")
    return Outcome(ERRATUM, f"exp(i phi) - (cos phi + sin phi) = {residual} != 0",
                   "lambda_{2,3}(R) = exp(±i phi) = cos phi ± i sin phi")


def _eq9() -> Outcome:
    """(9) printed R = ω×R; the intended Ṙ = (ω×) R, with ω = axial(Ṙ Rᵀ)."""
    printed_worst, corrected_worst = mpmath.mpf("inf"), mpmath.mpf(0)
    with mpmath.workdps(DIGITS):
        for seed in SEEDS:
            path = Trajectory(seed)
            t = mpmath.mpf(rng(seed + 100).uniform(-1, 1))
            rot, rot_dot = path.rotation(t), path.rotation_dot(t)
            omega_cross = skew(axial(rot_dot * rot.T))
            printed_worst = min(printed_worst, norm(rot - omega_cross * rot))
            corrected_worst = max(corrected_worst, norm(rot_dot - omega_cross * rot))
    if corrected_worst > TOLERANCE or printed_worst < 1e-3:
        raise ArithmeticError("eq (9) check inconsistent")
    return Outcome(ERRATUM, f"printed form: ||R - (w x)R|| >= {mpmath.nstr(printed_worst, 6)} on random "
                   f"trajectories; corrected form residual <= {mpmath.nstr(corrected_worst, 3)}",
                   "R_dot = (omega x) R  (the dot on R is missing)")


def _eq10() -> Outcome:
    """(10) ω = φ̇ u + (sin φ I + (1 − cos φ)(u×)) u̇, against ω = axial(Ṙ Rᵀ) on trajectories."""
    worst = mpmath.mpf(0)
    with mpmath.workdps(DIGITS):
        for seed in SEEDS:
            path = Trajectory(seed)
            t = mpmath.mpf(rng(seed + 100).uniform(-1, 1))
            rot, rot_dot = path.rotation(t), path.rotation_dot(t)
            omega = mpmath.matrix(axial(rot_dot * rot.T))
            phi, u = path.phi(t), path.u(t)
            phi_dot = mpmath.diff(path.phi, t)
            u_dot = mpmath.matrix([mpmath.diff(lambda s, i=i, q=path: q.u(s)[i], t) for i in range(3)])
            formula = phi_dot * mpmath.matrix(u) + (
                mpmath.sin(phi) * mpmath.eye(3) + (1 - mpmath.cos(phi)) * skew(u)) * u_dot
            worst = max(worst, mpmath.mnorm(omega - formula, 1))
    if worst > TOLERANCE:
        return Outcome(ERRATUM, f"residual {mpmath.nstr(worst, 6)}")
    return Outcome(HOLDS, f"max residual {mpmath.nstr(worst, 3)} on {len(SEEDS)} random trajectories")


CHECKS = [
    Check("1", "R = I + sin(phi) (u x) + (1 - cos(phi)) (u x)^2", "definition", _eq1),
    Check("text after (6)", "lambda_{2,3}(R) = exp(±i phi) = cos phi ± sin phi", "symbolic", _eigenvalues),
    Check("9", "R = omega x R", "numeric trajectory", _eq9),
    Check("10", "omega = phi_dot u + (sin phi I + (1 - cos phi)(u x)) u_dot", "numeric trajectory", _eq10),
]
