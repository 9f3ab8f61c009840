"""The JAX primitives of every generated JAX module (the array modules' framework part).

Everything below the marker line is copied verbatim into each module that
:mod:`symrot.backends.array_backend` writes for JAX, before the plan's part; the shared code of
:mod:`symrot.backends.runtime.array_runtime` follows the plan's part and calls these functions (the
same names in torch_runtime.py and jax_runtime.py). The stand-ins above the marker give the names
of array_runtime that these functions call, so that the file imports on its own.
"""

from typing import Any

import jax
import jax.numpy as _xp
from jax import lax


def _dot(a: Any, b: Any) -> Any:
    raise NotImplementedError("array_runtime's")


def _norm_value(v: Any) -> Any:
    raise NotImplementedError("array_runtime's")


def _direction(v: Any) -> Any:
    raise NotImplementedError("array_runtime's")


# --- copied into every generated JAX module from here on ---
def _where(condition, a, b):
    return _xp.where(condition, a, b)


def _atan2(y, x):
    return _xp.arctan2(y, x)


def _cbrt(v):
    """The real cube root: XLA's cbrt (up to 3 ulp off NumPy's), then one Newton step; 0, +-inf
    and NaN pass unchanged (and without a NaN derivative from the unused side)."""
    root = _xp.cbrt(v)
    refine = _xp.isfinite(root) & (root != 0)
    safe_root = _where(refine, root, 1.0)
    safe_v = _where(refine, v, 1.0)
    better = safe_root - (safe_root * safe_root * safe_root - safe_v) / (3.0 * safe_root * safe_root)
    return _where(refine, better, root)


def _stop(v):
    return lax.stop_gradient(v)


def _sqrt(v):
    """The square root (XLA's, rounded to nearest as NumPy's is)."""
    return _xp.sqrt(v)


def _wide(v):
    """v in float64 when JAX has it (jax_enable_x64), else unchanged."""
    return v.astype(_xp.float64) if jax.config.jax_enable_x64 else v


def _narrow(value, like):
    return _xp.asarray(value).astype(like.dtype) if jax.config.jax_enable_x64 else value


def _as_float(value, name, shape):
    value = _xp.asarray(value)
    if not _xp.issubdtype(value.dtype, _xp.floating) and not _xp.issubdtype(value.dtype, _xp.integer):
        raise ValueError(f"{name} must be a real float or integer array, got dtype {value.dtype}")
    if value.dtype != _xp.float32:
        value = value.astype(_xp.float64 if jax.config.jax_enable_x64 else _xp.float32)
    if value.ndim < len(shape) or value.shape[value.ndim - len(shape):] != shape:
        raise ValueError(f"{name} must have shape (..., {', '.join(map(str, shape))}), got {value.shape}")
    return value


def _suffix(value):
    return "32" if value.dtype == _xp.float32 else "64"


def _like(v, p):
    return v.astype(p.dtype)


def _amax(v):
    return _xp.max(v, axis=-1)


def _frexp_exponent(v):
    return _xp.frexp(v)[1]


def _power_of_two(exponent, like):
    """2^exponent in the dtype of like (exact), without a derivative."""
    return _stop(_xp.ldexp(_xp.ones_like(like), exponent))


def _unit(p, k):
    return _xp.zeros_like(p) + _xp.eye(3, dtype=p.dtype)[k]


def _jvp(function, primals, tangents):
    return jax.jvp(function, primals, tangents)


@jax.custom_jvp
def _norm(v):
    """|v| over the last axis without underflow or overflow, for finite v; derivative n = v/|v|
    (0 at v = 0: the safe side of a double where), second derivative (I - n n^T)/|v|."""
    return _norm_value(v)


@_norm.defjvp
def _norm_jvp(primals, tangents):
    (v,), (dv,) = primals, tangents
    return _norm(v), _dot(_direction(v), dv)


def _implicit_angle(newton, slope):
    """The angle phi(s, d) = newton(s) of a plan without a closed inverse, its derivative by the
    implicit function theorem: p(phi) = s, so dphi = ds / p'(phi) = ds / slope(phi^2, phi), not
    the derivative of the fixed-count iteration."""
    @jax.custom_jvp
    def angle(s):
        return newton(s)

    @angle.defjvp
    def angle_jvp(primals, tangents):
        (s,), (ds,) = primals, tangents
        phi = angle(s)
        return phi, ds / slope(phi * phi, phi)

    def angle_of(s, d):
        return angle(s)
    return angle_of
