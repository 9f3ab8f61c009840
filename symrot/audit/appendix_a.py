"""Appendix A, Euler–Rodrigues parameters, eqs (48)–(67): the quaternion algebra.

Quaternion identities are polynomial identities in the components (e₀, e₁, e₂, e₃): they are
proved exactly by expansion (:func:`exact_identity`), reduced modulo the normality condition
e₀² + e·e = 1 (50) where the paper invokes it. Rates and the link to p, eqs (68)–(75), are in
:mod:`symrot.audit.appendix_a_rates`.
"""

from __future__ import annotations

from typing import Any

import mpmath
import sympy as sp

from symrot.audit.claims import dual_outcome
from symrot.audit.numeric import (
    TOLERANCE,
    Vector,
    fmt,
    precision,
    random_axis,
    rng,
    rotation,
    vector,
)
from symrot.audit.records import ERRATUM, HOLDS, AuditInconsistency, Check, Outcome, definition

E = sp.symbols("e0:4")
F = sp.symbols("f0:4")
V = sp.symbols("v0:4")
NORMALITY = sum(x**2 for x in E) - 1
QUATERNION = sp.Matrix(E)
SAMPLES = 4


def _vec(q: sp.Matrix) -> sp.Matrix:
    return sp.Matrix(q[1:4])


def _skew(v: sp.Matrix) -> sp.Matrix:
    return sp.Matrix([[0, -v[2], v[1]], [v[2], 0, -v[0]], [-v[1], v[0], 0]])


def compose(left: sp.Matrix, right: sp.Matrix) -> sp.Matrix:
    """(53) as printed: e₂ ∘ e₁ = [e₁₀e₂₀ − e₁·e₂; e₁₀ e₂ + e₂₀ e₁ − e₁ × e₂] (left = e₂)."""
    e2, e1 = _vec(left), _vec(right)
    scalar = right[0] * left[0] - e1.dot(e2)
    vec = right[0] * e2 + left[0] * e1 - e1.cross(e2)
    return sp.Matrix([scalar, *vec])


def conjugate(q: sp.Matrix) -> sp.Matrix:
    """(60): e* = [e₀; −e]."""
    return sp.Matrix([q[0], *(-_vec(q))])


def _block(corner: sp.Expr, row: sp.Matrix, column: sp.Matrix, body: sp.Matrix) -> sp.Matrix:
    top = sp.Matrix([[corner, *row]])
    return top.col_join(column.row_join(body))


def m_left(q: sp.Matrix) -> sp.Matrix:
    """(54): [[e₀, −eᵀ], [e, e₀ I + (e×)]]."""
    e = _vec(q)
    return _block(q[0], -e, e, q[0] * sp.eye(3) + _skew(e))


def m_right(q: sp.Matrix) -> sp.Matrix:
    """(55): [[e₀, −eᵀ], [e, e₀ I − (e×)]]."""
    e = _vec(q)
    return _block(q[0], -e, e, q[0] * sp.eye(3) - _skew(e))


def rotation51(q: sp.Matrix) -> sp.Matrix:
    """(51): R = I + 2 e₀ (e×) + 2 (e×)²."""
    ex = _skew(_vec(q))
    return sp.eye(3) + 2 * q[0] * ex + 2 * ex * ex


def _zero(m: sp.Matrix, modulo_normality: bool) -> bool:
    for entry in m:
        polynomial = sp.expand(entry)
        if modulo_normality:
            polynomial = sp.reduced(polynomial, [NORMALITY], *E)[1]
        if polynomial != 0:
            return False
    return True


def exact_identity(
    label: str, pairs: list[tuple[sp.Matrix, sp.Matrix]], modulo_normality: bool, note: str = ""
) -> Outcome:
    """Each (lhs, rhs) pair equal as polynomials in e₀..e₃ (modulo (50) if ``modulo_normality``)."""
    for index, (lhs, rhs) in enumerate(pairs):
        if not _zero(lhs - rhs, modulo_normality):
            raise AuditInconsistency(f"{label}: equality {index + 1} fails")
    how = "modulo the normality condition (50)" if modulo_normality else "without using (50)"
    count = f"each of the {len(pairs)} equalities" if len(pairs) > 1 else "the equality"
    return Outcome(
        HOLDS, f"exact polynomial identity in e0..e3 ({count}, {how})" + (f"; {note}" if note else "")
    )


Q = QUATERNION
Q2 = sp.Matrix(F)
PURE = sp.Matrix([0, *V[1:]])
"""A vector as a quaternion with vanishing scalar part (66)."""


def _embed(r: sp.Matrix) -> sp.Matrix:
    return _block(1, sp.zeros(1, 3), sp.zeros(3, 1), r)


def _eq62() -> Outcome:
    r = rotation51(Q)
    trace = r.trace()
    axial = sp.Matrix([r[2, 1] - r[1, 2], r[0, 2] - r[2, 0], r[1, 0] - r[0, 1]]) / 2
    printed = _block(1 + trace, 2 * axial, 2 * axial, (1 - trace) * sp.eye(3) + r + r.T) / 4
    return exact_identity(
        "62",
        [(printed, Q * Q.T)],
        modulo_normality=True,
        note="R from (51); tr and axial as defined in Section 1.1",
    )


def _eq64() -> Outcome:
    """(64): e_i = E_ik/√E_kk recovers ±e; numerically from R built by eq (1)."""
    worst = mpmath.mpf(0)
    with precision():
        r = rng("64")
        for _ in range(SAMPLES):
            phi, u = mpmath.mpf(r.uniform(-3.1, 3.1)), random_axis(r)
            rot = rotation(phi, u)
            trace = rot[0, 0] + rot[1, 1] + rot[2, 2]
            axial = vector(
                [(rot[2, 1] - rot[1, 2]) / 2, (rot[0, 2] - rot[2, 0]) / 2, (rot[1, 0] - rot[0, 1]) / 2]
            )
            body = (1 - trace) * mpmath.eye(3) + rot + rot.T
            e_matrix = mpmath.matrix(4, 4)
            e_matrix[0, 0] = (1 + trace) / 4
            for i in range(3):
                e_matrix[0, i + 1] = e_matrix[i + 1, 0] = axial[i] / 2
                for j in range(3):
                    e_matrix[i + 1, j + 1] = body[i, j] / 4
            k = max(range(4), key=lambda i: e_matrix[i, i])
            delta = mpmath.sqrt(e_matrix[k, k])  # (65)
            e = [e_matrix[i, k] / delta for i in range(4)]  # (64)
            truth = [mpmath.cos(phi / 2), *(mpmath.sin(phi / 2) * u)]
            sign = 1 if sum(a * b for a, b in zip(e, truth, strict=True)) > 0 else -1
            worst = max(worst, max(abs(a - sign * b) for a, b in zip(e, truth, strict=True)))
    if worst > TOLERANCE:
        raise AuditInconsistency(f"(64) residual {fmt(worst)}")
    return Outcome(
        HOLDS,
        "by (63) E_ik/sqrt(E_kk) = e_i e_k/|e_k| = sign(e_k) e_i, i.e. e up to the sign "
        "of e_k (+e and -e give the same R, (51) being quadratic); numeric: from R of eq (1) "
        f"with k = argmax E_kk the extracted quaternion is +-(cos(phi/2), sin(phi/2) u), residual "
        f"< 1e-45 at {SAMPLES} random rotations",
    )


def _max_text() -> Outcome:
    """After (65): max(E₀₀, ..., E₃₃) = max(tr R, R₁₁, R₂₂, R₃₃) — equal positions, not values."""
    r = sp.Matrix(3, 3, sp.symbols("r0:9"))
    trace = r.trace()
    diagonal = [(1 + trace) / 4] + [((1 - trace) + 2 * r[k, k]) / 4 for k in range(3)]
    shift = [sp.expand(diagonal[k + 1] - diagonal[0] - (r[k, k] - trace) / 2) for k in range(3)]
    at_identity = [d.subs({s: (1 if s in (r[0, 0], r[1, 1], r[2, 2]) else 0) for s in r}) for d in diagonal]
    if any(shift) or max(at_identity) != 1:
        raise AuditInconsistency("max statement")
    return Outcome(
        ERRATUM,
        "from (62), E_00 = (1 + tr R)/4 and E_kk = (1 - tr R + 2 R_kk)/4, so E_kk - E_00 = "
        "(R_kk - tr R)/2 (exact, any R): the largest diagonal entry of E sits where the largest "
        "of tr R, R_11, R_22, R_33 sits, but the values differ; e.g. R = I: max E_kk = "
        f"{max(at_identity)} while max(tr R, R_11, R_22, R_33) = 3",
        r"\arg\max_k E_{kk} \text{ corresponds to } \arg\max(\operatorname{tr}(\mathbf{R}), R_{11}, "
        r"R_{22}, R_{33}) \quad (E_{kk} - E_{00} = (R_{kk} - \operatorname{tr}\mathbf{R})/2)",
    )


def _e(ops: Any, phi: Any) -> tuple[Any, Any]:
    return ops.cos(phi / 2), ops.sin(phi / 2)


def _r51(ops: Any, phi: Any, u: Vector) -> Any:
    e0, s = _e(ops, phi)
    ex = ops.skew(s * u)
    return ops.eye() + 2 * e0 * ex + 2 * ex * ex


def _r1(ops: Any, phi: Any, u: Vector) -> Any:
    k = ops.skew(u)
    return ops.eye() + ops.sin(phi) * k + (1 - ops.cos(phi)) * k * k


CHECKS = [
    Check(
        "48",
        r"e_0 = \cos\frac{\varphi}{2}",
        "definition",
        lambda: definition(
            "defines the scalar part e0; used by (50), (51), (64), (68)-(75), (84), (85), (96)"
        ),
    ),
    Check(
        "49",
        r"\mathbf{e} = \sin\frac{\varphi}{2}\,\mathbf{u}",
        "definition",
        lambda: definition("defines the vector part e; used with (48)"),
    ),
    Check(
        "50",
        r"e_0^2 + e^2 = 1",
        "symbolic + numeric",
        lambda: dual_outcome(
            "50", lambda o, phi, u: _e(o, phi)[0] ** 2 + _e(o, phi)[1] ** 2 * o.dot(u, u), lambda o, phi, u: 1
        ),
    ),
    Check(
        "51",
        r"\mathbf{R} = \mathbf{I} + 2e_0 \left(\mathbf{e}\times\right) + 2 \left(\mathbf{e}\times"
        r"\right)^2",
        "symbolic + numeric",
        lambda: dual_outcome("51", _r51, _r1),
    ),
    Check(
        "52",
        r"\underline{e} := \begin{bmatrix} e_0 \\ \mathbf{e} \end{bmatrix}",
        "definition",
        lambda: definition("defines the quaternion array; used by (53)-(73)"),
    ),
    Check(
        "53",
        r"\underline{e}_2 \circ \underline{e}_1 = \begin{bmatrix} e_{10} e_{20} - \mathbf{e}_1 \cdot "
        r"\mathbf{e}_2 \\ e_{10} \mathbf{e}_2 + e_{20} \mathbf{e}_1 - \mathbf{e}_1 \times \mathbf{e}_2 "
        r"\end{bmatrix}",
        "definition",
        lambda: definition(
            "defines the product o (the Hamilton product e2 e1); its compatibility with "
            "R3 = R2 R1 is proved in (67) and with (7), (8) numerically"
        ),
    ),
    Check(
        "54",
        r"\mathcal{M}_{l}(\underline{e}) = \begin{bmatrix} e_{0} & -\mathbf{e}^{T} \\ \mathbf{e} & "
        r"e_{0}\mathbf{I} + (\mathbf{e}\times) \end{bmatrix}",
        "definition",
        lambda: definition("defines M_l; used by (56)-(61), (66)"),
    ),
    Check(
        "55",
        r"\mathcal{M}_{r}(\underline{e}) = \begin{bmatrix} e_{0} & -\mathbf{e}^{T} \\ \mathbf{e} & "
        r"e_{0}\mathbf{I} - (\mathbf{e}\times) \end{bmatrix}",
        "definition",
        lambda: definition("defines M_r; used by (56)-(61), (66), (71)"),
    ),
    Check(
        "56",
        r"\underline{e}_2 \circ \underline{e}_1 = \mathcal{M}_l(\underline{e}_2) \, \underline{e}_1 = "
        r"\mathcal{M}_r(\underline{e}_1) \, \underline{e}_2",
        "exact",
        lambda: exact_identity(
            "56", [(compose(Q2, Q), m_left(Q2) * Q), (compose(Q2, Q), m_right(Q) * Q2)], False
        ),
    ),
    Check(
        "57",
        r"\mathcal{M}_{l}(\underline{e}) \,\mathcal{M}_{l}(\underline{e})^{T} = \mathcal{M}_{r}"
        r"(\underline{e}) \,\mathcal{M}_{r}(\underline{e})^{T} = \begin{bmatrix} 1 & \mathbf{0}^{T} \\ "
        r"\mathbf{0} & \mathbf{I} \end{bmatrix}",
        "exact",
        lambda: exact_identity(
            "57", [(m_left(Q) * m_left(Q).T, sp.eye(4)), (m_right(Q) * m_right(Q).T, sp.eye(4))], True
        ),
    ),
    Check(
        "58",
        r"\mathcal{R}(\underline{e}) := \mathcal{M}_l(\underline{e}) \, \mathcal{M}_r(\underline{e})^T "
        r"= \mathcal{M}_r(\underline{e})^T \mathcal{M}_l(\underline{e})",
        "exact",
        lambda: exact_identity(
            "58",
            [(m_left(Q) * m_right(Q).T, m_right(Q).T * m_left(Q))],
            False,
            "the := part defines the 4x4 operator R(e)",
        ),
    ),
    Check(
        "59",
        r"\mathcal{R}(\underline{e}) = \begin{bmatrix} 1 & \mathbf{0}^T \\ \mathbf{0} & \mathbf{R} "
        r"\end{bmatrix}",
        "exact",
        lambda: exact_identity(
            "59", [(m_left(Q) * m_right(Q).T, _embed(rotation51(Q)))], True, "R from (51)"
        ),
    ),
    Check(
        "60",
        r"\underline{e}^* := \begin{bmatrix} e_0 \\ -\mathbf{e} \end{bmatrix}",
        "definition",
        lambda: definition("defines the conjugate; used by (61), (66), (67), (71)-(73)"),
    ),
    Check(
        "61",
        r"\mathcal{M}_{l}(\underline{e}^{*}) \,\mathcal{M}_{r}(\underline{e}^{*})^{T} = \dots"
        r"\begin{bmatrix} 1 & \mathbf{0}^{T} \\ \mathbf{0} & \mathbf{R}^{T} \end{bmatrix}",
        "exact",
        lambda: exact_identity(
            "61",
            [
                (m_left(conjugate(Q)), m_left(Q).T),
                (m_right(conjugate(Q)), m_right(Q).T),
                (
                    m_left(conjugate(Q)) * m_right(conjugate(Q)).T,
                    m_right(conjugate(Q)).T * m_left(conjugate(Q)),
                ),
                (m_right(conjugate(Q)).T * m_left(conjugate(Q)), m_left(Q).T * m_right(Q)),
                (m_left(Q).T * m_right(Q), m_right(Q) * m_left(Q).T),
                (m_right(Q) * m_left(Q).T, _embed(rotation51(Q).T)),
            ],
            True,
            "includes M_l(e*) = M_l(e)^T and M_r(e*) = M_r(e)^T stated before it",
        ),
    ),
    Check(
        "62",
        r"\underline{E} = \frac{1}{4} \begin{bmatrix} 1 + \operatorname{tr}(\mathbf{R}) & 2\operatorname"
        r"{axial}(\mathbf{R})^T \\ 2\operatorname{axial}(\mathbf{R}) & (1 - \operatorname{tr}(\mathbf{R}))"
        r"\mathbf{I} + \mathbf{R} + \mathbf{R}^T \end{bmatrix} = \underline{e} \otimes \underline{e}",
        "exact",
        _eq62,
    ),
    Check(
        "63",
        r"[\underline{E}]_{\mathcal{B}} = \begin{bmatrix} e_0^2 & e_0e_1 & e_0e_2 & e_0e_3\\ \dots "
        r"& e_3^2 \end{bmatrix}",
        "exact",
        lambda: exact_identity(
            "63",
            [(Q * Q.T, sp.Matrix(4, 4, lambda i, j: E[i] * E[j]))],
            False,
            "the printed matrix is e_i e_j entry by entry",
        ),
    ),
    Check("64", r"e_i = \frac{1}{\Delta_k} E_{ik}, \quad i = 0, 1, 2, 3", "symbolic + numeric", _eq64),
    Check(
        "65", r"\Delta_k = \sqrt{E_{kk}}", "definition", lambda: definition("defines Delta_k; used by (64)")
    ),
    Check(
        "text after (65): max",
        r"\max (E_{00}, E_{11}, E_{22}, E_{33}) = \max(\operatorname{tr}(\mathbf{R}), "
        r"R_{11}, R_{22}, R_{33})",
        "exact",
        _max_text,
    ),
    Check(
        "66",
        r"\underline{w} = \mathcal{R}(\underline{e}) \, \underline{v} = \underline{e} \circ \underline{v} "
        r"\circ \underline{e}^*",
        "exact",
        lambda: exact_identity(
            "66",
            [
                (m_left(Q) * m_right(Q).T * PURE, compose(Q, compose(PURE, conjugate(Q)))),
                (m_left(Q) * m_right(Q).T * PURE, sp.Matrix([0, *(rotation51(Q) * sp.Matrix(V[1:]))])),
            ],
            True,
        ),
    ),
    Check(
        "67",
        r"\mathcal{R}(\underline{e}_3)\,\underline{v} = \mathcal{R}(\underline{e}_2)\,\mathcal{R}"
        r"(\underline{e}_1)\,\underline{v} = \dots = \mathcal{R}(\underline{e}_2 \circ \underline{e}_1)\,"
        r"\underline{v}",
        "exact",
        lambda: exact_identity(
            "67",
            [
                (
                    m_left(Q2) * m_right(Q2).T * m_left(Q) * m_right(Q).T * sp.Matrix(V),
                    compose(compose(Q2, compose(compose(Q, sp.Matrix(V)), conjugate(Q))), conjugate(Q2)),
                ),
                (
                    compose(compose(Q2, compose(compose(Q, sp.Matrix(V)), conjugate(Q))), conjugate(Q2)),
                    compose(compose(compose(Q2, Q), sp.Matrix(V)), conjugate(compose(Q2, Q))),
                ),
                (
                    compose(compose(compose(Q2, Q), sp.Matrix(V)), conjugate(compose(Q2, Q))),
                    m_left(compose(Q2, Q)) * m_right(compose(Q2, Q)).T * sp.Matrix(V),
                ),
            ],
            False,
            "for every quaternion v, so e3 = +-(e2 o e1)",
        ),
    ),
]
