"""sin and cos of bounded arguments in generated C: the kernel of :mod:`symrot.plan.sincos_kernel`.

The closed forms of a plan call sin, cos and tan of arguments c·φ, and φ never leaves
[0, φ_max]. Where |c|·φ_max is far inside the kernel's exact range, the C backend prints the
branch-free kernel inline instead of calling libm:

in the ``_batch`` kernels (:mod:`symrot.backends.c_batch`), because a loop with a library call
in it is not vectorized (its roundings to an integer are the header's ``SYMROT_NEAREST`` macros,
:data:`NEAREST`). The single calls keep libm: the kernel is within 1.5 ulp of the exact
sin and cos (libm: about 0.5 ulp), and one call at a time it was not faster than glibc's
``sincos`` on the benchmark's angles (21.2 ns with libm, 22.3–22.6 ns with the kernel). The tests
measure the kernel and every batch output built on it (tests/test_c_batch.py, test_c_backend.py).
"""

from __future__ import annotations

import math
from typing import Any

import sympy as sp

from symrot.backends.c_printer import MANTISSA_BITS, Precision, SymrotCPrinter, horner
from symrot.plan.sincos_kernel import SinCosKernel, sincos_kernel

TRIG = (sp.sin, sp.cos, sp.tan)
NEAREST: dict[Precision, str] = {"double": "SYMROT_NEAREST", "float": "SYMROT_NEARESTF"}
"""The header's macros for rint in the kernel (templates/c/nearest.h.j2): ``(y + 1.5·2^52) − 1.5·2^52``
(1.5·2^23 in float), which rounds |y| < 2^51 (2^22) to the nearest integer, ties to even, exactly as
rint does in the default rounding mode, and vectorizes with SSE2 alone: at baseline x86-64 gcc
writes rint as a compare-and-branch sequence (no SSE4.1 ``roundsd``) and the loop holding it was not
vectorized. The kernel's |q| stays below 2^20 (:data:`symrot.plan.sincos_kernel.QUADRANT_BITS`)."""


class SinCosWriter:
    """Prints the kernel for one precision and decides where it applies."""

    def __init__(self, precision: Precision, printer: SymrotCPrinter, phi: sp.Symbol, phi_max: float) -> None:
        self.kernel: SinCosKernel = sincos_kernel(MANTISSA_BITS[precision])
        self.precision = precision
        self.printer = printer
        self.phi = phi
        self.phi_max = phi_max
        self.t = precision
        self.f = "" if precision == "double" else "f"
        self.nearest = NEAREST[precision]

    def applies(self, argument: sp.Expr) -> bool:
        """sin/cos/tan of ``argument`` can use the kernel: c·φ with |c|·φ_max far inside its range."""
        if argument.free_symbols != {self.phi}:
            return False
        ratio = sp.simplify(argument / self.phi)
        return bool(ratio.is_Rational) and math.isfinite(self.phi_max) and \
            abs(float(ratio)) * self.phi_max < self.kernel.max_argument / 2

    def replace(self, expr: sp.Expr, arguments: dict[sp.Expr, int]) -> sp.Expr:
        """``expr`` with sin, cos, tan of kernel arguments as symbols sin{i}, cos{i} (tan = sin/cos);
        new arguments are numbered in ``arguments``."""
        replacements: dict[sp.Expr, sp.Expr] = {}
        for call in sorted(expr.atoms(*TRIG), key=sp.default_sort_key):
            argument = call.args[0]
            if not self.applies(argument):
                continue
            index = arguments.setdefault(argument, len(arguments))
            sine, cosine = sp.Symbol(f"sin{index}", real=True), sp.Symbol(f"cos{index}", real=True)
            replacements[call] = {sp.sin: sine, sp.cos: cosine, sp.tan: sine / cosine}[call.func]
        return expr.xreplace(replacements)

    def statements(self, arguments: dict[sp.Expr, int], used: set[str]) -> list[dict[str, Any]]:
        """The kernel for every argument, setting the sin{i}/cos{i} named in ``used``."""
        statements: list[dict[str, Any]] = []
        for argument, index in arguments.items():
            statements += self.kernel_statements(str(self.printer.doprint(argument)), index, used)
        return statements

    def kernel_statements(self, argument: str, index: int, wanted: set[str]) -> list[dict[str, Any]]:
        """Statements setting ``sin{index}`` and/or ``cos{index}`` (those in ``wanted``) to sin and
        cos of ``argument`` (C text).

        Printed inline rather than as a helper function: in a translation unit with many callers a
        compiler may decline to inline a helper, and a loop with a call in it is not vectorized.
        """
        kernel, literal, t, f, nearest = self.kernel, self.printer.literal, self.t, self.f, self.nearest
        z = sp.Symbol(f"a{index}_z", real=True)
        first, second, third = (literal(part) for part in kernel.pio2_parts)
        sine = self.printer.doprint(horner(kernel.sin_coefficients, z))
        cosine = self.printer.doprint(horner(kernel.cos_coefficients, z))

        def let(name: str, value: str) -> dict[str, Any]:
            return {"kind": "let", "type": t, "name": name.replace("$", f"a{index}_"),
                    "value": value.replace("$", f"a{index}_"), "ops": 0}

        statements = [
            let("$a", argument),
            let("$q", f"{nearest}($a*{literal(kernel.two_over_pi)})"),
            let("$r", f"(($a - $q*{first}) - $q*{second}) - $q*{third}"),
            let("$z", "$r*$r"),
            let("$s", f"$r + ($r*$z)*({sine})"),
            let("$c", f"1 + $z*({cosine})"),
            let("$j", f"$q - 4*{nearest}({literal(0.25)}*$q - {literal(0.375)})"),
            let("$h", f"{nearest}({literal(0.5)}*$j - {literal(0.25)})"),
            let("$odd", "$j - 2*$h"),
        ]
        if f"sin{index}" in wanted:
            statements.append(let(f"sin{index}", "(1 - 2*$h)*((1 - $odd)*$s + $odd*$c)"))
        if f"cos{index}" in wanted:
            statements.append(let("$up", f"fabs{f}($j - {literal(1.5)}) - {literal(0.5)}"))
            statements.append(let(f"cos{index}", "(2*$up - 1)*((1 - $odd)*$c + $odd*$s)"))
        statements[0]["ops"] = self.ops(wanted & {f"sin{index}", f"cos{index}"})
        return statements

    def ops(self, outputs: set[str]) -> int:
        """Operations of one kernel: q 2, r 6, z 1, the two polynomials, j 4, h 3, odd 2, and 6
        per output (plus 3 for the cosine's sign)."""
        kernel = self.kernel
        return 18 + 2 * (len(kernel.sin_coefficients) + len(kernel.cos_coefficients)) + 3 + \
            6 * len(outputs) + (3 if any(o.startswith("cos") for o in outputs) else 0)

    def note(self) -> str:
        """One line for the comment of a function that uses the kernel."""
        kernel = self.kernel
        degrees = (2 * len(kernel.sin_coefficients) + 1, 2 * len(kernel.cos_coefficients))
        return (f"sin/cos: a - q pi/2 in three parts (exact for |a| < {kernel.max_argument:.4g}), Taylor "
                f"degree {degrees[0]}/{degrees[1]} on |r| <= pi/4 (truncation < {kernel.truncation:.1e}), "
                "quadrant by exact products (symrot.plan.sincos_kernel); assumes round-to-nearest.")


__all__ = ["NEAREST", "TRIG", "SinCosWriter"]
