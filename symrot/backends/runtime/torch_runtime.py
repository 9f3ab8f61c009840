"""The PyTorch primitives of every generated PyTorch module (the array modules' framework part).

Everything below the marker line is copied verbatim into each module that
:mod:`symrot.backends.array_backend` writes for PyTorch, before the plan's part; the shared code of
:mod:`symrot.backends.runtime.array_runtime` follows the plan's part and calls these functions (the
same names in torch_runtime.py and jax_runtime.py). The stand-ins above the marker give the names
of array_runtime that these functions call, so that the file imports on its own.
"""

from typing import Any

import torch as _xp


def _dot(a: Any, b: Any) -> Any:
    raise NotImplementedError("array_runtime's")


def _norm_value(v: Any) -> Any:
    raise NotImplementedError("array_runtime's")


def _direction(v: Any) -> Any:
    raise NotImplementedError("array_runtime's")


# --- copied into every generated PyTorch module from here on ---
def _tensors(a, b):
    """(a, b) as tensors: a Python number takes the other's dtype and device."""
    if not isinstance(a, _xp.Tensor):
        a = _xp.full_like(b, a)
    if not isinstance(b, _xp.Tensor):
        b = _xp.full_like(a, b)
    return a, b


def _where(condition, a, b):
    return _xp.where(condition, a, b)


def _atan2(y, x):
    return _xp.atan2(*_tensors(y, x))


def _cbrt(v):
    """The real cube root: a power, then one Newton step (torch has no cbrt), 0 at 0."""
    zero = v == 0
    safe = _where(zero, 1.0, v)
    root = _xp.sign(safe) * _xp.abs(safe) ** (1.0 / 3.0)
    root = root - (root * root * root - safe) / (3.0 * root * root)
    return _where(zero, 0.0, root)


def _stop(v):
    return v.detach()


_SPLITTER = {_xp.float32: 4097.0, _xp.float64: 134217729.0}


def _sqrt(v):
    """The square root rounded to nearest, as NumPy's: torch's CPU kernel is only faithful (torch
    2.13 rounded 17% of the float32 arguments in [1, 4) and 1.2% of random float64 ones the other
    way), which moved |p| an ulp from the NumPy module's and eq 35's angle two. One correction
    r / (2 root) from the exact residual r = v - root^2 (Veltkamp's split, no FMA needed) rounds to
    nearest except within about 2^-22 ulp of a tie (checked: every float32 in [1, 4) but 4 - 2^-22,
    10^7 random float64); 0, inf and NaN pass unchanged. The correction carries no derivative."""
    root = _xp.sqrt(v)
    c = _SPLITTER[v.dtype] * root
    high = c - (c - root)
    low = root - high
    square = root * root
    error = ((high * high - square) + 2.0 * high * low) + low * low
    correction = ((v - square) - error) / (2.0 * root)
    return root + _stop(_where((root > 0) & _xp.isfinite(correction), correction, 0.0))


def _wide(v):
    return v.to(_xp.float64)


def _narrow(value, like):
    return value.to(like.dtype)


def _as_float(value, name, shape):
    value = _xp.as_tensor(value)
    if value.is_complex() or value.dtype == _xp.bool:
        raise ValueError(f"{name} must be a real float or integer tensor, got dtype {value.dtype}")
    if value.dtype != _xp.float32:
        value = value.to(_xp.float64)
    if value.ndim < len(shape) or tuple(value.shape[value.ndim - len(shape):]) != shape:
        raise ValueError(f"{name} must have shape (..., {', '.join(map(str, shape))}), "
                         f"got {tuple(value.shape)}")
    return value


def _suffix(value):
    return "32" if value.dtype == _xp.float32 else "64"


def _like(v, p):
    return v.to(dtype=p.dtype, device=p.device)


def _amax(v):
    return _xp.amax(v, dim=-1)


def _frexp_exponent(v):
    return _xp.frexp(v)[1]


def _power_of_two(exponent, like):
    """2^exponent in the dtype of like (exact), without a derivative."""
    return _xp.ldexp(_xp.ones_like(like), exponent).detach()


def _unit(p, k):
    return _xp.zeros_like(p) + _xp.eye(3, dtype=p.dtype, device=p.device)[k]


def _jvp(function, primals, tangents):
    return _xp.func.jvp(function, primals, tangents)


class _Norm(_xp.autograd.Function):
    """|v| over the last axis; derivative n = v/|v| (0 at v = 0), second (I - n n^T)/|v|."""

    generate_vmap_rule = True

    @staticmethod
    def forward(v):
        return _norm_value(v)

    @staticmethod
    def setup_context(ctx, inputs, output):
        ctx.save_for_backward(inputs[0])
        ctx.save_for_forward(inputs[0])

    @staticmethod
    def backward(ctx, grad):
        (v,) = ctx.saved_tensors
        return grad[..., None] * _direction(v)

    @staticmethod
    def jvp(ctx, dv):
        (v,) = ctx.saved_tensors
        return _dot(_direction(v), dv)


def _norm(v):
    """|v| over the last axis without underflow or overflow, for finite v."""
    return _Norm.apply(v)


def _implicit_angle(newton, slope):
    """The angle phi(s, d) = newton(s) of a plan without a closed inverse, its derivative by the
    implicit function theorem: p(phi) = s, so dphi = ds / p'(phi) = ds / slope(phi^2, phi), not
    the derivative of the fixed-count iteration."""
    class AngleNewton(_xp.autograd.Function):
        generate_vmap_rule = True

        @staticmethod
        def forward(s):
            with _xp.no_grad():
                return newton(s)

        @staticmethod
        def setup_context(ctx, inputs, output):
            ctx.save_for_backward(output)
            ctx.save_for_forward(output)

        @staticmethod
        def backward(ctx, grad):
            (phi,) = ctx.saved_tensors
            return grad / slope(phi * phi, phi)

        @staticmethod
        def jvp(ctx, ds):
            (phi,) = ctx.saved_tensors
            return ds / slope(phi * phi, phi)

    def angle_of(s, d):
        return AngleNewton.apply(s)
    return angle_of
