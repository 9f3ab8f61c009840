"""Section 3.1, general formulation: eqs (11)–(29) and the statements of the running text.

"Any p" identities are proved for a generic p (free symbols p, p′) against the symbolic core
(R from eq 1, H from eq 10, H⁻¹ by inversion) and checked at 50 digits over the generating
functions of :mod:`symrot.audit.subjects`; the tangent tensors H, H⁻¹ are also checked against
random trajectories (:mod:`symrot.audit.kinematics`).
"""

from __future__ import annotations

import functools
from collections.abc import Callable

import mpmath
import sympy as sp

from ..parsing import PHI
from ..series import coefficient_list, taylor_series
from ..validation import validate
from .claims import Claim, Sweep, conclude, evidence, settle, sweep_function
from .kinematics import describe, tensor_at, trajectory_sweep
from .numeric import (
    TOLERANCE,
    Trajectory,
    Vector,
    cross,
    derivative,
    dot,
    fmt,
    precision,
    random_angle,
    random_axis,
    relative,
    rng,
    rotation,
    skew,
    unit,
)
from .proof import DP, EPS, EYE, MU, NU, U_CROSS, P, Verdict, at_e1, core_tensor, identity
from .records import DEFINITION, ERRATUM, HOLDS, AuditInconsistency, Check, Outcome, definition
from .subjects import Subject, scope, subjects

PX = P * U_CROSS
"""(p×) = p (u×) (eq 11)."""
R14 = EYE + NU**2 / EPS * PX + NU**2 / 2 * PX**2
H22 = MU * EYE + NU**2 / 2 * PX + (MU - NU**2 / EPS) / P**2 * PX**2
H_INVERSE26 = EYE / MU - PX / 2 - (1 / EPS - 1 / MU) / P**2 * PX**2
HALF = PHI / 2


def _block(axial: sp.Expr, diagonal: sp.Expr, upper: sp.Expr, lower: sp.Expr) -> sp.Matrix:
    return sp.Matrix([[axial, 0, 0], [0, diagonal, upper], [0, lower, diagonal]])


R17 = (
    _block(1, 1 - P**2 * NU**2 / 2, -P * NU**2 / EPS, P * NU**2 / EPS),
    _block(1, sp.cos(PHI), -sp.sin(PHI), sp.sin(PHI)),
)
H23 = (
    _block(MU, (MU - NU**2 / EPS) / P**2, -P * NU**2 / 2, P * NU**2 / 2),
    NU * _block(MU / NU, sp.cos(HALF), -sp.sin(HALF), sp.sin(HALF)),
)
H23_CORRECTED = _block(MU, NU**2 / EPS, -P * NU**2 / 2, P * NU**2 / 2)
H_INVERSE27 = (_block(1 / MU, 1 / EPS, P / 2, -P / 2), P / 2 * _block(2 * DP / P, 1 / sp.tan(HALF), 1, -1))


def _canonical_basis(u: Vector) -> mpmath.matrix:
    """Columns u, v, w = u × v: an orthonormal, right-handed basis with first vector u."""
    helper = mpmath.matrix([1, 0, 0]) if abs(u[0]) < 0.9 else mpmath.matrix([0, 1, 0])
    v = unit(cross(u, helper))
    w = cross(u, v)
    return mpmath.matrix([[u[i], v[i], w[i]] for i in range(3)])


def _canonical_form(label: str, name: str, printed: sp.Matrix) -> tuple[bool, Verdict, Sweep]:
    """[T]_B = printed, T from the core; numerically with B built around a random axis."""
    verdict = identity(printed, at_e1(core_tensor(name)))
    tensor, form = tensor_at(core_tensor(name)), tensor_at(printed)

    def evaluate(fn: Subject | None, phi: mpmath.mpf, u: Vector) -> tuple[object, object]:
        assert fn is not None
        basis = _canonical_basis(u)
        components = basis.T * tensor(fn, phi, u) * basis
        return components - form(fn, phi, u), components

    numeric = sweep_function(label, evaluate, subjects())
    return conclude(label, verdict, numeric), verdict, numeric


def _canonical(
    label: str,
    name: str,
    forms: tuple[sp.Matrix, ...],
    corrected: sp.Matrix | None = None,
    corrected_text: str = "",
    why: str = "",
) -> Outcome:
    notes, failed = [], []
    for index, printed in enumerate(forms, start=1):
        holds, verdict, numeric = _canonical_form(f"{label}:{index}", name, printed)
        claim = Claim(printed, printed)
        notes.append(f"form {index} of {len(forms)}: {evidence(verdict, numeric, claim)}")
        if not holds:
            failed.append(index)
    if not failed:
        return Outcome(
            HOLDS,
            "components in a canonical basis {u, v, w} (u = e1 symbolically; "
            "numerically B built around random axes): " + "; ".join(notes),
        )
    if corrected is None:
        raise AuditInconsistency(f"{label}: forms {failed} fail and no correction is known")
    holds, verdict, numeric = _canonical_form(f"{label}:corrected", name, corrected)
    if not holds:
        raise AuditInconsistency(f"{label}: the corrected form fails too")
    fixed = evidence(verdict, numeric, Claim(corrected, corrected))
    return Outcome(
        ERRATUM,
        f"forms {failed} fail{why}: " + "; ".join(notes) + f". Corrected form: {fixed}",
        corrected_text,
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


def _composition(vector_part: bool) -> Outcome:
    """(18), (19) for every generating function: rebuild R₃ = R₂R₁ from their right-hand sides."""

    def evaluate(fn: Subject | None, phi1: mpmath.mpf, u1: Vector) -> tuple[object, object]:
        assert fn is not None
        r = rng(f"composition:{fn.name}:{phi1}")
        phi2, u2 = random_angle(r, fn.bound), random_axis(r)
        s1, s2 = fn.scalars(phi1), fn.scalars(phi2)
        p1, p2 = s1["p"] * u1, s2["p"] * u2
        a, b = s1["nu"] * p1, s2["nu"] * p2
        cos3 = s1["nu"] / s1["eps"] * s2["nu"] / s2["eps"] - dot(a, b) / 4  # (18): nu3/eps3
        nu3_p3 = s1["nu"] / s1["eps"] * b + s2["nu"] / s2["eps"] * a - cross(a, b) / 2  # (19)
        r3 = rotation(phi2, u2) * rotation(phi1, u1)
        if not vector_part:
            return 4 * cos3**2 - 1 - (r3[0, 0] + r3[1, 1] + r3[2, 2]), r3
        half = nu3_p3 / 2  # e3 = (nu3/2) p3 (75), i.e. sin(phi3/2) u3
        rebuilt = rotation(2 * mpmath.atan2(mpmath.norm(half), cos3), unit(half))
        return rebuilt - r3, r3

    numeric = sweep_function("18-19" if vector_part else "18", evaluate, subjects())
    if not numeric.holds:
        raise AuditInconsistency(f"composition fails: {numeric.describe()}")
    what = (
        "the rotation with cos(phi3/2) = (18) and sin(phi3/2) u3 = (19)/2 is R2 R1"
        if vector_part
        else "4 (nu3/eps3)^2 - 1 = tr(R2 R1), i.e. nu3/eps3 = cos(phi3/2) up to the sign fixed by (19)"
    )
    return Outcome(
        HOLDS, f"numeric: {what}; relative residual < 1e-45 at {numeric.points} random pairs [{scope()}]"
    )


def _change_of_basis() -> Outcome:
    """Text after (19): F R Fᵀ = I + (ν²/ε)((F p)×) + (ν²/2)((F p)×)² for F ∈ SO(3)."""

    def evaluate(fn: Subject | None, phi: mpmath.mpf, u: Vector) -> tuple[object, object]:
        assert fn is not None
        r = rng(f"basis:{fn.name}:{phi}")
        f = rotation(random_angle(r, 3.1), random_axis(r))
        s = fn.scalars(phi)
        fp = skew(f * (s["p"] * u))
        printed = mpmath.eye(3) + s["nu"] ** 2 / s["eps"] * fp + s["nu"] ** 2 / 2 * fp * fp
        lhs = f * rotation(phi, u) * f.T
        return lhs - printed, lhs

    numeric = sweep_function("change-of-basis", evaluate, subjects())
    if not numeric.holds:
        raise AuditInconsistency(numeric.describe())
    return Outcome(HOLDS, f"{numeric.describe()}, random F in SO(3) [{scope()}]")


def _limits(label: str, expressions: dict[str, tuple[sp.Expr, int]]) -> Outcome:
    """lim_{φ→0} of each expression (exact series constant term) for every generating function."""
    for fn in subjects():
        for name, (expr, expected) in expressions.items():
            concrete = expr.subs({DP: sp.diff(fn.expression, PHI)}).subs({P: fn.expression})
            value = coefficient_list(taylor_series(concrete, 1), 0, 1)[0]
            if value != expected:
                raise AuditInconsistency(f"{label}: lim {name} = {value} for {fn.name}")
    limits = ", ".join(f"lim {name} = {expected}" for name, (_, expected) in expressions.items())
    return Outcome(HOLDS, f"exact series (symrot.series): {limits} at phi -> 0 [{scope()}]")


def _kappa_one() -> Outcome:
    kappas = {fn.name: validate(fn.expression).kappa for fn in subjects()}
    others = {name: k for name, k in kappas.items() if k != 1}
    if others:
        raise AuditInconsistency(f"kappa != 1 for {others}")
    return Outcome(
        DEFINITION,
        "the unit normalization kappa = 1 of eq (12) (the printed limit is "
        "shorthand for p(phi) = phi + O(phi^3); read literally its left side is p(0) = 0); "
        f"kappa = 1 confirmed from the exact Taylor series [{scope()}]",
    )


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


def _r_text() -> Outcome:
    """After (17): λ₂,₃ = (1 − p²ν²/2) ± i pν²/ε = cos φ ± i sin φ, tr R = 3 − p²ν² = 1 + 2 cos φ,
    det R = (1 − p²ν²/2)² + (pν²/ε)² = 1."""
    pairs = [
        (1 - P**2 * NU**2 / 2, sp.cos(PHI)),
        (P * NU**2 / EPS, sp.sin(PHI)),
        (3 - P**2 * NU**2, 1 + 2 * sp.cos(PHI)),
        ((1 - P**2 * NU**2 / 2) ** 2 + (P * NU**2 / EPS) ** 2, sp.Integer(1)),
    ]
    for lhs, rhs in pairs:
        if not Claim(lhs, rhs).settle("R-text")[0]:
            raise AuditInconsistency(f"after (17): {lhs} != {rhs}")
    return Outcome(HOLDS, f"each equality symbolic (generic p) and numeric (< 1e-45) [{scope()}]")


def _mu_limit() -> Outcome:
    h = core_tensor("H")
    return _limits(
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
        "11",
        r"\mathbf{p} = p(\varphi) \,\mathbf{u}",
        "definition",
        lambda: definition(
            "defines the parameter vector; every later check builds p this way "
            "(p = p(phi) u; symbrot.core.tensor_definitions)"
        ),
    ),
    Check(
        "12",
        r"\lim_{\varphi \to 0} \frac{p(\varphi)}{\varphi} = \kappa",
        "definition",
        lambda: definition(
            "defines kappa; symrot.validation computes it from the exact Taylor "
            "series (used by (13), the kappa statements after (32), (33), (75), (98), "
            "(101))"
        ),
    ),
    Check("13", r"\lim_{\varphi \to 0} p(\varphi) = \varphi", "definition + series", _kappa_one),
    Check(
        "14",
        r"\mathbf{R} = \mathbf{I} + \frac{\nu^2}{\varepsilon} \left( \mathbf{p} \times \right) + "
        r"\frac{\nu^2}{2} \left( \mathbf{p} \times \right)^2",
        "symbolic + numeric",
        lambda: settle("14", Claim(R14, core_tensor("R"))),
    ),
    Check(
        "15",
        r"\nu(\varphi) = \frac{2\sin(\varphi/2)}{p(\varphi)}",
        "definition",
        lambda: definition(
            "defines nu; used by (14), (17)-(19), (22)-(27), (38), (41)-(47), (74), "
            "(75), (81), (83) and Table 1"
        ),
    ),
    Check(
        "16",
        r"\varepsilon(\varphi) = \frac{2\tan(\varphi/2)}{p(\varphi)}",
        "definition",
        lambda: definition(
            "defines epsilon; used by (14), (17)-(19), (22), (23), (26), (27), (38), "
            "(43)-(47), (74), (81), (83), (95) and Table 1"
        ),
    ),
    Check(
        "text after (16): limits",
        r"\lim_{\varphi \to 0} \nu = \lim_{\varphi \to 0} \varepsilon = 1",
        "exact series",
        lambda: _limits("after (16)", {"nu": (NU, 1), "epsilon": (EPS, 1)}),
    ),
    Check(
        "17",
        r"[\mathbf{R}]_{\mathcal{B}} = \begin{bmatrix} 1 & 0 & 0\\ 0 & 1 - p^2 \nu^2 / 2 & "
        r"-p \nu^2 / \varepsilon\\ 0 & p \nu^2 / \varepsilon & 1 - p^2 \nu^2 / 2 \end{bmatrix} = "
        r"\begin{bmatrix} 1 & 0 & 0\\ 0 & \cos \varphi & -\sin \varphi\\ 0 & \sin \varphi & "
        r"\cos \varphi \end{bmatrix}",
        "symbolic + numeric",
        lambda: _canonical("17", "R", R17),
    ),
    Check(
        "text after (17): eigenvalues, trace, det",
        r"\lambda_{2,3}(\mathbf{R}) = (1 - p^2 \nu^2/2) \pm i p \nu^2 / \varepsilon = \cos \varphi "
        r"\pm i \sin \varphi",
        "symbolic + numeric",
        _r_text,
    ),
    Check(
        "18",
        r"\frac{\nu_3}{\varepsilon_3} = \frac{\nu_1}{\varepsilon_1} \frac{\nu_2}{\varepsilon_2} "
        r"- \frac{1}{4} (\nu_1 \mathbf{p}_1) \cdot (\nu_2 \mathbf{p}_2)",
        "numeric",
        lambda: _composition(vector_part=False),
    ),
    Check(
        "19",
        r"\nu_{3} \mathbf{p}_{3} = \frac{\nu_{1}}{\varepsilon_{1}} \left(\nu_{2} \mathbf{p}_{2}"
        r"\right) + \frac{\nu_{2}}{\varepsilon_{2}} \left(\nu_{1} \mathbf{p}_{1}\right) - \frac{1}{2} "
        r"\left(\nu_{1} \mathbf{p}_{1}\right) \times \left(\nu_{2} \mathbf{p}_{2}\right)",
        "numeric",
        lambda: _composition(vector_part=True),
    ),
    Check(
        "text after (19): change of basis",
        r"\mathbf{FRF}^T = \mathbf{I} + (\nu^2/\varepsilon) ((\mathbf{Fp}) \times) + (\nu^2/2) "
        r"((\mathbf{Fp}) \times)^2",
        "numeric",
        _change_of_basis,
    ),
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
        lambda: _canonical(
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
        lambda: _canonical("27", "H_inverse", H_INVERSE27),
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
