"""A branch-free sine and cosine for vectorizing compilers: the plan of the batch kernels' trig.

The closed forms of the evaluation plan (:mod:`symrot.plan.builder`) call sin and cos of arguments c·φ.
A loop that calls libm's ``sin`` cannot be vectorized, so the batch kernels of the C backend
evaluate those calls with this kernel instead, written with +, ×, ``rint`` and selects only (the C
headers print rint as ``SYMROT_NEAREST``, :data:`symrot.backends.c_sincos.NEAREST`):

* **reduction** (Cody–Waite): q = rint(a·2/π), r = ((a − q·P₁) − q·P₂) − q·P₃ with
  P₁ + P₂ + P₃ = π/2 to 2(m − g) + m bits. P₁ and P₂ have m − g significant bits, so q·P₁ and
  q·P₂ are exact for |q| < 2^g, without FMA;
* **polynomials** on |r| ≤ π/4 (rounded: a little more): the Taylor series of sin r = r + r z Σ sⱼ zʲ
  and cos r = 1 + z Σ cⱼ zʲ in z = r², truncated where the remainder (alternating, so bounded by
  the first omitted term) is below 2^-(m+4) relative;
* **quadrant**: j = q mod 4 = q − 4·rint(q/4 − 3/8) (exact for integer q; ``floor`` is not
  vectorized by gcc), then (sin a, cos a) = (S, C), (C, −S), (−S, −C), (−C, S) for j = 0, 1, 2, 3,
  chosen by arithmetic rather than selects: with h = rint(j/2 − 1/4) ∈ {0, 0, 1, 1}, odd = j − 2h
  and u = |j − 3/2| − 1/2 ∈ {1, 0, 0, 1}, sin a = (1 − 2h)((1 − odd)S + odd·C) and
  cos a = (2u − 1)((1 − odd)C + odd·S). Every product is by 0 or ±1 and every sum has a zero
  term, so this is exact, and it has no branch for a compiler to refuse to if-convert.

Everything here is exact rational arithmetic or 60-digit mpmath; the backends print it. The
accuracy of the printed kernel is measured against mpmath in the tests (``tests/test_c_batch.py``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import cache

import mpmath
import sympy as sp

QUADRANT_BITS = {53: 20, 24: 8}
"""g: the kernel is exact in its reduction for |a| < (2^g − 1/2)·π/2 (double: 1.6e6, float: 401)."""
REDUCED_BOUND = 0.7854 * (1 + 2.0**-20)
"""|r| after the reduction: π/4 plus the rounding of a·2/π (relative 2^-m, so far below 2^-20)."""


@dataclass(frozen=True)
class SinCosKernel:
    """The constants of the kernel for one floating-point format (m = ``mantissa_bits``)."""

    mantissa_bits: int
    quadrant_bits: int
    two_over_pi: sp.Float
    pio2_parts: tuple[sp.Rational, sp.Rational, sp.Rational]
    sin_coefficients: tuple[sp.Rational, ...]
    cos_coefficients: tuple[sp.Rational, ...]

    @property
    def max_argument(self) -> float:
        """Largest |a| for which the reduction's products are exact."""
        return (2**self.quadrant_bits - 1) * math.pi / 2

    @property
    def truncation(self) -> float:
        """Relative truncation error bound of the two polynomials on |r| ≤ π/4."""
        return max(_sin_remainder(len(self.sin_coefficients)), _cos_remainder(len(self.cos_coefficients)))


def _round_to_bits(value: mpmath.mpf, bits: int) -> sp.Rational:
    """``value`` rounded to ``bits`` significant bits, as an exact dyadic rational."""
    mantissa, exponent = mpmath.frexp(value)
    scaled = int(mpmath.nint(mpmath.ldexp(mantissa, bits)))
    return sp.Rational(scaled) * sp.Rational(2) ** (int(exponent) - bits)


def _sin_remainder(terms: int) -> float:
    """First omitted Taylor term of sin r / r at r = π/4, relative to sin r / r ≥ 0.9 there."""
    return REDUCED_BOUND ** (2 * terms + 2) / math.factorial(2 * terms + 3) / 0.9


def _cos_remainder(terms: int) -> float:
    """First omitted Taylor term of cos r at r = π/4, relative to cos r ≥ 0.707 there."""
    return REDUCED_BOUND ** (2 * terms + 2) / math.factorial(2 * terms + 2) / 0.7071


@cache
def sincos_kernel(mantissa_bits: int) -> SinCosKernel:
    """The kernel for a format with ``mantissa_bits`` significant bits (53: double, 24: float)."""
    quadrant_bits = QUADRANT_BITS[mantissa_bits]
    with mpmath.workdps(60):
        half_pi = mpmath.pi / 2
        first = _round_to_bits(half_pi, mantissa_bits - quadrant_bits)
        second = _round_to_bits(half_pi - mpmath.mpf(first.p) / first.q, mantissa_bits - quadrant_bits)
        third = _round_to_bits(half_pi - mpmath.mpf(first.p) / first.q - mpmath.mpf(second.p) / second.q,
                               mantissa_bits)
    target = 2.0 ** -(mantissa_bits + 4)
    sin_terms = next(n for n in range(1, 20) if _sin_remainder(n) < target)
    cos_terms = next(n for n in range(1, 20) if _cos_remainder(n) < target)
    # sin r = r + r z Σ_{j<sin_terms} s_j z^j with s_j = (-1)^(j+1)/(2j+3)!
    sin_coefficients = tuple(sp.Rational((-1) ** (j + 1), math.factorial(2 * j + 3))
                             for j in range(sin_terms))
    # cos r = 1 + z Σ_{j<cos_terms} c_j z^j with c_j = (-1)^(j+1)/(2j+2)!
    cos_coefficients = tuple(sp.Rational((-1) ** (j + 1), math.factorial(2 * j + 2))
                             for j in range(cos_terms))
    return SinCosKernel(mantissa_bits, quadrant_bits, (2 / sp.pi).evalf(40), (first, second, third),
                        sin_coefficients, cos_coefficients)


__all__ = ["QUADRANT_BITS", "SinCosKernel", "sincos_kernel"]
