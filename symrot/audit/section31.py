"""Section 3.1, general formulation, eqs (11)–(19): the parameter vector and the rotation tensor.

"Any p" identities are proved for a generic p (free symbols p, p′) against the symbolic core
(R from eq 1, H from eq 10, H⁻¹ by inversion) and checked at 50 digits over the generating
functions of :mod:`symrot.audit.subjects`. The tangent tensors, eqs (20)–(29), are in
:mod:`symrot.audit.section31_tangent`, which shares the canonical-basis and limit checks of this
module.
"""

from __future__ import annotations

import mpmath
import sympy as sp

from symrot.audit.claims import Claim, Sweep, conclude, evidence, settle, sweep_function
from symrot.audit.kinematics import tensor_at
from symrot.audit.numeric import (
    Vector,
    cross,
    dot,
    random_angle,
    random_axis,
    rng,
    rotation,
    skew,
    unit,
)
from symrot.audit.proof import DP, EPS, EYE, NU, U_CROSS, P, Verdict, at_e1, core_tensor, identity
from symrot.audit.records import DEFINITION, ERRATUM, HOLDS, AuditInconsistency, Check, Outcome, definition
from symrot.audit.subjects import Subject, scope, subjects
from symrot.core.parsing import PHI
from symrot.core.series import coefficient_list, taylor_series
from symrot.core.validation import validate

PX = P * U_CROSS
"""(p×) = p (u×) (eq 11)."""
R14 = EYE + NU**2 / EPS * PX + NU**2 / 2 * PX**2


def canonical_matrix(axial: sp.Expr, diagonal: sp.Expr, upper: sp.Expr, lower: sp.Expr) -> sp.Matrix:
    """A tensor's components in a canonical basis {u, v, w}: the axial entry, then the 2×2 block."""
    return sp.Matrix([[axial, 0, 0], [0, diagonal, upper], [0, lower, diagonal]])


R17 = (
    canonical_matrix(1, 1 - P**2 * NU**2 / 2, -P * NU**2 / EPS, P * NU**2 / EPS),
    canonical_matrix(1, sp.cos(PHI), -sp.sin(PHI), sp.sin(PHI)),
)


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


def canonical_outcome(
    label: str,
    name: str,
    forms: tuple[sp.Matrix, ...],
    corrected: sp.Matrix | None = None,
    corrected_text: str = "",
    why: str = "",
) -> Outcome:
    """Each printed canonical form (17, 23, 27) of the core's tensor ``name``; when one fails, the
    ``corrected`` form must hold and the outcome is an erratum."""
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


def series_limits(label: str, expressions: dict[str, tuple[sp.Expr, int]]) -> Outcome:
    """lim_{φ→0} of each expression (exact series constant term) for every generating function."""
    for fn in subjects():
        for name, (expr, expected) in expressions.items():
            concrete = expr.subs({DP: sp.diff(fn.expression, PHI)}).subs({P: fn.expression})
            value = coefficient_list(taylor_series(concrete, 1), 0, 1)[0]
            if value != expected:
                raise AuditInconsistency(f"{label}: lim {name} = {value} for {fn.name}")
    limits = ", ".join(f"lim {name} = {expected}" for name, (_, expected) in expressions.items())
    return Outcome(HOLDS, f"exact series (symrot.core.series): {limits} at phi -> 0 [{scope()}]")


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
            "defines kappa; symrot.core.validation computes it from the exact Taylor "
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
        lambda: series_limits("after (16)", {"nu": (NU, 1), "epsilon": (EPS, 1)}),
    ),
    Check(
        "17",
        r"[\mathbf{R}]_{\mathcal{B}} = \begin{bmatrix} 1 & 0 & 0\\ 0 & 1 - p^2 \nu^2 / 2 & "
        r"-p \nu^2 / \varepsilon\\ 0 & p \nu^2 / \varepsilon & 1 - p^2 \nu^2 / 2 \end{bmatrix} = "
        r"\begin{bmatrix} 1 & 0 & 0\\ 0 & \cos \varphi & -\sin \varphi\\ 0 & \sin \varphi & "
        r"\cos \varphi \end{bmatrix}",
        "symbolic + numeric",
        lambda: canonical_outcome("17", "R", R17),
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
]
