"""The operations on rotations of any size in every generated NumPy module (eqs 40-47, 61-67, 74-75).

Everything below the marker line is copied verbatim into each module, after numpy_runtime.py's
copied part (:mod:`symrot.backends.numpy_backend`): conversion to and from Euler-Rodrigues
parameters (scalar first), from a rotation matrix by Shepperd's largest pivot, composition
e3 = e2 o e1, rescaling to |phi| <= pi, and their Jacobians. Above the marker, the names it
uses come from numpy_runtime.py, so that the file is linted, type-checked and tested on its own.
"""

import numpy

from symrot.backends.runtime.numpy_runtime import (
    _COEFFICIENTS,
    _ROTATION_TOLERANCE,
    _SCALE,
    E0_MIN,
    _as_float,
    _cross,
    _inside,
    _length,
    _norm,
    _prepare,
    _quiet,
    _tensor,
)


# --- copied into every generated NumPy module from here on ---
def _quaternion(p):
    p, state, valid, suffix = _prepare(p, ["e_0", "nu"])
    table = _COEFFICIENTS[suffix]
    e0 = table["e_0"](*state)
    e = (0.5 * table["nu"](*state))[..., None] * p
    return e0, e, valid, suffix


def _from_quaternion(e0, e, valid, suffix):
    """p = sigma e on the hemisphere e0 >= 0 after normalization; NaN where not representable."""
    dtype = e.dtype
    # exact power-of-two scaling: subnormal or huge quaternions normalize without under/overflow
    biggest = numpy.maximum(numpy.abs(e0), numpy.max(numpy.abs(e), axis=-1))
    exponent = numpy.frexp(numpy.where(valid & (biggest > 0) & (biggest < numpy.inf), biggest, 1.0))[1]
    e0 = numpy.ldexp(e0, -exponent).astype(dtype)
    e = numpy.ldexp(e, -exponent[..., None]).astype(dtype)
    e_norm = _norm(e)
    n = numpy.hypot(e0, e_norm)
    valid = valid & (n > 0) & numpy.isfinite(n)
    n = numpy.where(valid, n, 1.0).astype(dtype)
    sign = numpy.where(e0 < 0, -1.0, 1.0).astype(dtype)
    e0 = numpy.abs(e0) / n
    e = e * (sign / n)[..., None]
    e_norm = e_norm / n
    valid = valid & (e0 > E0_MIN)
    e0 = numpy.where(valid, e0, 1.0).astype(dtype)
    e_norm = numpy.where(valid, e_norm, 0.0).astype(dtype)
    p = _SCALE[suffix](e0, e_norm)[..., None] * e
    valid = valid & _inside(_length(p, suffix)[0], suffix)
    return numpy.where(valid[..., None], p, numpy.nan).astype(dtype)


@_quiet
def to_quaternion(p):
    """e = (e0, e1, e2, e3), e0 = cos(phi/2) = nu/epsilon (eq 74), (e1, e2, e3) = (nu/2) p (eq 75)."""
    e0, e, valid, _suffix = _quaternion(p)
    q = numpy.concatenate([e0[..., None], e], axis=-1)
    return numpy.where(valid[..., None], q, numpy.nan).astype(e.dtype)


@_quiet
def from_quaternion(e):
    """p from e = (e0, e1, e2, e3) (scalar first; normalized here; e and -e give the same p).

    phi = 2 atan2(|e|, |e0|) <= pi and p = (p(phi) / sin(phi/2)) e (inverse of eq 75), with the
    sign of e chosen so that e0 >= 0 (rescaling, eqs 40-47).  NaN where not representable.
    """
    e = _as_float(e, "e", (4,))
    suffix = "32" if e.dtype == numpy.float32 else "64"
    finite = numpy.all(numpy.isfinite(e), axis=-1)
    e = numpy.where(finite[..., None], e, 0.0).astype(e.dtype)
    return _from_quaternion(e[..., 0], e[..., 1:], finite, suffix)


@_quiet
def from_rotation_matrix(R):
    """p from a rotation matrix (..., 3, 3): Shepperd's largest pivot (eqs 61-65), then from_quaternion.

    R must be a rotation within the documented tolerance: max |R^T R - I| <= _ROTATION_TOLERANCE
    (see the module's docstring) and det R > 0; anything else (non-finite, singular,
    scaled, a reflection) gives NaN.  No orthogonalization: for R = Q + D with Q a rotation the
    result differs from Q's parameter vector by O(|D|).
    """
    r = _as_float(R, "R", (3, 3))
    suffix = "32" if r.dtype == numpy.float32 else "64"
    gram = numpy.einsum("...ki,...kj->...ij", r, r) - numpy.eye(3, dtype=r.dtype)
    det = numpy.einsum("...i,...i->...", r[..., 0, :], _cross(r[..., 1, :], r[..., 2, :]))
    # NaN compares false: non-finite R (and R whose products overflow) is refused here too
    finite = numpy.all(numpy.abs(gram) <= _ROTATION_TOLERANCE[suffix], axis=(-2, -1)) & (det > 0)
    r = numpy.where(finite[..., None, None], r, 0.0).astype(r.dtype)
    r00, r01, r02 = r[..., 0, 0], r[..., 0, 1], r[..., 0, 2]
    r10, r11, r12 = r[..., 1, 0], r[..., 1, 1], r[..., 1, 2]
    r20, r21, r22 = r[..., 2, 0], r[..., 2, 1], r[..., 2, 2]
    one = numpy.ones_like(r00)
    # row k is 4 e_k e for the pivot k in (e0, e1, e2, e3): eqs 62-65
    rows = numpy.stack([
        numpy.stack([one + r00 + r11 + r22, r21 - r12, r02 - r20, r10 - r01], axis=-1),
        numpy.stack([r21 - r12, one + r00 - r11 - r22, r01 + r10, r02 + r20], axis=-1),
        numpy.stack([r02 - r20, r01 + r10, one - r00 + r11 - r22, r12 + r21], axis=-1),
        numpy.stack([r10 - r01, r02 + r20, r12 + r21, one - r00 - r11 + r22], axis=-1),
    ], axis=-2)
    pivot = numpy.argmax(numpy.stack([r00 + r11 + r22, r00, r11, r22], axis=-1), axis=-1)
    q = numpy.take_along_axis(rows, pivot[..., None, None], axis=-2)[..., 0, :]
    return _from_quaternion(q[..., 0], q[..., 1:], finite, suffix)


@_quiet
def compose(p1, p2):
    """p3 with R(p3) = R(p2) R(p1): p1 applied first, then p2 (eqs 18-19; e3 = e2 o e1, eq 67).

    The result is rescaled (|phi3| <= pi); NaN where an input is out of range or the result
    is not representable.
    """
    a0, a, valid1, suffix = _quaternion(p1)
    b0, b, valid2, _suffix = _quaternion(p2)
    if a.dtype != b.dtype:
        raise ValueError("compose: p1 and p2 must have the same dtype")
    e0 = a0 * b0 - numpy.einsum("...i,...i->...", a, b)
    e = a0[..., None] * b + b0[..., None] * a + _cross(b, a)
    valid = valid1 & valid2
    e0 = numpy.where(valid, e0, 1.0).astype(a.dtype)
    e = numpy.where(valid[..., None], e, 0.0).astype(a.dtype)
    return _from_quaternion(e0, e, valid, suffix)


@_quiet
def compose_jacobians(p1, p2):
    """(dp3/dp1, dp3/dp2) of p3 = compose(p1, p2), each (..., 3, 3): H(p3)^-1 R(p2) H(p1) and
    H(p3)^-1 H(p2) (the rotation increments add as d theta3 = R(p2) d theta1 + d theta2, omega = H pdot).

    p3 is the rescaled result of compose, so the rescaling is included; NaN where compose is NaN.
    """
    p3 = compose(p1, p2)
    h3_inverse = _tensor(p3, "H_inverse")
    return h3_inverse @ (_tensor(p2, "R") @ _tensor(p1, "H")), h3_inverse @ _tensor(p2, "H")


@_quiet
def rescale_jacobian(p):
    """d rescale(p)/dp (..., 3, 3): H(rescale(p))^-1 H(p) where p is rescaled (the same rotation, so
    the same increment d theta), the identity where p is kept; NaN outside the validity range."""
    p = _as_float(p, "p", (3,))
    e0, _e, valid, _suffix = _quaternion(p)
    flip = valid & (e0 < 0)
    jacobian = _tensor(rescale(p), "H_inverse") @ _tensor(p, "H")
    identity = numpy.broadcast_to(numpy.eye(3, dtype=p.dtype), jacobian.shape)
    out = numpy.where(flip[..., None, None], jacobian, identity)
    return numpy.where(valid[..., None, None], out, numpy.nan).astype(p.dtype)


@_quiet
def rescale(p):
    """The equivalent parameter vector with |phi| <= pi (eqs 40-47); p itself when |phi| <= pi."""
    p = _as_float(p, "p", (3,))
    e0, e, valid, suffix = _quaternion(p)
    flip = valid & (e0 < 0)
    e0 = numpy.where(valid, e0, 1.0).astype(p.dtype)
    e = numpy.where(valid[..., None], e, 0.0).astype(p.dtype)
    rescaled = _from_quaternion(e0, e, valid, suffix)
    kept = numpy.where(valid[..., None], p, numpy.nan).astype(p.dtype)
    return numpy.where(flip[..., None], rescaled, kept)
