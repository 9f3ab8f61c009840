"""Appendix C, rotation vector and exponential map: eqs (86)–(91) and the text around them.

Power series of (φ×) are compared in the axial-tensor algebra: (φ×)^k = φ^k U^k with
U^(2j+1) = (−1)^j U and U^(2j) = (−1)^(j−1) U² (j ≥ 1), so a series in (φ×) is a triple of power
series in φ on I, U, U², compared exactly (rational coefficients) with the exact Taylor series of
the core's tensors for p = φ (:mod:`symrot.core.series`), and summed numerically at 60 digits.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import mpmath
import sympy as sp

from symrot.audit.claims import Claim, dual_outcome, settle
from symrot.audit.numeric import (
    TOLERANCE,
    fmt,
    precision,
    random_angle,
    random_axis,
    relative,
    rng,
    rotation,
    skew,
)
from symrot.audit.proof import NU, U_VECTOR, P
from symrot.audit.records import ERRATUM, HOLDS, AuditInconsistency, Check, Outcome, definition
from symrot.core.derivation import root_tangent, root_tensor
from symrot.core.parsing import PHI
from symrot.core.series import coefficient_list, taylor_series

ORDER = 24
"""Exact series comparisons through φ^(ORDER − 1)."""
SAMPLES = 4


def u_power(k: int) -> tuple[int, int, int]:
    """U^k = a I + b U + c U² for U = (u×), |u| = 1 (U³ = −U)."""
    if k == 0:
        return (1, 0, 0)
    if k % 2:
        return (0, (-1) ** ((k - 1) // 2), 0)
    return (0, 0, (-1) ** (k // 2 - 1))


def series_triple(coefficient: Callable[[int], sp.Expr], terms: int) -> list[list[sp.Expr]]:
    """Σ_k coefficient(k) (φ×)^k as three coefficient lists in φ (index = power of φ)."""
    triple = [[sp.S.Zero] * terms for _ in range(3)]
    for k in range(terms):
        for slot, weight in enumerate(u_power(k)):
            triple[slot][k] += weight * coefficient(k)
    return triple


def taylor_triple(a: sp.Expr, b: sp.Expr, c: sp.Expr, terms: int) -> list[list[sp.Expr]]:
    return [coefficient_list(taylor_series(x, terms), 0, terms) for x in (a, b, c)]


def _first_difference(left: list[list[sp.Expr]], right: list[list[sp.Expr]]) -> str | None:
    names = ("I", "(u x)", "(u x)^2")
    for power in range(len(left[0])):
        for slot in range(3):
            if sp.nsimplify(left[slot][power] - right[slot][power]) != 0:
                return (
                    f"coefficient of phi^{power} {names[slot]}: printed {left[slot][power]}, "
                    f"exact {right[slot][power]}"
                )
    return None


def _numeric_sum(
    coefficient: Callable[[int], sp.Expr],
    terms: int,
    truth: Callable[[mpmath.mpf, Any], mpmath.matrix],
    bound: float,
    label: str,
) -> mpmath.mpf:
    worst = mpmath.mpf(0)
    with precision():
        values = [
            mpmath.mpf(sp.Rational(coefficient(k)).p) / sp.Rational(coefficient(k)).q for k in range(terms)
        ]
        r = rng(label)
        for _ in range(SAMPLES):
            phi, u = random_angle(r, bound), random_axis(r)
            a = phi * skew(u)
            total, power = mpmath.zeros(3), mpmath.eye(3)
            for k in range(terms):
                total += values[k] * power
                power = power * a
            exact = truth(phi, u)
            worst = max(worst, relative(total - exact, exact))
    return worst


def _core_matrix(tensor: Any) -> Callable[[mpmath.mpf, Any], mpmath.matrix]:
    functions = [sp.lambdify(PHI, x, "mpmath") for x in (tensor.a, tensor.b, tensor.c)]

    def at(phi: mpmath.mpf, u: Any) -> mpmath.matrix:
        k = skew(u)
        return functions[0](phi) * mpmath.eye(3) + functions[1](phi) * k + functions[2](phi) * k * k

    return at


def _series_claim(
    label: str, coefficient: Callable[[int], sp.Expr], tensor: Any, bound: float, terms: int = 160
) -> tuple[str | None, mpmath.mpf]:
    printed = series_triple(coefficient, ORDER)
    exact = taylor_triple(tensor.a, tensor.b, tensor.c, ORDER)
    return _first_difference(printed, exact), _numeric_sum(
        coefficient, terms, _core_matrix(tensor), bound, label
    )


def _eq87() -> Outcome:
    difference, worst = _series_claim("87", lambda k: 1 / sp.factorial(k), root_tensor(PHI, 1), 6.0)
    if difference or worst > TOLERANCE:
        raise AuditInconsistency(f"(87): {difference} {fmt(worst)}")
    return Outcome(
        HOLDS,
        f"exact: the series equals eq (14) for p = phi through phi^{ORDER - 1} (I, U, U^2 "
        f"coefficients); numeric: 160 terms at {SAMPLES} random |phi| < 6, relative residual < 1e-45",
    )


def _eq88() -> Outcome:
    worst = mpmath.mpf(0)
    with precision():
        r = rng("88")
        for _ in range(SAMPLES):
            phi, u = random_angle(r, 3.1), random_axis(r)
            logarithm = mpmath.logm(rotation(phi, u))
            axial = mpmath.matrix([logarithm[2, 1], logarithm[0, 2], logarithm[1, 0]])
            worst = max(worst, relative(axial - phi * u, phi * u))
    if worst > TOLERANCE:
        raise AuditInconsistency(f"(88) residual {fmt(worst)}")
    return Outcome(
        HOLDS,
        "numeric: axial of the principal matrix logarithm (mpmath.logm) of R(phi, u) is phi u, "
        f"relative residual < 1e-45 at {SAMPLES} random |phi| < 3.1 (principal value, |phi| < pi)",
    )


def _log_partial(phi: mpmath.mpf, u: Any, terms: int) -> tuple[mpmath.matrix, mpmath.mpf]:
    """−Σ_{k ≤ terms} (I − R)^k / k and the norm of its last term."""
    a = mpmath.eye(3) - rotation(phi, u)
    total, power = mpmath.zeros(3), mpmath.eye(3)
    for k in range(1, terms + 1):
        power = power * a
        total -= power / k
    return total, max(abs(x) for x in power) / terms


def _eq89() -> Outcome:
    with precision():
        r = rng("89")
        worst = mpmath.mpf(0)
        for _ in range(SAMPLES):
            phi, u = random_angle(r, 1.0), random_axis(r)
            total, _ = _log_partial(phi, u, 600)
            worst = max(worst, relative(total - phi * skew(u), phi * skew(u)))
        u = random_axis(r)
        _, term_30 = _log_partial(mpmath.pi / 2, u, 30)
        _, term_60 = _log_partial(mpmath.pi / 2, u, 60)
    radius = sp.simplify(
        sp.expand_complex(sp.Abs(1 - sp.exp(sp.I * PHI)) ** 2).rewrite(sp.cos) - 4 * sp.sin(PHI / 2) ** 2
    )
    corrected = dual_outcome(
        "89:corrected",
        lambda o, phi, u: phi / (2 * o.sin(phi)) * (_rot(o, phi, u) - _rot(o, phi, u).T),
        lambda o, phi, u: phi * o.skew(u),
        bound=3.1,
    )
    if (
        worst > TOLERANCE
        or term_60 < 1e6
        or term_60 < term_30
        or sp.simplify(radius) != 0
        or corrected.status != HOLDS
    ):
        raise AuditInconsistency("(89) check inconsistent")
    return Outcome(
        ERRATUM,
        "I - R has eigenvalues 0 and 1 - exp(±i phi), of modulus 2|sin(phi/2)| (|1 - "
        "exp(i phi)|^2 = 4 sin^2(phi/2), symbolic): the series converges only for |phi| <= pi/3, "
        "not on the principal range |phi| < pi that the text requires. Numeric: for |phi| < 1 "
        "600 terms give (phi x) (relative residual < 1e-45, consistent with (88)); at phi = pi/2 "
        f"the k-th term has size {fmt(term_30, 6)} at k = 30 and {fmt(term_60, 6)} at k = 60 "
        "(diverges). Corrected form for |phi| < pi: log(R) = phi/(2 sin phi) (R - R^T) = (phi x): "
        f"{corrected.evidence}",
        r"\log(\mathbf{R}) := -\sum_{k=1}^{\infty} \frac{1}{k} (\mathbf{I} - \mathbf{R})^k "
        r"\text{ only for } |\varphi| \le \pi/3; \text{ for } |\varphi| < \pi: \log(\mathbf{R}) = "
        r"\frac{\varphi}{2\sin\varphi}(\mathbf{R} - \mathbf{R}^T)",
    )


def _rot(ops: Any, phi: Any, u: Any) -> Any:
    k = ops.skew(u)
    return ops.eye() + ops.sin(phi) * k + (1 - ops.cos(phi)) * k * k


def _after86() -> Outcome:
    printed_nu, printed_eps = 2 * sp.sin(PHI) / PHI, 2 * sp.tan(PHI) / PHI
    mu = settle("86:mu", Claim(sp.Integer(1), 1 / sp.diff(PHI, PHI), p=PHI))
    nu = settle(
        "86:nu",
        Claim(NU, printed_nu, p=PHI),
        (r"\nu = 2\sin(\varphi/2)/\varphi", Claim(NU, 2 * sp.sin(PHI / 2) / PHI, p=PHI)),
    )
    eps = settle(
        "86:eps",
        Claim(2 * sp.tan(PHI / 2) / P, printed_eps, p=PHI),
        (
            r"\varepsilon = 2\tan(\varphi/2)/\varphi",
            Claim(2 * sp.tan(PHI / 2) / P, 2 * sp.tan(PHI / 2) / PHI, p=PHI),
        ),
    )
    limit = coefficient_list(taylor_series(printed_nu, 1), 0, 1)[0]
    if mu.status != HOLDS or nu.status != ERRATUM or eps.status != ERRATUM:
        raise AuditInconsistency("(86) statements")
    return Outcome(
        ERRATUM,
        f"mu = 1 holds. Read literally, nu = 2 sin(phi)/phi tends to {limit} at phi -> 0 "
        "while nu -> 1 (eq 15 with kappa = 1), and at phi = pi it is 0 instead of 2/pi; "
        f"nu: {nu.evidence}; eps: {eps.evidence}",
        r"\mu = 1, \nu = 2 \sin(\varphi/2)/\varphi, \varepsilon = 2 \tan(\varphi/2)/\varphi "
        r"\text{ (as in Table 1)}",
    )


def _after89() -> Outcome:
    e_vector = sp.sin(PHI / 2) * U_VECTOR
    return settle(
        "89:text",
        Claim(e_vector / NU, PHI * U_VECTOR, p=PHI),
        (r"\boldsymbol{\varphi} = 2\mathbf{e}/\nu", Claim(2 * e_vector / NU, PHI * U_VECTOR, p=PHI)),
    )


def _eq90() -> Outcome:
    difference, worst = _series_claim("90", lambda k: 1 / sp.factorial(k + 1), root_tangent(PHI, 1), 6.0)
    if difference or worst > TOLERANCE:
        raise AuditInconsistency(f"(90): {difference} {fmt(worst)}")
    return Outcome(
        HOLDS,
        f"exact: the series equals the core's H for p = phi through phi^{ORDER - 1}; numeric: "
        f"160 terms at {SAMPLES} random |phi| < 6, relative residual < 1e-45",
    )


def bernoulli(n: int) -> sp.Rational:
    """B_n with B_1 = −1/2 (Abramowitz & Stegun [34], 23.1); SymPy ≥ 1.12 uses B_1 = +1/2."""
    return sp.Rational(-1, 2) if n == 1 else sp.bernoulli(n)


def _printed91(k: int) -> sp.Expr:
    """(91) as printed: I − ½(φ×) − Σ_{k≥1} B_k/(2k)! (φ×)^k, coefficient of (φ×)^k."""
    if k == 0:
        return sp.S.One
    return (sp.Rational(-1, 2) if k == 1 else 0) - bernoulli(k) / sp.factorial(2 * k)


def _corrected91(k: int) -> sp.Expr:
    """I − ½(φ×) + Σ_{k≥1} B_{2k}/(2k)! (φ×)^{2k}."""
    if k == 0:
        return sp.S.One
    if k == 1:
        return sp.Rational(-1, 2)
    return bernoulli(k) / sp.factorial(k) if k % 2 == 0 else sp.S.Zero


def _old_convention91(k: int) -> sp.Expr:
    """(91) read with the older convention B*_k = |B_2k| (B*_1 = 1/6, B*_2 = 1/30, ...)."""
    if k == 0:
        return sp.S.One
    return (sp.Rational(-1, 2) if k == 1 else 0) - abs(sp.bernoulli(2 * k)) / sp.factorial(2 * k)


def _eq91() -> Outcome:
    inverse = root_tangent(PHI, 1).inverse()
    exact = taylor_triple(inverse.a, inverse.b, inverse.c, ORDER)
    printed = _first_difference(series_triple(_printed91, ORDER), exact)
    old = _first_difference(series_triple(_old_convention91, ORDER), exact)
    fixed = _first_difference(series_triple(_corrected91, ORDER), exact)
    worst = _numeric_sum(_corrected91, 220, _core_matrix(inverse), 3.0, "91")
    if printed is None or old is None or fixed is not None or worst > TOLERANCE:
        raise AuditInconsistency(f"(91) check inconsistent: {printed} {old} {fixed} {fmt(worst)}")
    return Outcome(
        ERRATUM,
        f"exact series against the core's H^-1 for p = phi: as printed (B_1 = -1/2, "
        f"B_2 = 1/6, ...) the first wrong term is the {printed}; with the older convention "
        f"B*_k = |B_2k| the {old}. Corrected form: exact through phi^{ORDER - 1}, and 220 terms "
        f"at {SAMPLES} random |phi| < 3 (the series converges for |phi| < 2 pi) give H^-1 with "
        "relative residual < 1e-45",
        r"\mathbf{S}^{-1} = \mathbf{I} - \frac{1}{2} (\boldsymbol{\varphi} \times) + \sum_{k=1}^"
        r"{\infty} \frac{B_{2k}}{(2k)!} (\boldsymbol{\varphi} \times)^{2k} \quad (B_2 = 1/6, "
        r"B_4 = -1/30, \dots)",
    )


CHECKS = [
    Check(
        "86",
        r"\boldsymbol{\varphi} = \boldsymbol{\varphi} \, \mathbf{u}",
        "definition",
        lambda: definition("names the rotation vector p = phi u (eq 30); used by (87)-(91)"),
    ),
    Check(
        "text after (86): mu, nu, eps",
        r"\mu = 1, \nu = 2 \sin \varphi/\varphi, \text{ and } "
        r"\varepsilon = 2 \tan \varphi/\varphi",
        "symbolic + numeric",
        _after86,
    ),
    Check(
        "87",
        r"\mathbf{R} = \exp(\boldsymbol{\varphi} \times) := \sum_{k=0}^{\infty} \frac{(\boldsymbol"
        r"{\varphi} \times)^k}{k!}",
        "exact series + numeric",
        _eq87,
    ),
    Check("88", r"\boldsymbol{\varphi} = \operatorname{axial}(\log(\mathbf{R}))", "numeric", _eq88),
    Check(
        "89",
        r"\log(\mathbf{R}) := -\sum_{k=1}^{\infty} \frac{1}{k} (\mathbf{I} - \mathbf{R})^k",
        "symbolic + numeric",
        _eq89,
    ),
    Check(
        "text after (89): phi = e/nu",
        r"\boldsymbol{\varphi} = \mathbf{e}/\nu",
        "symbolic + numeric",
        _after89,
    ),
    Check(
        "90",
        r"\mathbf{S} = \operatorname{dexp}(\boldsymbol{\varphi} \times) := \sum_{k=0}^{\infty} "
        r"\frac{(\boldsymbol{\varphi} \times)^k}{(k+1)!}",
        "exact series + numeric",
        _eq90,
    ),
    Check(
        "91",
        r"\mathbf{S}^{-1} = \operatorname{dexp}^{-1}(\boldsymbol{\varphi} \times) := \mathbf{I} - "
        r"\frac{1}{2} \left( \boldsymbol{\varphi} \times \right) - \sum_{k=1}^{\infty} \frac{B_k}{(2\,k)!} "
        r"\left( \boldsymbol{\varphi} \times \right)^k",
        "exact series + numeric",
        _eq91,
    ),
]
