"""Section 3.4, rescaling: eqs (40)–(47) and the notes after (43) and (47).

A parameter vector stands for a rotation through the *principal* inverse of its generating
function: φ = 4 atan(|p|/4) ∈ [0, 2π) for p = 4 tan(φ/4) and φ = 4 asin(|p|/4) ∈ [0, 2π] for
p = 4 sin(φ/4), axis p/|p|. A rescaled vector p̂ is correct iff it stands for the same rotation;
the update formulas (43), (44), (47) are correct iff their p₃ stands for R₃ = R₂R₁.
"""

from __future__ import annotations

import itertools
from collections.abc import Callable

import mpmath
import sympy as sp

from symrot.audit.claims import Claim, settle, sweep_function
from symrot.audit.numeric import (
    REFUTED,
    TOLERANCE,
    Vector,
    cross,
    dot,
    fmt,
    fmt_vector,
    precision,
    random_angle,
    random_axis,
    relative,
    rng,
    rotation,
    unit,
)
from symrot.audit.proof import NU, P, is_zero
from symrot.audit.records import ERRATUM, HOLDS, AuditInconsistency, Check, Outcome
from symrot.audit.subjects import Subject, scope, subjects
from symrot.core.parsing import PHI

WM = 4 * sp.tan(PHI / 4)
SINE4 = 4 * sp.sin(PHI / 4)
PAIRS = 4
"""Random pairs per branch of the combined update-and-rescale formulas."""


def _rotation_of(p: Vector, inverse: Callable[[mpmath.mpf], mpmath.mpf]) -> mpmath.matrix:
    norm = mpmath.norm(p)
    return rotation(inverse(norm), p / norm)


def _wm_rotation(p: Vector) -> mpmath.matrix:
    return _rotation_of(p, lambda n: 4 * mpmath.atan(n / 4))


def _sine4_rotation(p: Vector) -> mpmath.matrix:
    return _rotation_of(p, lambda n: 4 * mpmath.asin(n / 4))


def _wm(phi: mpmath.mpf) -> dict[str, mpmath.mpf]:
    p = 4 * mpmath.tan(phi / 4)
    return {"p": p, "nu": 2 * mpmath.sin(phi / 2) / p, "eps": 2 * mpmath.tan(phi / 2) / p}


def _sine4(phi: mpmath.mpf) -> dict[str, mpmath.mpf]:
    p = 4 * mpmath.sin(phi / 4)
    return {"p": p, "nu": 2 * mpmath.sin(phi / 2) / p, "eps": 2 * mpmath.tan(phi / 2) / p}


def _require(what: str, verdict: bool | None) -> None:
    if verdict is not True:
        raise AuditInconsistency(f"could not prove: {what}")


def _eq40() -> Outcome:
    for sign in (1, -1):
        chain = [
            WM.subs(PHI, PHI + sign * 2 * sp.pi),
            4 * sp.tan(PHI / 4 + sign * sp.pi / 2),
            -4 / sp.tan(PHI / 4),
            -WM / sp.tan(PHI / 4) ** 2,
        ]
        for left, right in itertools.pairwise(chain):
            _require(f"{left} = {right}", is_zero(sp.expand_trig(left - right)))
    return Outcome(
        HOLDS,
        "symbolic: each link of the chain (magnitudes along u), for phi_hat = phi + 2 pi and phi - 2 pi",
    )


def _rescaled_rotation(
    label: str,
    scalars: Callable[[mpmath.mpf], dict[str, mpmath.mpf]],
    factor: Callable[[mpmath.mpf], mpmath.mpf],
    to_rotation: Callable[[Vector], mpmath.matrix],
) -> tuple[bool, str]:
    """Does p̂ = factor(ν) p stand for R(φ, u) at random angles π < |φ| < 2π?"""
    worst, where, points = mpmath.mpf(-1), "", 6
    with precision():
        r = rng(label)
        for _ in range(points):
            phi = mpmath.mpf(r.uniform(3.2, 6.2)) * r.choice((-1, 1))
            u = random_axis(r)
            s = scalars(phi)
            exact = rotation(phi, u)
            value = relative(to_rotation(factor(s["nu"]) * s["p"] * u) - exact, exact)
            if value > worst:
                worst, where = value, f"phi = {fmt(phi, 15)}, u = {fmt_vector(u)}"
    if TOLERANCE <= worst <= REFUTED:
        raise AuditInconsistency(f"{label}: inconclusive {fmt(worst)}")
    if worst < TOLERANCE:
        return True, f"relative residual < 1e-45 at {points} random angles pi < |phi| < 2 pi"
    return False, f"relative residual {fmt(worst)} at {where}"


def _eq41() -> Outcome:
    for sign in (1, -1):
        _require(
            "p_hat = -nu/(1 - nu) p",
            is_zero(sp.expand_trig(WM.subs(PHI, PHI + sign * 2 * sp.pi) - (-NU / (1 - NU) * P).subs(P, WM))),
        )
    holds, text = _rescaled_rotation("41", _wm, lambda nu: -nu / (1 - nu), _wm_rotation)
    _require("(41) stands for the same rotation", holds)
    return Outcome(
        HOLDS,
        "symbolic: -nu/(1 - nu) p = 4 tan(phi_hat/4) u for phi_hat = phi ± 2 pi; "
        f"the rescaled vector stands for the same rotation ({text})",
    )


def _eq42() -> Outcome:
    _require("4 tan(phi/4) * 4/tan(phi/4) = 16", is_zero(WM * 4 / sp.tan(PHI / 4) - 16))
    return Outcome(
        HOLDS,
        "symbolic: |p| |p_hat| = 4 |tan(phi/4)| 4/|tan(phi/4)| = 16; hence p > 4 "
        "(pi < |phi| < 2 pi) gives p_hat < 4, as stated",
    )


def _pairs(
    label: str, scalars: Callable[[mpmath.mpf], dict[str, mpmath.mpf]]
) -> list[tuple[dict[str, mpmath.mpf], Vector, dict[str, mpmath.mpf], Vector, mpmath.matrix, bool]]:
    """Random pairs |φ₁|, |φ₂| < π: PAIRS with |φ₃| ≤ π and PAIRS with |φ₃| > π."""
    r = rng(label)
    small: list = []
    large: list = []
    while len(small) < PAIRS or len(large) < PAIRS:
        phi1, phi2 = random_angle(r, 3.1, low=1.0), random_angle(r, 3.1, low=1.0)
        u1, u2 = random_axis(r), random_axis(r)
        r3 = rotation(phi2, u2) * rotation(phi1, u1)
        cos3 = (r3[0, 0] + r3[1, 1] + r3[2, 2] - 1) / 2
        s1, s2 = scalars(phi1), scalars(phi2)
        half_cos = s1["nu"] * s2["nu"] * (1 / (s1["eps"] * s2["eps"]) - dot(s1["p"] * u1, s2["p"] * u2) / 4)
        beyond = half_cos < 0  # cos(phi3/2) < 0: |phi3| > pi
        if abs(cos3 + 1) < 1e-6:
            continue
        bucket = large if beyond else small
        if len(bucket) < PAIRS:
            bucket.append((s1, u1, s2, u2, r3, beyond))
    return small + large


def _update(
    label: str,
    scalars: Callable[[mpmath.mpf], dict[str, mpmath.mpf]],
    nu3_of: Callable[[mpmath.mpf], mpmath.mpf],
    branches: Callable[[mpmath.mpf, mpmath.mpf, bool], mpmath.mpf],
    to_rotation: Callable[[Vector], mpmath.matrix],
    bound: mpmath.mpf,
) -> dict[bool, tuple]:
    """Worst residual of R(p₃) − R₂R₁ per branch (False: |φ₃| ≤ π) and the largest |p₃|."""
    worst: dict[bool, tuple] = {
        False: (mpmath.mpf(0), "", mpmath.mpf(0)),
        True: (mpmath.mpf(0), "", mpmath.mpf(0)),
    }
    with precision():
        for s1, u1, s2, u2, r3, beyond in _pairs(label, scalars):
            p1, p2 = s1["p"] * u1, s2["p"] * u2
            half_cos = s1["nu"] * s2["nu"] * (1 / (s1["eps"] * s2["eps"]) - dot(p1, p2) / 4)
            nu3 = nu3_of(half_cos)
            q = p1 / s2["eps"] + p2 / s1["eps"] - cross(p1, p2) / 2
            p3 = branches(s1["nu"] * s2["nu"], nu3, beyond) * q
            value = relative(to_rotation(p3) - r3, r3)
            old = worst[beyond]
            if value >= old[0]:
                where = f"p1 = {fmt_vector(p1)}, p2 = {fmt_vector(p2)}"
                worst[beyond] = (value, where, max(old[2], mpmath.norm(p3)))
            else:
                worst[beyond] = (old[0], old[1], max(old[2], mpmath.norm(p3)))
    for branch in (False, True):
        if worst[branch][2] > bound * (1 + TOLERANCE):
            raise AuditInconsistency(f"{label}: |p3| = {fmt(worst[branch][2])} exceeds {fmt(bound)}")
    return worst


def _branch_text(worst: dict[bool, tuple], beyond: bool) -> str:
    value, where, _ = worst[beyond]
    which = "|phi3| > pi (rescaled branch)" if beyond else "|phi3| <= pi"
    if value < TOLERANCE:
        return f"{which}: R(p3) = R2 R1, relative residual < 1e-45 at {PAIRS} random pairs"
    return f"{which}: R(p3) != R2 R1, relative residual {fmt(value)} at {where}"


def _eq43() -> Outcome:
    """(43) for every generating function: p₃ stands for R₂R₁ (|φ₁| + |φ₂| below the bound)."""

    def evaluate(fn: Subject | None, phi1: mpmath.mpf, u1: Vector) -> tuple[object, object]:
        assert fn is not None
        r = rng(f"43:{fn.name}:{phi1}")
        phi1 = phi1 / 2
        phi2, u2 = random_angle(r, fn.bound / 2), random_axis(r)
        s1, s2 = fn.scalars(phi1), fn.scalars(phi2)
        r3 = rotation(phi2, u2) * rotation(phi1, u1)
        phi3 = mpmath.acos((r3[0, 0] + r3[1, 1] + r3[2, 2] - 1) / 2)
        s3 = fn.scalars(phi3)
        p1, p2 = s1["p"] * u1, s2["p"] * u2
        p3 = s1["nu"] * s2["nu"] / s3["nu"] * (p1 / s2["eps"] + p2 / s1["eps"] - cross(p1, p2) / 2)
        rebuilt = rotation(phi3, unit(p3)) if s3["p"] > 0 else rotation(-phi3, unit(p3))
        return rebuilt - r3, r3

    result = sweep_function("43", evaluate, subjects())
    if not result.holds:
        raise AuditInconsistency(f"(43) fails: {result.describe()}")
    return Outcome(
        HOLDS,
        "numeric: with nu3 = nu(phi3) of R3 = R2 R1, the p3 of (43) points along the axis "
        f"of R3 (and |p3| = p(phi3) by (19)); {result.describe()} [{scope()}; stated for "
        "Wiener-Milenkovic, valid for any p]",
    )


def _note43() -> Outcome:
    first = settle("note43", Claim(2 * NU - 1, sp.cos(PHI / 2), p=WM))
    worst = _update(
        "note43", _wm, lambda c: (1 + c) / 2, lambda nu12, nu3, beyond: nu12 / nu3, _wm_rotation, mpmath.inf
    )
    if first.status != HOLDS or worst[False][0] > TOLERANCE:
        raise AuditInconsistency("note after (43)")
    return Outcome(
        HOLDS,
        f"2 nu3 - 1 = cos(phi3/2) for p = 4 tan(phi/4): {first.evidence}; "
        "cos(phi3/2) = nu1 nu2 (1/(eps1 eps2) - p1.p2/4) is (18) times 1 (nu/eps = cos(phi/2)); "
        "numeric: " + _branch_text(worst, False),
    )


def _eq44() -> Outcome:
    worst = _update(
        "44",
        _wm,
        lambda c: (1 + c) / 2,
        lambda nu12, nu3, beyond: -nu12 / (1 - nu3) if nu3 <= 0.5 else nu12 / nu3,
        _wm_rotation,
        mpmath.mpf(4),
    )
    if max(worst[False][0], worst[True][0]) > TOLERANCE:
        raise AuditInconsistency(_branch_text(worst, True))
    return Outcome(
        HOLDS,
        "numeric, p = 4 tan(phi/4), nu3 from 2 nu3 - 1 = nu1 nu2 (1/(eps1 eps2) - "
        f"p1.p2/4): {_branch_text(worst, False)}; {_branch_text(worst, True)}; |p3| <= 4",
    )


def _eq45() -> Outcome:
    printed, printed_text = _rescaled_rotation(
        "45", _sine4, lambda nu: nu / mpmath.sqrt(1 - nu**2), _sine4_rotation
    )
    inverse, _ = _rescaled_rotation(
        "45:transpose", _sine4, lambda nu: nu / mpmath.sqrt(1 - nu**2), lambda p: _sine4_rotation(p).T
    )
    fixed, fixed_text = _rescaled_rotation(
        "45:corrected", _sine4, lambda nu: -nu / mpmath.sqrt(1 - nu**2), _sine4_rotation
    )
    # symbolic, 0 < phi < 4 pi: sqrt(1 - nu^2) = sin(phi/4), so -nu/sqrt(1 - nu^2) p = p(phi - 2 pi) u
    _require(
        "-cos(phi/4)/sin(phi/4) * 4 sin(phi/4) = 4 sin((phi - 2 pi)/4)",
        is_zero(
            sp.expand_trig(-sp.cos(PHI / 4) / sp.sin(PHI / 4) * SINE4 - SINE4.subs(PHI, PHI - 2 * sp.pi))
        ),
    )
    if printed or not inverse or not fixed:
        raise AuditInconsistency("(45) check inconsistent")
    return Outcome(
        ERRATUM,
        f"as printed, p_hat stands for the inverse rotation R^T: R(p_hat) - R(phi, u) "
        f"{printed_text}, while R(p_hat) = "
        "R^T exactly (< 1e-45). p_hat as printed is p(phi + 2 pi) u for phi > 0, a point outside "
        "the principal range of the map p -> R. Corrected form: symbolic, for 0 < phi < 4 pi: "
        "-nu/sqrt(1 - nu^2) p = 4 sin((phi - 2 pi)/4) u (and 4 sin((phi + 2 pi)/4) u for "
        "-4 pi < phi < 0), and "
        f"R(p_hat) = R(phi, u) ({fixed_text})",
        r"\hat{\mathbf{p}} = -\frac{\nu}{\sqrt{1 - \nu^2}} \,\mathbf{p}",
    )


def _eq46() -> Outcome:
    _require("(4 sin(phi/4))^2 + (4 cos(phi/4))^2 = 16", is_zero(SINE4**2 + (4 * sp.cos(PHI / 4)) ** 2 - 16))
    return Outcome(
        HOLDS,
        "symbolic: p^2 + p_hat^2 = 16 sin^2(phi/4) + 16 cos^2(phi/4) = 16 "
        "(|p_hat| = 4 |cos(phi/4)| for either sign of (45))",
    )


def _sine_branches(sign: int) -> Callable[[mpmath.mpf, mpmath.mpf, bool], mpmath.mpf]:
    def factor(nu12: mpmath.mpf, nu3: mpmath.mpf, beyond: bool) -> mpmath.mpf:
        if nu3 >= 1 / mpmath.sqrt(2):
            return nu12 / nu3
        return sign * nu12 / mpmath.sqrt(1 - nu3**2)

    return factor


def _eq47() -> Outcome:
    def nu3_of(c: mpmath.mpf) -> mpmath.mpf:
        return mpmath.sqrt((1 + c) / 2)

    printed = _update("47", _sine4, nu3_of, _sine_branches(+1), _sine4_rotation, mpmath.sqrt(8))
    fixed = _update("47", _sine4, nu3_of, _sine_branches(-1), _sine4_rotation, mpmath.sqrt(8))
    if (
        printed[False][0] > TOLERANCE
        or printed[True][0] < REFUTED
        or max(fixed[False][0], fixed[True][0]) > TOLERANCE
    ):
        raise AuditInconsistency("(47) check inconsistent")
    return Outcome(
        ERRATUM,
        "numeric, p = 4 sin(phi/4), nu3 from 2 nu3^2 - 1 = nu1 nu2 (1/(eps1 eps2) - "
        f"p1.p2/4): as printed {_branch_text(printed, False)}; {_branch_text(printed, True)} "
        "(the second branch carries the sign error of (45)). Corrected: "
        f"{_branch_text(fixed, False)}; {_branch_text(fixed, True)}; p3^2 <= 8",
        r"\mathbf{p}_{3} = \begin{cases} \frac{\nu_{1}\nu_{2}}{\nu_{3}} \left(\frac{1}{\varepsilon_{2}} "
        r"\mathbf{p}_{1} + \frac{1}{\varepsilon_{1}} \mathbf{p}_{2} - \frac{1}{2} \mathbf{p}_{1} "
        r"\times \mathbf{p}_{2}\right) & \text{if } \nu_{3} \ge \frac{1}{\sqrt{2}} \\ -\frac{\nu_{1}"
        r"\nu_{2}}{\sqrt{1 - \nu_{3}^{2}}} \left(\frac{1}{\varepsilon_{2}} \mathbf{p}_{1} + \frac{1}"
        r"{\varepsilon_{1}} \mathbf{p}_{2} - \frac{1}{2} \mathbf{p}_{1} \times \mathbf{p}_{2}\right) "
        r"& \text{if } \nu_{3} \le \frac{1}{\sqrt{2}} \end{cases}",
    )


def _note47() -> Outcome:
    first = settle("note47", Claim(2 * NU**2 - 1, sp.cos(PHI / 2), p=SINE4))
    if first.status != HOLDS:
        raise AuditInconsistency("note after (47)")
    return Outcome(
        HOLDS,
        f"2 nu3^2 - 1 = cos(phi3/2) for p = 4 sin(phi/4): {first.evidence}; the second "
        "equality is (18) (nu/eps = cos(phi/2)), checked with (18)",
    )


CHECKS = [
    Check(
        "40",
        r"\hat{\mathbf{p}} = 4 \tan \frac{\hat{\varphi}}{4} \mathbf{u} = 4 \tan \left(\frac{\varphi}"
        r"{4} \pm \frac{\pi}{2}\right) \mathbf{u} = -\frac{4}{\tan \frac{\varphi}{4}} \mathbf{u} = "
        r"-\frac{1}{\tan^2 \frac{\varphi}{4}} \mathbf{p}",
        "symbolic",
        _eq40,
    ),
    Check("41", r"\hat{\mathbf{p}} = -\frac{\nu}{1-\nu}\,\mathbf{p}", "symbolic + numeric", _eq41),
    Check("42", r"p\,\hat{p} = 16", "symbolic", _eq42),
    Check(
        "43",
        r"\mathbf{p}_3 = \frac{\nu_1 \nu_2}{\nu_3} \left( \frac{1}{\varepsilon_2} \mathbf{p}_1 + "
        r"\frac{1}{\varepsilon_1} \mathbf{p}_2 - \frac{1}{2} \mathbf{p}_1 \times \mathbf{p}_2 \right)",
        "numeric",
        _eq43,
    ),
    Check(
        "text after (43): nu3",
        r"2\nu_3 - 1 = \cos \varphi_3/2 = \nu_1 \nu_2 (1/\varepsilon_1 "
        r"\varepsilon_2 - \mathbf{p}_1 \cdot \mathbf{p}_2/4)",
        "symbolic + numeric",
        _note43,
    ),
    Check(
        "44",
        r"\mathbf{p}_{3} = \begin{cases} \frac{\nu_{1}\nu_{2}}{\nu_{3}} \dots & \text{if } \nu_{3} "
        r"\ge \frac{1}{2} \\ -\frac{\nu_{1}\nu_{2}}{1 - \nu_{3}} \left( \frac{1}{\varepsilon_{2}} "
        r"\mathbf{p}_{1} + \frac{1}{\varepsilon_{1}} \mathbf{p}_{2} - \frac{1}{2} \mathbf{p}_{1} \times "
        r"\mathbf{p}_{2} \right) & \text{if } \nu_{3} \le \frac{1}{2} \end{cases}",
        "numeric",
        _eq44,
    ),
    Check("45", r"\hat{\mathbf{p}} = \frac{\nu}{\sqrt{1 - \nu^2}} \,\mathbf{p}", "symbolic + numeric", _eq45),
    Check("46", r"p^2 + \hat{p}^2 = 16", "symbolic", _eq46),
    Check(
        "47",
        r"\mathbf{p}_{3} = \begin{cases} \frac{\nu_{1}\nu_{2}}{\nu_{3}} \dots & \text{if } \nu_{3} "
        r"\ge \frac{1}{\sqrt{2}} \\ \frac{\nu_{1}\nu_{2}}{\sqrt{1 - \nu_{3}^{2}}} \left(\frac{1}{"
        r"\varepsilon_{2}} \mathbf{p}_{1} + \frac{1}{\varepsilon_{1}} \mathbf{p}_{2} - \frac{1}{2} "
        r"\mathbf{p}_{1} \times \mathbf{p}_{2}\right) & \text{if } \nu_{3} \le \frac{1}{\sqrt{2}} "
        r"\end{cases}",
        "numeric",
        _eq47,
    ),
    Check(
        "text after (47): nu3",
        r"2\nu_3^2 - 1 = \cos \varphi_3/2 = \nu_1 \nu_2 (1/\varepsilon_1 "
        r"\varepsilon_2 - \mathbf{p}_1 \cdot \mathbf{p}_2/4)",
        "symbolic",
        _note47,
    ),
]
