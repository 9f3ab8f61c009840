"""Trajectory checks ω = H ṗ, ṗ = H⁻¹ ω, γ_(m) = K_(m) ṗ for every generating function.

For each generating function a few random smooth trajectories φ(t), u(t) (|φ(0)| inside its
sampling bound) give ṗ = d/dt [p(φ) u] and ω = axial(Ṙ Rᵀ) of eq (1) (γ_(m) = axial(Ġ Gᵀ) for
the m-th root, eq 76) by :func:`mpmath.diff` at 60 digits: an independent numeric truth for the
tangent tensors, unrelated to the symbolic core.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence

import mpmath
import sympy as sp

from symrot.audit.claims import Sweep, compile_numeric
from symrot.audit.numeric import Trajectory, Vector, derivative, fmt, fmt_vector, precision, relative
from symrot.audit.subjects import Subject, subjects

TRAJECTORIES = 2
"""Random trajectories per generating function."""

TensorAt = Callable[[Subject, mpmath.mpf, Vector], mpmath.matrix]


def tensor_at(expr: sp.Matrix) -> TensorAt:
    """A tensor transcribed in (φ, p, p′, u) as a numeric function of (generating function, φ, u)."""
    compiled = compile_numeric(expr)

    def at(fn: Subject, phi: mpmath.mpf, u: Vector) -> mpmath.matrix:
        return compiled(phi, fn.p(phi), fn.dp(phi), u[0], u[1], u[2])

    return at


def trajectory_sweep(
    label: str,
    tensor: TensorAt,
    fraction: int = 1,
    inverse: bool = False,
    functions: Sequence[Subject] | None = None,
) -> Sweep:
    """Worst relative residual of T ṗ − γ (or T γ − ṗ when ``inverse``), γ = spin of G_(fraction)."""
    worst, where, count = mpmath.mpf(-1), "", 0
    with precision():
        for fn in functions if functions is not None else subjects():
            for k in range(TRAJECTORIES):
                path = Trajectory(f"{label}:{fn.name}:{k}", bound=fn.bound)
                phi, u = path.phi(path.t), path.u(path.t)
                p_dot = derivative(path.parameter_vector(fn.p), path.t)
                spin = path.spin(fraction)
                t = tensor(fn, phi, u)
                residual, reference = (t * spin - p_dot, p_dot) if inverse else (t * p_dot - spin, spin)
                value = relative(residual, reference)
                count += 1
                if value > worst:
                    worst = value
                    where = f"{fn.name}, phi = {fmt(phi, 15)}, u = {fmt_vector(u)}"
    return Sweep(worst, where, count)


def describe(sweep: Sweep, relation: str) -> str:
    if sweep.holds:
        return (
            f"trajectories: {relation} with relative residual < 1e-45 on {sweep.points} random "
            "trajectories (mpmath.diff, 60 digits)"
        )
    return f"trajectories: {relation} fails: {sweep.where}: relative residual {fmt(sweep.worst)}"
