"""Generating functions from a required property (Section 3.2, eqs 31–35 and 37).

A property is a relation between p, p′ (``p_prime``), ν (``nu``), ε (``eps``), μ (``mu``),
det H (``det_H``) and φ, with an unknown constant written ``c`` or ``const`` and the family order
``m`` allowed as a number: ``'mu = nu**2/eps'``, ``'det_H = const'``, ``'nu**2 = c*eps'``.
It is parsed by the same AST whitelist as generating functions (never ``sympify``), turned into
an equation for p(φ) with eqs (15), (16), (21), (24), and solved:

* without p′: algebraically for p (e.g. ν² = c ε gives p = sin φ / c);
* with p′: by ``dsolve`` with explicit hints (separable, exact, linear, Bernoulli…), each under
  a time limit (``classify_ode`` alone can take seconds).

Integration constants and c are fixed by p(0) = 0 and the limit condition p/φ → 1 (eq 13),
which ``ics=`` cannot express. Among the returned branches the real, odd one is kept (principal
cube roots become the real cube root), then verified: the property's residual vanishes at 50
digits at several angles and the function validates (odd, κ = 1, analytic). When no closed form
is found, the exact Taylor series of p is computed from a power-series ansatz and returned.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import mpmath
import sympy as sp

from symrot.core.errors import InvalidGeneratingFunction, SymrotError, SymrotTimeout
from symrot.core.functions import RealCbrt, mpmath_namespace
from symrot.core.parsing import PHI, parse_expression
from symrot.core.series_engine import exact_number
from symrot.core.simplify import complexity, simplest
from symrot.core.timeouts import bounded, time_limit
from symrot.core.validation import validate

SOLVE_TIME_LIMIT = 10.0
HINTS = ("separable", "1st_exact", "1st_linear", "Bernoulli", "1st_homogeneous_coeff_best",
         "lie_group")
_P = sp.Function("p")
_C = sp.Symbol("c")
_NAMES = ("p", "p_prime", "nu", "eps", "epsilon", "mu", "det_H", "c", "const")
SERIES_ORDER = 9


class SolveError(SymrotError):
    """A property that cannot be turned into an admissible generating function."""


@dataclass
class Solution:
    property: str
    expression: sp.Expr | None
    """The closed-form p(φ), or None when only the series is known."""
    constant: sp.Expr | None
    """The value of the constant c, when the property has one."""
    taylor: list[sp.Expr] = field(default_factory=list)
    """Exact Taylor coefficients of p (index k ↔ φ^k)."""
    method: str = ""


def property_equation(text: str, m: int | None = None) -> sp.Expr:
    """The property as ``lhs - rhs`` in terms of the unknown function p(φ).

    ``m``, when given, is the value of the name ``m`` (the family order of eq 37), so that
    ``'mu = 1/sqrt(1 - p**2/m**2)'`` can be written literally.
    """
    if not isinstance(text, str) or text.count("=") != 1 or "==" in text:
        raise SolveError("a property is one relation 'LHS = RHS', e.g. 'mu = nu**2/eps'")
    p = _P(PHI)
    p_prime = sp.Derivative(p, PHI)
    nu = 2 * sp.sin(PHI / 2) / p
    eps = 2 * sp.tan(PHI / 2) / p
    mu = 1 / p_prime
    names = {"p": p, "p_prime": p_prime, "nu": nu, "eps": eps, "epsilon": eps, "mu": mu,
             "det_H": mu * nu**2, "c": _C, "const": _C}
    if m is not None:
        if isinstance(m, bool) or not isinstance(m, int) or m < 1:
            raise SolveError(f"the family order m must be a positive integer, not {m!r}")
        names["m"] = sp.Integer(m)
    left, right = text.split("=")
    sides = [parse_expression(side, names) for side in (left, right)]
    equation = sides[0] - sides[1]
    if not equation.has(p):
        raise SolveError("the property does not involve p or the derived functions")
    return equation


def solve_property(text: str, m: int | None = None) -> Solution:
    """Solve ``text`` for the generating function with κ = 1 (see module docstring)."""
    equation = property_equation(text, m)
    p = _P(PHI)
    try:
        with time_limit(SOLVE_TIME_LIMIT, "solving the property"):
            candidates, method = _candidates(equation, p)  # SolveError: no closed form
            for candidate in [c for raw in candidates for c in (raw, _continue_from_the_right(raw))]:
                fixed = _fix_constants(candidate)
                if fixed is None:
                    continue
                expression, constant = fixed
                verified = _verify(equation, expression, constant)
                if verified is not None:
                    return Solution(text, verified, constant,
                                    list(validate(verified).taylor), method)
    except (SymrotTimeout, SolveError):
        pass
    taylor, constant = _series_ansatz(equation)
    return Solution(text, None, constant, taylor, "power-series ansatz (no closed form found)")


def _candidates(equation: sp.Expr, p: sp.Expr) -> tuple[list[sp.Expr], str]:
    derivative = sp.Derivative(p, PHI)
    if not equation.has(derivative):
        roots = sp.solve(sp.numer(sp.together(equation)), p)
        if not roots:
            raise SolveError("the property has no solution for p")
        return list(roots), "algebraic"
    ode = sp.Eq(sp.numer(sp.together(equation.subs(derivative, sp.Symbol("dp")))).subs(
        sp.Symbol("dp"), derivative), 0)
    found: list[sp.Expr] = []
    for hint in HINTS:
        try:
            with time_limit(4.0, f"dsolve ({hint})"):
                solutions = sp.dsolve(ode, p, hint=hint, simplify=False)
        except (SymrotTimeout, ValueError, NotImplementedError, TypeError, AttributeError):
            continue
        for solution in solutions if isinstance(solutions, list) else [solutions]:
            if solution.lhs == p:
                found.append(solution.rhs)
            else:
                try:
                    with time_limit(2.0, "solving an implicit solution"):
                        found.extend(sp.solve(solution, p))
                except (SymrotTimeout, NotImplementedError, ValueError):
                    continue
        if found:
            return found, f"dsolve, hint '{hint}'"
    raise SolveError("no closed-form solution found")


_HALF_ANGLE_REWRITES = (
    lambda x: 1 - 2 * sp.sin(x / 2) ** 2,
    lambda x: 2 * sp.cos(x / 2) ** 2 - 1,
)
_RIGHT_OF_ZERO = sp.Rational(1, 1000)


def _continue_from_the_right(expr: sp.Expr) -> sp.Expr:
    """Analytic continuation of the branch valid just right of φ = 0.

    ``dsolve`` returns forms such as C1 sqrt(cos φ − 1)/sqrt(cos φ + 1), valid for φ > 0 only.
    A square root whose argument is a constant times a perfect square g² (after the half-angle
    rewrites 1 − cos x = 2 sin²(x/2), 1 + cos x = 2 cos²(x/2)) is replaced by √const · ±g with
    the sign that matches just right of 0; |f| likewise becomes ±f.
    """
    replacements: dict[sp.Expr, sp.Expr] = {}
    for power in expr.atoms(sp.Pow):
        if not (power.exp.is_Rational and power.exp.q == 2 and power.base.has(sp.cos)):
            continue
        for rewrite in _HALF_ANGLE_REWRITES:
            base = sp.factor(power.base.replace(sp.cos, rewrite))
            constant, factors = base.as_coeff_mul()
            roots = []
            for factor in factors:
                b, e = factor.as_base_exp()
                if not (e.is_Integer and int(e) % 2 == 0):
                    break
                roots.append(b ** (int(e) // 2))
            else:
                root = sp.sqrt(constant) * sp.Mul(*roots)
                principal = complex(power.base.subs(PHI, _RIGHT_OF_ZERO).evalf() ** sp.Rational(1, 2))
                candidate = complex(root.subs(PHI, _RIGHT_OF_ZERO).evalf())
                sign = 1 if abs(principal - candidate) < abs(principal + candidate) else -1
                replacements[power] = (sign * root) ** (power.exp * 2)
                break
    for absolute in expr.atoms(sp.Abs):
        inside = absolute.args[0]
        value = inside.subs(PHI, _RIGHT_OF_ZERO).evalf()
        if value.is_real and value != 0:
            replacements[absolute] = inside if value > 0 else -inside
    return expr.xreplace(replacements) if replacements else expr


def _real_forms(expr: sp.Expr) -> list[sp.Expr]:
    """The candidate itself and its real-branch rewrites (principal cube root → real one)."""
    expr = sp.expand_complex(expr) if expr.has(sp.I) else expr
    forms = [expr]
    cube_roots = {power: RealCbrt(power.base) ** (power.exp * 3)
                  for power in expr.atoms(sp.Pow) if power.exp.is_Rational and power.exp.q == 3}
    if cube_roots:
        forms.append(expr.xreplace(cube_roots))
    return forms


def _fix_constants(candidate: sp.Expr) -> tuple[sp.Expr, sp.Expr | None] | None:
    """Choose integration constants and c so that p(0) = 0 and p/φ → 1 (eqs 12–13)."""
    free = sorted(candidate.free_symbols - {PHI}, key=str)
    if not free:
        return candidate, None
    conditions = []
    at_zero = sp.limit(candidate, PHI, 0, "+")
    if at_zero != 0:
        conditions.append(at_zero)
    kappa = sp.limit(candidate / PHI, PHI, 0, "+") if not conditions else None
    solutions: list[dict[sp.Symbol, sp.Expr]]
    if conditions:
        zero = sp.solve(conditions, free, dict=True)
        if not zero:
            return None
        for assignment in zero:
            reduced = candidate.subs(assignment)
            rest = sorted(reduced.free_symbols - {PHI}, key=str)
            kappa = sp.limit(reduced / PHI, PHI, 0, "+")
            if not rest:
                return (reduced, None) if kappa == 1 else None
            for values in sp.solve([kappa - 1], rest, dict=True):
                expression = reduced.subs(values)
                if not expression.free_symbols - {PHI}:
                    return expression, {**assignment, **values}.get(_C)
        return None
    solutions = sp.solve([kappa - 1], free, dict=True) if kappa is not None else []
    for values in solutions:
        expression = candidate.subs(values)
        remaining = expression.free_symbols - {PHI}
        if remaining:
            expression = expression.subs({s: 0 for s in remaining if s != _C})
        if not expression.free_symbols - {PHI}:
            return expression, values.get(_C)
    return None


def _verify(equation: sp.Expr, expression: sp.Expr, constant: sp.Expr | None) -> sp.Expr | None:
    """The simplest real, odd, unit-κ form of ``expression`` that satisfies the property."""
    residual_template = equation.subs(_C, constant if constant is not None else 0)
    verified: list[sp.Expr] = []
    for form in _real_forms(_continue_from_the_right(expression)):
        tidy = form.replace(lambda e: isinstance(e, RealCbrt),
                            lambda e: RealCbrt(sp.factor(sp.trigsimp(e.args[0]))))
        for candidate in {simplest(tidy), bounded(1.0, tidy, sp.trigsimp, tidy), tidy}:
            try:
                validated = validate(candidate)
            except (InvalidGeneratingFunction, SymrotError):
                continue
            if validated.kappa != 1:
                continue
            residual = residual_template.subs(_P(PHI), candidate).doit()
            f = sp.lambdify(PHI, residual, modules=[mpmath_namespace(), "mpmath"])
            with mpmath.workdps(50):
                if all(abs(f(mpmath.mpf(a))) < mpmath.mpf(10) ** -35 for a in ("0.31", "0.77", "1.19")):
                    verified.append(candidate)
    return min(verified, key=complexity) if verified else None


def _series_ansatz(equation: sp.Expr) -> tuple[list[sp.Expr], sp.Expr | None]:
    """Odd ansatz p = φ + a3 φ³ + … solved order by order (bounded)."""
    coefficients = [sp.Symbol(f"a{k}") for k in range(3, SERIES_ORDER + 1, 2)]
    ansatz = PHI + sum(a * PHI**k for a, k in zip(coefficients, range(3, SERIES_ORDER + 1, 2),
                                                 strict=True))
    unknowns = [*coefficients, _C] if equation.has(_C) else list(coefficients)
    try:
        with time_limit(SOLVE_TIME_LIMIT, "power-series ansatz"):
            residual = sp.together(equation.subs(_P(PHI), ansatz).doit())
            numerator = sp.numer(residual)
            series = sp.series(numerator, PHI, 0, SERIES_ORDER + 1).removeO()
            conditions = [series.coeff(PHI, k) for k in range(SERIES_ORDER + 1)]
            conditions = [c for c in conditions if c != 0]
            solutions = sp.solve(conditions, unknowns, dict=True)
    except SymrotTimeout:
        raise SolveError("no closed form and the power-series ansatz timed out") from None
    if not solutions:
        raise SolveError("the property admits no odd generating function with kappa = 1")
    solution = solutions[0]
    taylor = [sp.S.Zero, sp.S.One] + [sp.S.Zero] * (SERIES_ORDER - 1)
    for a, k in zip(coefficients, range(3, SERIES_ORDER + 1, 2), strict=True):
        taylor[k] = exact_number(solution.get(a, a))
    return taylor, solution.get(_C)
