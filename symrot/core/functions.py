"""SymPy functions symrot adds: the real (odd) cube root, and a power kept apart from its base.

SymPy's ``cbrt(x)`` is ``x**(1/3)``, the principal root, which is complex for x < 0. A generating
function such as eq (35), p = cbrt(6(phi - sin phi)), must be odd, so symrot's ``cbrt`` is the real
cube root, ``sign(x) |x|^(1/3)``, everywhere: in the parser, the series engine, the printers and
numeric evaluation.

:class:`BoundedPower` is (a/b)**n that SymPy may not rewrite into aⁿ/bⁿ: for an unbounded p the
plan prints Wiener–Milenkovic's det H = 4096/(x + 16)³ (eq 24 with eq 34) as (16/(x + 16))³, whose
float32 evaluation does not overflow at x = 2⁴³ (:func:`symrot.plan.algebraic.bounded_powers`).
"""

from __future__ import annotations

from typing import Any

import mpmath
import sympy as sp


class RealCbrt(sp.Function):
    """Real cube root: odd, real for every real argument, derivative 1/(3 cbrt(x)^2)."""

    nargs = 1

    @classmethod
    def eval(cls, arg: sp.Expr) -> sp.Expr | None:
        if arg.is_Number:
            if arg.is_zero:
                return sp.S.Zero
            if arg.is_extended_real:
                root = sp.real_root(arg, 3)
                return root if not isinstance(root, sp.Piecewise) else None
        if arg.could_extract_minus_sign():
            return -cls(-arg)
        if isinstance(arg, sp.Pow) and arg.exp == 3 and arg.base.is_extended_real:
            return arg.base
        return None

    def fdiff(self, argindex: int = 1) -> sp.Expr:
        return sp.Rational(1, 3) / RealCbrt(self.args[0]) ** 2

    def _eval_is_extended_real(self) -> bool | None:
        return self.args[0].is_extended_real

    def _eval_is_zero(self) -> bool | None:
        return self.args[0].is_zero

    def _eval_is_positive(self) -> bool | None:
        return self.args[0].is_positive

    def _eval_is_negative(self) -> bool | None:
        return self.args[0].is_negative

    def _eval_power(self, exponent: sp.Expr) -> sp.Expr | None:
        if exponent.is_Integer and int(exponent) % 3 == 0:
            return self.args[0] ** (int(exponent) // 3)
        return None

    def _eval_evalf(self, prec: int) -> sp.Expr | None:
        value = self.args[0]._eval_evalf(prec)
        if value is None or not value.is_Number or not value.is_extended_real:
            return None
        with mpmath.workprec(prec):
            return sp.Float(real_cbrt(value._to_mpmath(prec)), precision=prec)

    def _eval_rewrite_as_Pow(self, arg: sp.Expr, **kwargs: Any) -> sp.Expr:
        return sp.sign(arg) * sp.Abs(arg) ** sp.Rational(1, 3)

    def _sympystr(self, printer: Any) -> str:
        return f"cbrt({printer._print(self.args[0])})"


class BoundedPower(sp.Function):
    """``base**exponent`` (a positive integer) printed as a power of ``base``, never expanded.

    SymPy distributes a power over a product, (16/(x + 16))**3 → 4096/(x + 16)**3, whose
    denominator overflows where the value does not; as a function application the base stays one
    bounded factor, and every printer prints it as ``(base)**exponent`` (or a product)."""

    nargs = 2

    @classmethod
    def eval(cls, base: sp.Expr, exponent: sp.Expr) -> sp.Expr | None:
        if not (exponent.is_Integer and exponent > 0):
            raise ValueError(f"BoundedPower needs a positive integer exponent, not {exponent}")
        if base.is_Number:
            return base**exponent
        return None

    def as_pow(self) -> sp.Pow:
        """The unevaluated power that printers print (``(16/(x + 16))**3``)."""
        return sp.Pow(*self.args, evaluate=False)

    def doit(self, **hints: Any) -> sp.Expr:
        base, exponent = self.args
        return (base.doit(**hints) if hints.get("deep", True) else base) ** exponent

    def fdiff(self, argindex: int = 1) -> sp.Expr:
        base, exponent = self.args
        if argindex != 1:
            raise sp.ArgumentIndexError(self, argindex)
        return exponent * base ** (exponent - 1)

    def _eval_is_extended_real(self) -> bool | None:
        return self.args[0].is_extended_real

    def _eval_evalf(self, prec: int) -> sp.Expr | None:
        return (self.args[0] ** self.args[1])._eval_evalf(prec)

    def _sympystr(self, printer: Any) -> str:
        base, exponent = self.args
        if exponent == 1:
            return f"({printer._print(base)})"
        return str(printer._print(self.as_pow()))


def real_cbrt(x: Any) -> Any:
    """Real cube root in mpmath (``mpmath.cbrt`` is the complex principal root for x < 0)."""
    return mpmath.sign(x) * mpmath.cbrt(abs(x))


def mpmath_namespace() -> dict[str, Any]:
    """Names for ``sympy.lambdify(..., modules=[mpmath_namespace(), 'mpmath'])``."""
    return {"RealCbrt": real_cbrt, "BoundedPower": mpmath.power}
