"""Appendix A, eqs (68)–(75): quaternion rates and the link to the vectorial parameterization.

Rates (68)–(73) are checked on random trajectories at 60 digits (with the exact identities of
(71) proved by :func:`symrot.audit.appendix_a.exact_identity`); (74), (75) and the statement after
(75) symbolically and at 50 digits. The quaternion algebra, eqs (48)–(67), is in
:mod:`symrot.audit.appendix_a`.
"""

from __future__ import annotations

from collections.abc import Callable

import mpmath
import sympy as sp

from symrot.audit.appendix_a import SAMPLES, F, Q, compose, conjugate, exact_identity, m_right
from symrot.audit.claims import Claim, settle
from symrot.audit.numeric import (
    TOLERANCE,
    Trajectory,
    cross,
    derivative,
    fmt,
    precision,
    relative,
    vector,
)
from symrot.audit.proof import EPS, MU, NU, U_VECTOR, P
from symrot.audit.records import HOLDS, AuditInconsistency, Check, Outcome, definition
from symrot.core.parsing import PHI
from symrot.core.validation import validate


def _quaternion_path(label: str) -> tuple[Trajectory, Callable[[mpmath.mpf], mpmath.matrix]]:
    path = Trajectory(label)

    def e(t: mpmath.mpf) -> mpmath.matrix:
        half = path.phi(t) / 2
        return mpmath.matrix([mpmath.cos(half), *(mpmath.sin(half) * path.u(t))])

    return path, e


def _hamilton(left: mpmath.matrix, right: mpmath.matrix) -> mpmath.matrix:
    """(53) numerically: left ∘ right."""
    a, b = left[0], vector([left[1], left[2], left[3]])
    c, d = right[0], vector([right[1], right[2], right[3]])
    vec = c * b + a * d - cross(d, b)
    return mpmath.matrix([a * c - sum(b[i] * d[i] for i in range(3)), vec[0], vec[1], vec[2]])


def _rates(which: str) -> Outcome:
    """(68), ω₀ = 0 (after 69), (71), (72), (73) on random trajectories."""
    worst = mpmath.mpf(0)
    with precision():
        for k in range(SAMPLES):
            path, e = _quaternion_path(f"rates:{which}:{k}")
            t = path.t
            q, q_dot = e(t), derivative(e, t)
            omega = path.spin()
            e0, ev = q[0], vector([q[1], q[2], q[3]])
            e0_dot, ev_dot = q_dot[0], vector([q_dot[1], q_dot[2], q_dot[3]])
            omega4 = mpmath.matrix([0, *omega])
            conj = mpmath.matrix([q[0], -q[1], -q[2], -q[3]])
            if which == "68":
                value = relative(2 * e0 * ev_dot - 2 * e0_dot * ev + 2 * cross(ev, ev_dot) - omega, omega)
            elif which == "69":
                value = abs(2 * (e0 * e0_dot + sum(ev[i] * ev_dot[i] for i in range(3))))
            elif which == "71":
                m_r = mpmath.matrix(4, 4)
                m_r[0, 0] = e0
                for i in range(3):
                    m_r[0, i + 1], m_r[i + 1, 0] = -ev[i], ev[i]
                block = e0 * mpmath.eye(3) - mpmath.matrix(
                    [[0, -ev[2], ev[1]], [ev[2], 0, -ev[0]], [-ev[1], ev[0], 0]]
                )
                for i in range(3):
                    for j in range(3):
                        m_r[i + 1, j + 1] = block[i, j]
                value = relative(2 * m_r.T * q_dot - omega4, omega4)
            elif which == "72":
                value = relative(2 * _hamilton(q_dot, conj) - omega4, omega4)
            else:
                value = relative(_hamilton(omega4, q) / 2 - q_dot, q_dot)
            worst = max(worst, value)
    if worst > TOLERANCE:
        raise AuditInconsistency(f"({which}) residual {fmt(worst)}")
    return Outcome(
        HOLDS,
        f"numeric: e(t) = (cos(phi/2), sin(phi/2) u) on random trajectories, omega = "
        f"axial(R_dot R^T) of eq (1): residual < 1e-45 on {SAMPLES} trajectories",
    )


def _eq71() -> Outcome:
    exact = exact_identity(
        "71",
        [
            (m_right(Q).T, m_right(conjugate(Q))),
            (2 * m_right(Q).T * sp.Matrix(F), 2 * compose(sp.Matrix(F), conjugate(Q))),
        ],
        modulo_normality=False,
    )
    rates = _rates("71")
    return Outcome(
        HOLDS, f"{exact.evidence} (M_r(e)^T = M_r(e*), 2 M_r(e)^T e_dot = 2 e_dot o e*); {rates.evidence}"
    )


def _after75() -> Outcome:
    p = sp.sin(PHI / 2)
    kappa = validate(p).kappa
    e0 = sp.cos(PHI / 2)
    results = [
        settle("after75:mu", Claim(MU, 2 / e0, p=p)),
        settle("after75:nu", Claim(NU, sp.Integer(2), p=p)),
        settle("after75:eps", Claim(EPS, MU, p=p)),
    ]
    if kappa != sp.Rational(1, 2) or any(r.status != HOLDS for r in results):
        raise AuditInconsistency("statement after (75)")
    return Outcome(
        HOLDS,
        f"p = e means p = sin(phi/2) (75 with nu = 2), kappa = {kappa} (exact series); "
        "mu = 2/e0, nu = 2, eps = mu: " + "; ".join(r.evidence for r in results),
    )


CHECKS = [
    Check(
        "68",
        r"\boldsymbol{\omega} = 2e_0 \,\dot{\mathbf{e}} - 2\dot{e}_0 \,\mathbf{e} + 2 \,\mathbf{e} "
        r"\times \,\dot{\mathbf{e}}",
        "numeric trajectory",
        lambda: _rates("68"),
    ),
    Check(
        "69",
        r"\underline{\omega} = \begin{bmatrix} \omega_0 \\ \boldsymbol{\omega} \end{bmatrix}",
        "definition",
        lambda: definition("defines the angular-velocity quaternion; used by (70)-(73)"),
    ),
    Check(
        "text after (69): omega0",
        r"\omega_0 = 2 (e_0 \dot{e}_0 + \mathbf{e} \cdot \dot{\mathbf{e}}) = 0",
        "numeric trajectory",
        lambda: _rates("69"),
    ),
    Check(
        "70",
        r"\underline{\omega} = \mathcal{H}(\underline{e})\,\underline{\dot{e}}",
        "definition",
        lambda: definition("defines the operator H(e); (71) is checked against trajectories"),
    ),
    Check(
        "71",
        r"\mathcal{H}(\underline{e}) = 2 \,\mathcal{M}_r(\underline{e})^T = 2 \,\mathcal{M}_r"
        r"(\underline{e}^*)",
        "exact + numeric trajectory",
        _eq71,
    ),
    Check(
        "72",
        r"\underline{\omega} = 2\,\underline{\dot{e}} \circ \underline{e}^*",
        "numeric trajectory",
        lambda: _rates("72"),
    ),
    Check(
        "73",
        r"\underline{\dot{e}} = \frac{1}{2}\,\underline{\omega}\circ\underline{e}",
        "numeric trajectory",
        lambda: _rates("73"),
    ),
    Check(
        "74",
        r"e_0 = \frac{\nu}{\varepsilon}",
        "symbolic + numeric",
        lambda: settle("74", Claim(NU / EPS, sp.cos(PHI / 2))),
    ),
    Check(
        "75",
        r"\mathbf{e} = \frac{\nu}{2} \mathbf{p}",
        "symbolic + numeric",
        lambda: settle("75", Claim(NU / 2 * P * U_VECTOR, sp.sin(PHI / 2) * U_VECTOR)),
    ),
    Check(
        "text after (75): p = e",
        r"\mu = 2/e_0, \nu = 2, \text{ and } \varepsilon = \mu",
        "symbolic + numeric",
        _after75,
    ),
]
