"""The series engine: exact truncated power series of an expression in φ, by walking its tree.

``sympy.series``/``limit`` on composed expressions such as (1/ε − 1/μ)/p² can run for minutes.
This engine never calls them: it walks the expression tree and combines exact truncated Laurent
series with SymPy's ``ring_series`` primitives (``rs_mul``, ``rs_sin``, ``rs_exp``, ``rs_log``,
``rs_pow``, ``rs_series_inversion``...) over QQ, switching the whole computation to the EX domain
only when a coefficient is not rational (e.g. p = sin(π φ)/π). Cost is polynomial in the order.

Real semantics are enforced: a branch point at φ = 0 (``sqrt(phi)``, ``sqrt(phi**2) = |phi|``,
``log(phi)``) or an essential singularity raises :class:`NonAnalyticError`; a function that is
complex on one side of 0 raises :class:`InvalidGeneratingFunction`.

Callers use :mod:`symrot.core.series` (``taylor_series`` and the reversion and composition helpers).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from functools import lru_cache
from typing import Any

import sympy as sp
from sympy.polys.domains import EX, QQ
from sympy.polys.polyerrors import CoercionFailed
from sympy.polys.ring_series import (
    rs_cos,
    rs_exp,
    rs_log,
    rs_mul,
    rs_pow,
    rs_series_inversion,
    rs_sin,
    rs_trunc,
)
from sympy.polys.rings import PolyElement, PolyRing, ring

from symrot.core.errors import InvalidGeneratingFunction, NonAnalyticError, SymrotError
from symrot.core.functions import RealCbrt
from symrot.core.parsing import PHI


def exact_number(value: sp.Expr) -> sp.Expr:
    """``value`` with SymPy's nsimplify applied unless it is already a Rational.

    nsimplify cleans up exact expressions that the EX domain leaves unevaluated, but on a large
    exact Rational it can return a *different*, irrational number: nsimplify(1300075/226492416)
    gives 2·2^(248/347)·3^(164/347)·5^(224/347)·7^(145/347)/6125 (equal to 15 digits only), which
    made the series of pi/2 − acos(φ) wrong at φ^27 and its planning run past every budget."""
    return value if value.is_Rational else sp.nsimplify(value)


Coefficient = Any  # an element of QQ or EX


class NeedsSymbolicDomain(Exception):
    """A coefficient is not rational: :func:`symrot.core.series.taylor_series` restarts over EX."""


class InsufficientOrder(SymrotError):
    """Internal: cancellation ate the requested order; the caller retries with more terms."""


@lru_cache(maxsize=2)
def series_ring(domain_name: str) -> tuple[PolyRing, PolyElement]:
    """The polynomial ring in x over QQ or EX (``domain_name``) and its generator."""
    domain = QQ if domain_name == "QQ" else EX
    return ring("x", domain)


@dataclass(frozen=True)
class Series:
    """``x**shift * poly + O(x**order)``; ``poly`` has a non-zero constant term unless zero."""

    poly: PolyElement
    shift: int
    order: int

    @property
    def ring(self) -> PolyRing:
        return self.poly.ring

    @property
    def x(self) -> PolyElement:
        return self.ring.gens[0]

    @property
    def is_zero(self) -> bool:
        return not self.poly

    @property
    def valuation(self) -> int:
        """Lowest exponent with a non-zero coefficient (raises if the series is zero so far)."""
        if self.is_zero:
            raise InsufficientOrder("series is zero to its order; cannot find its leading term")
        return self.shift

    def leading_coefficient(self) -> Coefficient:
        self.valuation  # noqa: B018 - raises when unknown
        return self.poly.coeff(1)

    def coefficient(self, k: int) -> Coefficient:
        """Exact coefficient of x**k (k must be below the order)."""
        if k >= self.order:
            raise InsufficientOrder(f"coefficient x^{k} is beyond the known order {self.order}")
        if k < self.shift:
            return self.ring.domain.zero
        return self.poly.coeff(self.x ** (k - self.shift)) if k > self.shift else self.poly.coeff(1)

    def coefficients(self, start: int, stop: int) -> list[Coefficient]:
        return [self.coefficient(k) for k in range(start, stop)]

    def constant_term(self) -> Coefficient:
        if self.shift < 0 and not self.is_zero:
            raise NonAnalyticError("expression has a pole at phi = 0")
        return self.coefficient(0)


def _make(poly: PolyElement, shift: int, order: int) -> Series:
    """Normalize: move the lowest power of poly into shift and truncate at ``order``."""
    if order - shift <= 0:
        return Series(poly.ring.zero, order, order)
    poly = rs_trunc(poly, poly.ring.gens[0], order - shift)
    if not poly:
        return Series(poly, order, order)
    low = min(monom[0] for monom in poly.monoms())
    if low:
        poly = poly.ring({(m[0] - low,): c for m, c in poly.terms()})
    return Series(poly, shift + low, order)


class SeriesEngine:
    """Computes truncated series of SymPy expressions in :data:`PHI` about 0.

    ``order`` is the working truncation: leaves are exact up to x**order. Results carry their
    own (possibly smaller) order after cancellations; callers check it.
    """

    def __init__(self, order: int, domain_name: str = "QQ") -> None:
        self.order = order
        self.domain_name = domain_name
        self.ring, self.x = series_ring(domain_name)
        self.domain = self.ring.domain
        self._cache: dict[sp.Expr, Series] = {}

    # -- entry point ---------------------------------------------------------------------
    def series(self, expr: sp.Expr) -> Series:
        cached = self._cache.get(expr)
        if cached is None:
            cached = self._build(expr)
            self._cache[expr] = cached
        return cached

    # -- elementary constructions ---------------------------------------------------------
    def constant(self, value: sp.Expr) -> Series:
        try:
            element = self.domain.from_sympy(sp.nsimplify(value) if value.is_Float else value)
        except CoercionFailed:
            raise NeedsSymbolicDomain from None
        return _make(self.ring(element), 0, self.order)

    def _from_element(self, element: Coefficient) -> Series:
        return _make(self.ring(element), 0, self.order)

    def _to_element(self, value: sp.Expr) -> Coefficient:
        try:
            return self.domain.from_sympy(value)
        except CoercionFailed:
            raise NeedsSymbolicDomain from None

    def add(self, a: Series, b: Series) -> Series:
        order = min(a.order, b.order)
        if a.is_zero:
            return _make(b.poly, b.shift, order) if not b.is_zero else _make(b.poly, order, order)
        if b.is_zero:
            return _make(a.poly, a.shift, order)
        low = min(a.shift, b.shift)
        poly = a.poly * self.x ** (a.shift - low) + b.poly * self.x ** (b.shift - low)
        return _make(poly, low, order)

    def scale(self, a: Series, factor: Coefficient) -> Series:
        return _make(a.poly * factor, a.shift, a.order) if factor else self.zero_like(a.order)

    def zero_like(self, order: int) -> Series:
        return Series(self.ring.zero, order, order)

    def mul(self, a: Series, b: Series) -> Series:
        if a.is_zero or b.is_zero:
            order = min(a.order + (b.shift if not b.is_zero else b.order),
                        b.order + (a.shift if not a.is_zero else a.order))
            return self.zero_like(order)
        order = min(a.order + b.shift, b.order + a.shift)
        shift = a.shift + b.shift
        if order - shift <= 0:
            return self.zero_like(order)
        return _make(rs_mul(a.poly, b.poly, self.x, order - shift), shift, order)

    def inverse(self, a: Series) -> Series:
        relative = a.order - a.valuation
        poly = rs_series_inversion(a.poly, self.x, relative)
        return _make(poly, -a.shift, -a.shift + relative)

    def integer_power(self, a: Series, n: int) -> Series:
        if n == 0:
            return self._from_element(self.domain.one)
        if n < 0:
            return self.inverse(self.integer_power(a, -n))
        if a.is_zero:
            return self.zero_like(a.order + (n - 1) * a.order)
        relative = a.order - a.shift
        return _make(rs_pow(a.poly, n, self.x, relative), n * a.shift, n * a.shift + relative)

    def unit_power(self, u: Series, r: sp.Rational) -> Series:
        """(1 + h)**r for u = 1 + h with h(0) = 0 (binomial series, exact)."""
        return _make(rs_pow(u.poly, r, self.x, u.order), 0, u.order)

    def rational_power(self, a: Series, r: sp.Rational, real_odd_root: bool) -> Series:
        """a**r. ``real_odd_root`` selects the real root (cbrt) instead of the principal one."""
        if r.q == 1:
            return self.integer_power(a, int(r))
        valuation = a.valuation
        lead = self.domain.to_sympy(a.leading_coefficient())
        new_shift = valuation * r
        if not new_shift.is_integer:
            raise NonAnalyticError(
                f"a power x^{valuation} raised to {r} has a branch point at phi = 0"
            )
        if real_odd_root:
            if r.q % 2 == 0:
                raise NonAnalyticError("real odd root with even index")
            lead_root = sp.sign(lead) * sp.Abs(lead) ** r
        else:
            if not lead.is_positive or valuation % 2:
                raise InvalidGeneratingFunction(
                    f"a power ^{r} of a quantity that is negative near phi = 0 is not real "
                    "(use cbrt for a real cube root)"
                )
            if int(new_shift) % 2:
                raise NonAnalyticError(
                    f"a power ^{r} gives |phi|^{new_shift}, which is not analytic at phi = 0"
                )
            lead_root = lead**r
        unit = self.domain.one / a.leading_coefficient()
        normalized = self.scale(Series(a.poly, 0, a.order - a.shift), unit)
        root = self.unit_power(normalized, r)
        root = self.scale(root, self._to_element(exact_number(lead_root)))
        return _make(root.poly, int(new_shift), int(new_shift) + root.order)

    def derivative(self, a: Series) -> Series:
        if a.is_zero:
            return self.zero_like(a.order - 1)
        terms: dict[tuple[int], Coefficient] = {}
        for (k,), c in a.poly.terms():
            exponent = k + a.shift
            if exponent != 0:
                terms[(exponent - 1 - (a.shift - 1),)] = c * exponent
        return _make(self.ring(terms), a.shift - 1, a.order - 1)

    def integral(self, a: Series, constant: Coefficient) -> Series:
        terms: dict[tuple[int], Coefficient] = {}
        if not a.is_zero:
            for (k,), c in a.poly.terms():
                exponent = k + a.shift
                if exponent == -1:
                    raise NonAnalyticError("expression has a logarithmic singularity at phi = 0")
                terms[(exponent + 1,)] = c / (exponent + 1)
        poly = self.ring(terms) + self.ring(constant)
        return _make(poly, 0, a.order + 1)

    def _split_constant(self, a: Series) -> tuple[sp.Expr, Series]:
        """f = c0 + g with g(0) = 0; raises for negative valuation (essential singularity)."""
        if not a.is_zero and a.shift < 0:
            raise NonAnalyticError("a transcendental function of a pole has an essential singularity")
        c0 = a.constant_term()
        g = self.add(a, self._from_element(-c0))
        return self.domain.to_sympy(c0), g

    def _poly_function(self, rs_func: Callable[..., PolyElement], g: Series) -> Series:
        """Apply an rs_* primitive to g with g(0) = 0."""
        if g.is_zero:
            return _make(rs_func(self.ring.zero, self.x, g.order), 0, g.order)
        shifted = g.poly * self.x**g.shift
        return _make(rs_func(shifted, self.x, g.order), 0, g.order)

    # -- elementary functions ---------------------------------------------------------------
    def exp(self, a: Series) -> Series:
        c0, g = self._split_constant(a)
        return self.scale(self._poly_function(rs_exp, g), self._to_element(sp.exp(c0)))

    def sin_cos(self, a: Series) -> tuple[Series, Series]:
        c0, g = self._split_constant(a)
        sin_g, cos_g = self._poly_function(rs_sin, g), self._poly_function(rs_cos, g)
        if c0 == 0:
            return sin_g, cos_g
        s0, k0 = self._to_element(sp.sin(c0)), self._to_element(sp.cos(c0))
        sin_f = self.add(self.scale(cos_g, s0), self.scale(sin_g, k0))
        cos_f = self.add(self.scale(cos_g, k0), self.scale(sin_g, -s0))
        return sin_f, cos_f

    def log(self, a: Series) -> Series:
        c0, g = self._split_constant(a)
        if c0 == 0:
            raise NonAnalyticError("log of a quantity that vanishes at phi = 0")
        if not c0.is_positive:
            raise InvalidGeneratingFunction("log of a negative quantity is not real")
        unit = self.scale(self.add(g, self._from_element(self._to_element(c0))),
                          self._to_element(1 / c0))
        series = self._poly_function(lambda p, x, n: rs_log(1 + p, x, n),
                                     self.add(unit, self._from_element(-self.domain.one)))
        return self.add(series, self._from_element(self._to_element(sp.log(c0))))

    def by_derivative(self, a: Series, value_at_c0: sp.Expr, derivative: Series) -> Series:
        """F(f) = F(c0) + ∫ F'(f) f' dphi, for inverse functions with algebraic derivatives."""
        integrand = self.mul(derivative, self.derivative(a))
        return self.integral(integrand, self._to_element(value_at_c0))

    # -- tree walk -------------------------------------------------------------------------------
    def _build(self, expr: sp.Expr) -> Series:
        if expr == PHI:
            return _make(self.x, 0, self.order)
        if expr.is_Number or (expr.is_number and not expr.free_symbols):
            if expr.has(sp.zoo, sp.nan, sp.oo) or not expr.is_extended_real:
                raise InvalidGeneratingFunction(f"constant {expr} is not a real number")
            return self.constant(expr)
        if expr.free_symbols - {PHI}:
            raise SymrotError(f"unexpected symbols {sorted(map(str, expr.free_symbols - {PHI}))}")
        if isinstance(expr, sp.Add):
            total = self.series(expr.args[0])
            for term in expr.args[1:]:
                total = self.add(total, self.series(term))
            return total
        if isinstance(expr, sp.Mul):
            product = self.series(expr.args[0])
            for factor in expr.args[1:]:
                product = self.mul(product, self.series(factor))
            return product
        if isinstance(expr, sp.Pow):
            exponent = expr.exp
            if not exponent.is_Rational:
                raise NonAnalyticError(f"power with non-constant or irrational exponent: {expr}")
            return self.rational_power(self.series(expr.base), sp.Rational(exponent), False)
        if isinstance(expr, RealCbrt):
            return self.rational_power(self.series(expr.args[0]), sp.Rational(1, 3), True)
        if isinstance(expr, sp.Abs | sp.sign):
            return self._abs_or_sign(expr, self.series(expr.args[0]))
        if isinstance(expr, sp.Function) and len(expr.args) == 1:
            return self._function(expr, self.series(expr.args[0]))
        raise SymrotError(f"the series engine cannot expand {type(expr).__name__}: {expr}")

    def _function(self, expr: sp.Expr, a: Series) -> Series:
        one = self._from_element(self.domain.one)
        if isinstance(expr, sp.exp):
            return self.exp(a)
        if isinstance(expr, sp.sin | sp.cos | sp.tan | sp.cot | sp.sec | sp.csc):
            return self._trigonometric(expr, a)
        if isinstance(expr, sp.sinh | sp.cosh | sp.tanh):
            e_plus, e_minus = self.exp(a), self.exp(self.scale(a, -self.domain.one))
            sinh = self.scale(self.add(e_plus, self.scale(e_minus, -self.domain.one)),
                              self.domain.one / 2)
            cosh = self.scale(self.add(e_plus, e_minus), self.domain.one / 2)
            if isinstance(expr, sp.sinh):
                return sinh
            if isinstance(expr, sp.cosh):
                return cosh
            return self.mul(sinh, self.inverse(cosh))
        if isinstance(expr, sp.coth | sp.csch):  # SymPy writes tanh(x + i pi/2) this way
            numerator = self.scale(self.add(self.exp(a), self.exp(self.scale(a, -self.domain.one))),
                                   self.domain.one / 2) if isinstance(expr, sp.coth) else one
            sinh_f = self.scale(self.add(self.exp(a), self.scale(self.exp(self.scale(
                a, -self.domain.one)), -self.domain.one)), self.domain.one / 2)
            return self.mul(numerator, self.inverse(sinh_f))
        if isinstance(expr, sp.log):
            return self.log(a)
        c0, _ = self._split_constant(a)
        square = self.mul(a, a)
        minus_one = self.scale(one, -self.domain.one)
        half = sp.Rational(-1, 2)
        if isinstance(expr, sp.asin | sp.acos):
            if not abs(c0) < 1:
                raise NonAnalyticError(f"{type(expr).__name__} at its branch point or outside [-1, 1]")
            root = self.rational_power(self.add(one, self.scale(square, -self.domain.one)), half, False)
            sign = 1 if isinstance(expr, sp.asin) else -1
            return self.by_derivative(a, type(expr)(c0), self.scale(root, self.domain.one * sign))
        if isinstance(expr, sp.atan):
            return self.by_derivative(a, sp.atan(c0), self.inverse(self.add(one, square)))
        if isinstance(expr, sp.asinh):
            root = self.rational_power(self.add(one, square), half, False)
            return self.by_derivative(a, sp.asinh(c0), root)
        if isinstance(expr, sp.acosh):
            if not c0 > 1:
                raise NonAnalyticError("acosh at its branch point or below 1")
            root = self.rational_power(self.add(square, minus_one), half, False)
            return self.by_derivative(a, sp.acosh(c0), root)
        if isinstance(expr, sp.atanh):
            if not abs(c0) < 1:
                raise NonAnalyticError("atanh at its pole or outside (-1, 1)")
            return self.by_derivative(
                a, sp.atanh(c0), self.inverse(self.add(one, self.scale(square, -self.domain.one)))
            )
        raise SymrotError(f"the series engine has no rule for {type(expr).__name__}")

    def _trigonometric(self, expr: sp.Expr, a: Series) -> Series:
        """sin, cos and their quotients (SymPy turns tan(pi/2 + phi) into -cot(phi)); a pole of
        cot or csc at 0 is a Laurent term, so that the caller reports the pole of p itself."""
        sin_f, cos_f = self.sin_cos(a)
        name = type(expr).__name__
        if isinstance(expr, sp.sin | sp.cos):
            return sin_f if isinstance(expr, sp.sin) else cos_f
        if isinstance(expr, sp.tan | sp.sec):
            inverse_cos = self._inverse_checked(cos_f, f"{name} has a pole at phi = 0")
            return self.mul(sin_f, inverse_cos) if isinstance(expr, sp.tan) else inverse_cos
        inverse_sin = self.inverse(sin_f)  # a Laurent series: phi**2*cot(phi) is analytic
        return self.mul(cos_f, inverse_sin) if isinstance(expr, sp.cot) else inverse_sin

    def _abs_or_sign(self, expr: sp.Expr, a: Series) -> Series:
        c0 = self.domain.to_sympy(a.constant_term())
        if c0 == 0:
            raise NonAnalyticError(f"{expr} is not analytic at phi = 0")
        sign = self.domain.one if c0.is_positive else -self.domain.one
        if isinstance(expr, sp.sign):
            return self._from_element(sign)
        return self.scale(a, sign)

    def _inverse_checked(self, a: Series, message: str) -> Series:
        if not a.is_zero and a.shift > 0:
            raise NonAnalyticError(message)
        return self.inverse(a)
