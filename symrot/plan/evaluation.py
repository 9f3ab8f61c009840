"""Plan-layer numerics: candidate forms evaluated in a target precision, identically on every machine.

The plan's error model (:mod:`symrot.plan.builder`, :mod:`symrot.plan.algebraic`,
:mod:`symrot.plan.newton_start`) decides switches, Horner degrees and closed forms by *measuring* how an
expression behaves in float64 and float32. Those decisions are printed into ``generated/``, so the
measurement must not depend on the machine. NumPy's transcendental ufuncs do: ``sin``, ``exp``, ``log``,
``power``, … dispatch to SIMD kernels chosen at run time (AVX-512/SVML, AVX2, baseline), whose results
differ in the last bit, and even ``numpy.geomspace`` (which calls ``power``) returns other grids on a
CPU without AVX-512. libm is no better in principle (glibc selects FMA variants by CPU).

So this module models an *ideal* libm and leaves nothing to the CPU:

* arithmetic (+ − × ÷) is IEEE arithmetic in the target dtype (NumPy ufuncs: correctly rounded,
  the same on every CPU; no contraction into fused multiply-adds);
* every elementary function (sin … atanh, exp, log, sqrt, the real cube root, atan2) and every
  power with an exponent other than ±1/2 is computed by mpmath with :data:`GUARD_BITS` extra bits
  and rounded to the dtype: within 0.5 ulp (+2⁻⁴⁰) of the exact value, deterministically;
* grids are built in mpmath and rounded (:func:`log_grid`).

A plan measures hundreds of forms on one set of inputs, so the model remembers what it repeats: each
elementary call by its arguments (the same sin(φ/2) of the same angles serves every form) and each
form's printed source. Neither changes a value.

The measured error is thus the error of the *formula* under ≤ ½-ulp elementary functions; a real
libm adds at most its own documented error per call, which the accuracy benchmark measures on the
printed code (docs/accuracy.md).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from functools import lru_cache
from typing import Any

import mpmath
import numpy as np
import sympy as sp
from sympy.printing.pycode import PythonCodePrinter

from symrot.core.functions import real_cbrt

GUARD_BITS = 40
"""Bits beyond the dtype's mantissa at which mpmath evaluates elementary functions."""
WORKING_BITS = 53 + GUARD_BITS

_MPMATH_FUNCTIONS: dict[str, Callable[..., Any]] = {
    "sin": mpmath.sin, "cos": mpmath.cos, "tan": mpmath.tan,
    "asin": mpmath.asin, "acos": mpmath.acos, "atan": mpmath.atan,
    "sinh": mpmath.sinh, "cosh": mpmath.cosh, "tanh": mpmath.tanh,
    "asinh": mpmath.asinh, "acosh": mpmath.acosh, "atanh": mpmath.atanh,
    "exp": mpmath.exp, "log": mpmath.log, "sqrt": mpmath.sqrt,
    "cbrt": real_cbrt, "atan2": mpmath.atan2, "pow": mpmath.power,
    "abs": abs,
}


def _correctly_rounded(name: str, arguments: tuple[float, ...]) -> float:
    """f(arguments) at WORKING_BITS, rounded to the nearest float64 (NaN off the real domain)."""
    function = _MPMATH_FUNCTIONS[name]
    try:
        with mpmath.workprec(WORKING_BITS):
            value = function(*(mpmath.mpf(a) for a in arguments))
    except (ValueError, ZeroDivisionError, OverflowError):
        return math.nan
    if isinstance(value, mpmath.mpc):
        if value.imag != 0:
            return math.nan
        value = value.real
    return float(value)


@lru_cache(maxsize=1 << 18)
def _cached(name: str, arguments: tuple[float, ...], single: bool) -> float:
    value = _correctly_rounded(name, arguments)
    return float(np.float32(value)) if single else value


ARRAY_BYTES_KEPT = 1 << 26
"""Bytes of arguments and results :func:`_elementwise` remembers per process (then it starts
again): a plan's distinct calls take well under a megabyte."""
_ARRAYS: dict[tuple[Any, ...], np.ndarray] = {}
_array_bytes = [0]


def _elementwise(name: str) -> Callable[..., Any]:
    def apply(*arguments: Any) -> Any:
        dtype = np.result_type(*arguments)  # Python numbers are weak: float32 stays float32
        if dtype not in (np.float32, np.float64):
            dtype = np.dtype(np.float64)
        single = dtype == np.float32
        arrays = [np.asarray(a) for a in arguments]
        # the same call on the same arrays recurs: every form of every coefficient of a plan is
        # measured on one set of inputs (sin(φ/2) of the same angles dozens of times), so whole
        # results are remembered by the arguments' bytes (a copy is returned: callers own it)
        contents = [a.tobytes() for a in arrays]
        key = (name, single, *((a.dtype.str, a.shape) for a in arrays), *contents)
        known = _ARRAYS.get(key)
        if known is not None:
            return known.copy() if known.ndim else known[()]
        shape = max((a.shape for a in arrays), key=len)
        if any(a.shape not in ((), shape) for a in arrays):
            arrays = list(np.broadcast_arrays(*arrays))
        size = math.prod(shape)
        columns = [a.ravel().tolist() if a.shape else [a.item()] * size  # Python floats, exact
                   for a in arrays]
        values = [_cached(name, lane, single) for lane in zip(*columns, strict=True)]
        out = np.array(values, dtype=dtype).reshape(shape)
        kept = out.nbytes + sum(map(len, contents))
        if _array_bytes[0] + kept > ARRAY_BYTES_KEPT:
            _ARRAYS.clear()
            _array_bytes[0] = 0
        _ARRAYS[key] = out.copy()
        _array_bytes[0] += kept
        return out if out.ndim else out[()]

    apply.__name__ = name
    return apply


class _ModelFunctions:
    """The namespace ``_m`` of the printed source: one elementwise function per elementary call."""

    def __init__(self) -> None:
        for name in _MPMATH_FUNCTIONS:
            setattr(self, name, _elementwise(name))


_MODEL = _ModelFunctions()
_FUNCTION_NAMES = {
    "sin": "sin", "cos": "cos", "tan": "tan", "asin": "asin", "acos": "acos", "atan": "atan",
    "sinh": "sinh", "cosh": "cosh", "tanh": "tanh", "asinh": "asinh", "acosh": "acosh",
    "atanh": "atanh", "exp": "exp", "log": "log", "RealCbrt": "cbrt", "atan2": "atan2",
    "Abs": "abs",
}


class ModelPrinter(PythonCodePrinter):
    """Prints an expression as Python over ``_m`` (the ideal-libm namespace) and dtype arithmetic.

    Only what differs from :class:`PythonCodePrinter` is overridden: elementary functions and
    powers go to ``_m``, rationals and constants become float literals (as every backend prints
    them), so the dtype of the arrays decides the precision.
    """

    def __init__(self) -> None:
        super().__init__({"fully_qualified_modules": True, "inline": True})
        self.known_functions = {k: f"_m.{v}" for k, v in _FUNCTION_NAMES.items()}

    def _print_known_func(self, expr: Any) -> str:
        name = self.known_functions[expr.__class__.__name__]
        return f"{name}({', '.join(self._print(a) for a in expr.args)})"

    def _print_Function(self, expr: Any) -> str:
        if expr.__class__.__name__ in self.known_functions:
            return self._print_known_func(expr)
        raise ValueError(f"no model for the function {expr.func}")

    _print_RealCbrt = _print_known_func

    def _print_sign(self, expr: Any) -> str:
        """sign is exact (no libm): NumPy's elementwise sign, for arrays as for scalars (the
        inherited printing is a scalar conditional expression)."""
        return f"_sign({self._print(expr.args[0])})"

    def _print_Pow(self, expr: Any, rational: bool = False) -> str:
        base, exponent = expr.as_base_exp()
        if exponent == sp.S.Half:
            return f"_m.sqrt({self._print(base)})"
        if exponent == -sp.S.Half:
            return f"(1.0/_m.sqrt({self._print(base)}))"
        if exponent == -1:
            return f"(1.0/({self._print(base)}))"
        return f"_m.pow({self._print(base)}, {self._print(exponent)})"

    def _print_BoundedPower(self, expr: Any) -> str:
        """(base)**n as the backends print it: one pow of the bounded base (ideal libm)."""
        base, exponent = expr.args
        if exponent == 1:
            return f"({self._print(base)})"
        return f"_m.pow({self._print(base)}, {self._print(exponent)})"

    def _print_Rational(self, expr: sp.Rational) -> str:
        return repr(float(expr))

    def _print_Integer(self, expr: sp.Integer) -> str:
        return repr(float(expr))

    def _print_Float(self, expr: sp.Float) -> str:
        return repr(float(expr))

    def _print_Pi(self, expr: Any) -> str:
        return repr(math.pi)

    def _print_Exp1(self, expr: Any) -> str:
        return repr(math.e)


ModelKey = tuple[sp.Expr, tuple[str, ...]]
"""(expression, names of its variables): what a model's source is printed from."""
SOURCES_KEPT = 4096
"""Printed model sources remembered per process (a plan prints a few hundred)."""
_SOURCES: dict[ModelKey, str] = {}


def model_key(expr: sp.Expr, variables: Sequence[sp.Symbol]) -> ModelKey:
    """The key of :func:`model_source` for ``expr`` as a function of ``variables``."""
    return expr, tuple(str(v) for v in variables)


def model_source(key: ModelKey) -> str:
    """The Python source of the model of ``key`` (:func:`model_function`), printed once per process:
    a plan measures most forms in both precisions and in several places (branch, domain sweep), and
    SymPy's printer costs milliseconds per form. :func:`remember_sources` takes sources printed
    in another process."""
    if key not in _SOURCES:
        if len(_SOURCES) >= SOURCES_KEPT:
            _SOURCES.clear()
        expr, names = key
        _SOURCES[key] = f"def f({', '.join(names)}):\n    return {ModelPrinter().doprint(expr)}\n"
    return _SOURCES[key]


def remember_sources(sources: dict[ModelKey, str]) -> None:
    """Sources of :func:`model_source` printed elsewhere (a forked child), the same text."""
    _SOURCES.update(sources)


def model_function(expr: sp.Expr, variables: Sequence[sp.Symbol]) -> Callable[..., Any]:
    """``expr`` as a function of ``variables`` evaluated with the ideal libm (module docstring).

    Call it with NumPy arrays or scalars of the target dtype (float32 or float64); the result has
    that dtype. Floating-point exceptions are silenced (inf and NaN are results like others)."""
    source = model_source(model_key(expr, variables))
    namespace: dict[str, Any] = {"_m": _MODEL, "_sign": np.sign}
    exec(compile(source, "<symrot model>", "exec"), namespace)
    function = namespace["f"]

    def evaluate(*arguments: Any) -> Any:
        with np.errstate(all="ignore"):
            return function(*arguments)

    return evaluate


def log_grid(start: float, stop: float, points: int) -> np.ndarray:
    """``points`` values from ``start`` to ``stop`` equally spaced in log scale (float64), computed in
    mpmath so that every machine gets the same grid (``numpy.geomspace`` does not)."""
    if points == 1:
        return np.array([float(start)])
    with mpmath.workprec(WORKING_BITS):
        low, high = mpmath.log(mpmath.mpf(start)), mpmath.log(mpmath.mpf(stop))
        step = (high - low) / (points - 1)
        values = [float(mpmath.exp(low + k * step)) for k in range(points)]
    values[0], values[-1] = float(start), float(stop)
    return np.array(values)
