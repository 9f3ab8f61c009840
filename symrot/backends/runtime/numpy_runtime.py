"""The runtime of every generated NumPy module: the code that does not depend on the plan.

Everything below the marker line is copied verbatim into each module that
:mod:`symrot.backends.numpy_backend` writes (``symrot/backends/templates/numpy_module.py.j2``),
after the plan's part: P_MAX_SQUARED, the coefficient functions and their tables, the validity
test ``_inside`` and the derived ``_derivative_matrix`` and ``_rate_vector``. A generated module
therefore needs only NumPy. The stand-ins above the marker give those names here, so that this
file is linted, type-checked and unit-tested on its own (tests/test_runtime.py binds them to a
hand-written plan); their values are never copied.

The tensors are T = c0 I + c1 (p x) + c2 (p x)^2 (eqs 16, 20, 26, 81, 83), the quaternion
operations those of eqs 61-67 and 74-75, rescaling eqs 40-47.
"""

import functools
from collections.abc import Callable
from typing import Any

import numpy

# the plan's part of a generated module (stand-ins: a unit test or a generated module binds them)
P_MAX_SQUARED: Any = numpy.inf
_COEFFICIENTS: dict[str, dict[str, Callable[..., Any]]] = {"64": {}, "32": {}}
_ACROSS: tuple[str, ...] = ()
_ANGLE: dict[str, Callable[..., Any]] = {}
_ANGLE_LOW: dict[str, Callable[..., Any]] = {}
_ANGLE_LOW_BOUND: dict[str, float] = {}
_SCALE: dict[str, Callable[..., Any]] = {}
_USES_PHI: dict[str, dict[str, bool]] = {"64": {}, "32": {}}
_SWITCH: dict[str, dict[str, float]] = {"64": {}, "32": {}}
_X_LIMIT: dict[str, Any] = {"64": 2.0 ** 600, "32": numpy.float32(2.0 ** 100)}
_DERIVATIVE_X_LIMIT: dict[str, Any] = dict(_X_LIMIT)
E0_MIN: Any = -numpy.inf
_ROTATION_TOLERANCE: dict[str, Any] = {"64": 2.0 ** -26, "32": numpy.float32(2.0 ** -11)}
_COMPLEMENT: float | None = None
_COMPLEMENT_LOW = 0.0


def _inside(x: Any, suffix: str) -> Any:
    return x < _X_LIMIT[suffix]


def _derivative_matrix(*scalars_p_a: Any) -> Any:
    raise NotImplementedError("derived per module (symrot.backends.numpy_derivatives)")


def _rate_vector(*scalars_p_a: Any) -> Any:
    raise NotImplementedError("derived per module (symrot.backends.numpy_derivatives)")


# --- copied into every generated NumPy module from here on ---
_BLOCK = 4096  # vectors per block: float64 temporaries of 32 KiB stay in cache, under glibc's mmap threshold
_SMALL = 64  # up to this many vectors: one pass, entries gathered by index (fewest NumPy calls)
_FEW = {"d": 16, "f": 6}  # up to this many vectors (by dtype character): entries as scalar arithmetic
_TINY = {"64": 2.0 ** -600, "32": numpy.float32(2.0 ** -100)}
_HUGE = {"64": 2.0 ** 600, "32": numpy.float32(2.0 ** 100)}
_FAST_LIMIT = {suffix: 0.999 * min(P_MAX_SQUARED, float(limit)) for suffix, limit in _X_LIMIT.items()}


def _quiet(function):
    """Run a public function with every floating-point warning off: overflow, underflow and invalid
    operations inside are expected (e.g. x = |p|^2 overflowing for huge p) and their results are
    already NaN by the validity tests, so no RuntimeWarning reaches the caller."""
    @functools.wraps(function)
    def quiet(*args):
        with numpy.errstate(all="ignore"):
            return function(*args)
    return quiet


def _as_float(value, name, shape):
    """value as a float32 or float64 array of shape (..., *shape); ValueError for anything else
    (complex, bool, object, string and datetime input is refused, never silently converted).
    A masked array is refused (its mask would be lost); a non-native byte order keeps its
    precision (>f4 is computed in float32, >f8 in float64)."""
    if isinstance(value, numpy.ma.MaskedArray):
        raise ValueError(f"{name} must not be a masked array (numpy.ma): its mask would be lost; "
                         "pass value.filled(numpy.nan) or value.data")
    value = numpy.asarray(value)
    if value.dtype.kind == "f" and not value.dtype.isnative and value.dtype.itemsize in (4, 8):
        value = value.astype(value.dtype.newbyteorder("="))
    if value.dtype != numpy.float64 and value.dtype != numpy.float32:  # float input is never copied
        if value.dtype.kind not in "fiu":
            raise ValueError(f"{name} must be a real float or integer array, got dtype {value.dtype}")
        value = value.astype(numpy.float64)
    if value.ndim < len(shape) or value.shape[value.ndim - len(shape):] != shape:
        raise ValueError(f"{name} must have shape (..., {', '.join(map(str, shape))}), got {value.shape}")
    return value


def _norm(v):
    """|v| over the last axis without underflow or overflow (inf for infinite, NaN for NaN input)."""
    scale = numpy.max(numpy.abs(v), axis=-1)
    scale = numpy.where((scale > 0) & (scale < numpy.inf), scale, 1.0).astype(v.dtype)
    unit = v / scale[..., None]
    return scale * numpy.sqrt(numpy.einsum("...i,...i->...", unit, unit))


def _two_square(a):
    """(a*a, error) with a*a + error = a^2 exactly (Veltkamp split, no FMA needed)."""
    c = 134217729.0 * a
    high = c - (c - a)
    low = a - high
    square = a * a
    return square, ((high * high - square) + 2.0 * high * low) + low * low


def _complement(p):
    """d = _COMPLEMENT - |p|^2 (the distance to the pole of the plan's distance form, eq 35 and
    §3.4) accurate to a few ulp of d: compensated products and sums in float64."""
    if p.dtype == numpy.float32:
        q = p.astype(numpy.float64)
        return _COMPLEMENT - numpy.einsum("...i,...i->...", q, q)
    high = numpy.full(p.shape[:-1], _COMPLEMENT)
    low = numpy.full(p.shape[:-1], _COMPLEMENT_LOW)  # p_max^2 - float(p_max^2)
    for i in range(3):
        square, error = _two_square(p[..., i])
        total = high - square
        low = low + ((high - total) - square) - error  # Fast2Sum, exact in range (c_writer)
        high = total
    return high + low


def _horner(coefficients, terms, t):
    """The polynomial of the first ``terms`` coefficients (constant term first) at t, by Horner's
    rule from the highest term down, as the plan's Branch.horner; a zero term only multiplies."""
    series = coefficients[terms - 1]
    for k in range(terms - 2, -1, -1):
        c = coefficients[k]
        series = c + t * series if c != 0 else t * series
    return series


def _clenshaw(coefficients, y):
    """The Chebyshev series sum_j coefficients[j] T_j(y) by Clenshaw's recurrence (its monomial
    form loses every digit in float32)."""
    b1 = numpy.zeros_like(y)
    b2 = numpy.zeros_like(y)
    for c in coefficients[:0:-1]:
        b1, b2 = c + 2.0 * y * b1 - b2, b1
    return coefficients[0] + y * b1 - b2


def _squared_norm(p):
    """x = |p|^2 = (p0^2 + p2^2) + p1^2: the one definition of x used by every validity test (the
    summation order of NumPy's einsum on x86-64, used before; written out, it is 3 to 4 times
    faster and the same on every CPU)."""
    square = p * p
    return numpy.asarray((square[..., 0] + square[..., 2]) + square[..., 1])


def _length(p, suffix):
    """(|p|^2, |p|): the one definition of |p| used by every validity test."""
    x = _squared_norm(p)
    s = numpy.asarray(numpy.sqrt(x))
    extreme = ~((x >= _TINY[suffix]) & (x <= _HUGE[suffix]))
    if extreme.any():  # |p| without underflow or overflow
        s[extreme] = _norm(p[extreme])
    return x, s


def _span(x, suffix):
    """(min x, max x) when every lane of x = |p|^2 is finite, in [_TINY, _HUGE] (|p| = sqrt(x)
    without underflow or overflow) and safely inside the validity range; None otherwise (empty
    input, NaN, a lane near or beyond the boundary), which takes the exact lane-by-lane tests."""
    if x.size <= _SMALL:  # a Python list is cheaper than two NumPy reductions here
        values = x.ravel().tolist()
        if not values:
            return None
        low, high, total = min(values), max(values), sum(values)
        if total != total:  # NaN: min and max of a list with NaN depend on the order
            return None
    else:
        low, high = x.min(), x.max()  # NaN propagates and fails the tests below
    if low >= _TINY[suffix] and high <= _HUGE[suffix] and high < _FAST_LIMIT[suffix]:
        return low, high
    return None


def _prepare(p, names):
    """p, (x, phi, s, d, sin(phi/2), cos(phi/2), span), valid, suffix: the arguments of the
    coefficient functions ``names`` (the half-angle sine and cosine computed once for all of them).

    span = (min x, max x) when every lane is inside the range (see _span; then valid is
    numpy.True_ and the coefficients take one branch on all lanes when the span allows), else
    None.  phi is computed only when one of them needs it on some lane (None otherwise)."""
    p = _as_float(p, "p", (3,))
    suffix = "32" if p.dtype == numpy.float32 else "64"
    x = _squared_norm(p)
    span = _span(x, suffix)
    if span is not None:
        s = numpy.sqrt(x)
        valid = numpy.True_
    else:
        x, s = _length(p, suffix)
        valid = _inside(x, suffix)
        if not valid.all():
            p = numpy.where(valid[..., None], p, 0.0).astype(p.dtype)
            s = numpy.where(valid, s, 0.0).astype(p.dtype)
            x = numpy.where(valid, x, 0.0).astype(p.dtype)  # a lane's x never depends on the others
    # lanes with x <= k^2/4 (x <= d/3: the rounding error of x, under 2.5 ulp of x, stays below
    # one ulp of d) take d = k^2 - x, the others the compensated complement: lane by lane, so a
    # lane's d never depends on the other lanes of its block
    if _COMPLEMENT is None:
        d = None
    elif span is not None and suffix == "64" and span[1] <= _COMPLEMENT / 4:
        d = _COMPLEMENT - x
    else:
        d = numpy.where(valid, _complement(p), 1.0).astype(p.dtype)
        if suffix == "64":
            d = numpy.where(valid & (x <= _COMPLEMENT / 4), _COMPLEMENT - x, d)
    table = _USES_PHI[suffix]
    switch = _SWITCH[suffix]
    if any(table[name] and (span is None or span[1] >= switch[name]) for name in names):
        phi = _ANGLE[suffix](s, d)
        half = 0.5 * phi
        sin_half, cos_half = numpy.sin(half), numpy.cos(half)
        if suffix in _ANGLE_LOW:  # phi + low: the Newton angle beyond phi's last bit
            low = _ANGLE_LOW[suffix](numpy.asarray(s, numpy.float64), numpy.asarray(phi, numpy.float64))
            low = numpy.where(numpy.abs(low) <= _ANGLE_LOW_BOUND[suffix] * phi, 0.5 * low, 0.0)
            low = low.astype(p.dtype)
            sin_half, cos_half = sin_half + cos_half * low, cos_half - sin_half * low
        return p, (x, phi, s, d, sin_half, cos_half, span), valid, suffix
    return p, (x, None, s, d, None, None, span), valid, suffix


def _scalar(p, name):
    p, state, valid, suffix = _prepare(p, [name])
    value = _COEFFICIENTS[suffix][name](*state)
    return numpy.where(valid, value, numpy.nan).astype(p.dtype)


def _tensor(p, name):
    """T = c0 I + c1 (p x) + c2 (p x)^2 for p (..., 3): written in place into the (n, 9) result,
    in one pass for small n, else in cache-sized blocks."""
    p = _as_float(p, "p", (3,))
    shape = p.shape[:-1]
    flat = p.reshape(-1, 3)
    out = numpy.empty((flat.shape[0], 9), dtype=p.dtype)
    if flat.shape[0] <= _FEW[p.dtype.char]:
        _tensor_few(flat, name, out)
    elif flat.shape[0] <= _SMALL:
        _tensor_small(flat, name, out)
    else:
        for start in range(0, flat.shape[0], _BLOCK):
            _tensor_block(flat[start:start + _BLOCK], name, out[start:start + _BLOCK])
    return out.reshape(*shape, 3, 3)


# entry e = 3 i + j of T = t I + c1 (p x) + c2 p p^T: the off-diagonal p_i p_j as (c2 p_I[e]) p_J[e]
# (the same product for (i, j) and (j, i)), the cross term sign[e] p_K[e] with (p x)_ij = -eps_ijk p_k,
# and T_ii = t + c2 p_i^2
_I = numpy.array([0, 0, 0, 0, 1, 1, 0, 1, 2])
_J = numpy.array([0, 1, 2, 1, 1, 2, 2, 2, 2])
_K = numpy.array([0, 2, 1, 2, 0, 0, 1, 0, 0])
_SIGN = {"64": numpy.array([0.0, -1.0, 1.0, 1.0, 0.0, -1.0, -1.0, 1.0, 0.0])}
_SIGN["32"] = _SIGN["64"].astype(numpy.float32)
_DIAGONAL = numpy.array([0, 4, 8])


def _coefficients(p, name):
    """p, t, c1, c2, valid, suffix of T = c0 I + c1 (p x) + c2 (p x)^2 = t I + c1 (p x) + c2 p p^T
    for the (n, 3) rows p: t = c0 - c2 |p|^2, the part across the axis, is a planned coefficient
    (next to 2 pi c0 and c2 |p|^2 nearly cancel), computed from c0 and c2 where c0 is a constant."""
    first = name + "_across" if name in _ACROSS else name + "_0"
    p, state, valid, suffix = _prepare(p, [first, name + "_1", name + "_2"])
    table = _COEFFICIENTS[suffix]
    t, c = table[first](*state), table[name + "_2"](*state)
    if name not in _ACROSS:
        t = t - c * state[0]
    return p, t, table[name + "_1"](*state), c, valid, suffix


def _tensor_few(p, name, out):
    """_tensor_block's operations on scalars, row by row: for a few vectors, the nine entries cost
    less as scalar arithmetic (float64 rows as Python floats, the same IEEE double operations;
    float32 rows as numpy.float32 scalars) than as NumPy calls on tiny arrays."""
    p, a, b, c, valid, suffix = _coefficients(p, name)
    columns = (p, a, b, c) if suffix == "32" else (p.tolist(), a.tolist(), b.tolist(), c.tolist())
    entries: list = []
    for (p0, p1, p2), a_k, b_k, c_k in zip(*columns, strict=True):
        c0, c1 = c_k * p0, c_k * p1
        b0, b1, b2 = b_k * p0, b_k * p1, b_k * p2
        s0, s1, s2 = p0 * p0, p1 * p1, p2 * p2
        q01, q02, q12 = c0 * p1, c0 * p2, c1 * p2
        entries += (a_k + c_k * s0, q01 - b2, q02 + b1,
                    q01 + b2, a_k + c_k * s1, q12 - b0,
                    q02 - b1, q12 + b0, a_k + c_k * s2)
    out.reshape(-1)[:] = entries  # out is the contiguous (n, 9) result of _tensor
    if valid is not numpy.True_:
        out[~valid] = numpy.nan


def _tensor_small(p, name, out):
    p, a, b, c, valid, suffix = _coefficients(p, name)
    numpy.multiply((c[:, None] * p)[:, _I], p[:, _J], out=out)
    out += (b[:, None] * p)[:, _K] * _SIGN[suffix]
    out[:, _DIAGONAL] = a[:, None] + c[:, None] * (p * p)
    if valid is not numpy.True_:
        out[~valid] = numpy.nan


def _tensor_block(p, name, out):
    p, a, b, c, valid, _suffix = _coefficients(p, name)
    p0, p1, p2 = p.T.copy()  # contiguous components
    c0, c1 = c * p0, c * p1
    b0, b1, b2 = b * p0, b * p1, b * p2
    s0, s1, s2 = p0 * p0, p1 * p1, p2 * p2
    numpy.add(a, c * s0, out=out[:, 0])  # T_ii = t + c2 p_i^2
    numpy.add(a, c * s1, out=out[:, 4])
    numpy.add(a, c * s2, out=out[:, 8])
    q = c0 * p1
    numpy.subtract(q, b2, out=out[:, 1])
    numpy.add(q, b2, out=out[:, 3])
    q = c0 * p2
    numpy.add(q, b1, out=out[:, 2])
    numpy.subtract(q, b1, out=out[:, 6])
    q = c1 * p2
    numpy.subtract(q, b0, out=out[:, 5])
    numpy.add(q, b0, out=out[:, 7])
    if valid is not numpy.True_:
        out[~valid] = numpy.nan


def _apply(p, v, name):
    v = _as_float(v, "the second argument", (3,))
    first = name + "_across" if name in _ACROSS else name + "_0"
    p, state, valid, suffix = _prepare(p, [first, name + "_1", name + "_2"])
    v = v.astype(p.dtype)
    table = _COEFFICIENTS[suffix]
    c = table[name + "_2"](*state)
    t = table[first](*state)
    if name not in _ACROSS:
        t = t - c * state[0]
    b = table[name + "_1"](*state)[..., None]
    p_cross_v = _cross(p, v)
    p_dot_v = (p[..., 0] * v[..., 0] + p[..., 1] * v[..., 1]) + p[..., 2] * v[..., 2]
    result = t[..., None] * v + b * p_cross_v + (c * p_dot_v)[..., None] * p
    return numpy.where(valid[..., None], result, numpy.nan).astype(p.dtype)


def _cross(u, v):
    """u x v over the last axis, broadcast: numpy.cross's products and differences (the same bits)
    without its axis handling, which costs four times the arithmetic for a few vectors."""
    u0, u1, u2 = u[..., 0], u[..., 1], u[..., 2]
    v0, v1, v2 = v[..., 0], v[..., 1], v[..., 2]
    return numpy.stack([u1 * v2 - u2 * v1, u2 * v0 - u0 * v2, u0 * v1 - u1 * v0], axis=-1)


def _skew(v):
    """(v x) of shape (..., 3, 3)."""
    out = numpy.zeros((*v.shape, 3), dtype=v.dtype)
    out[..., 0, 1], out[..., 0, 2] = -v[..., 2], v[..., 1]
    out[..., 1, 0], out[..., 1, 2] = v[..., 2], -v[..., 0]
    out[..., 2, 0], out[..., 2, 1] = -v[..., 1], v[..., 0]
    return out


def _with_slopes(p, a, name, sign):
    """p, a, (c0, c1, c2, d0, d1, d2) of T = ``name`` (sign -1: of its transpose), valid."""
    a = _as_float(a, "the second argument", (3,))
    names = [name + "_0", name + "_1", name + "_2", name + "_0_x", name + "_1_x", name + "_2_x"]
    p, state, valid, suffix = _prepare(p, names)
    valid = valid & (state[0] < _DERIVATIVE_X_LIMIT[suffix])  # the slopes' own edge of the domain
    a = a.astype(p.dtype)
    table = _COEFFICIENTS[suffix]
    c0, c1, c2, d0, d1, d2 = (table[n](*state) for n in names)
    return p, a, (c0, sign * c1, c2, d0, sign * d1, d2), valid


def _derivative(p, a, name, sign):
    p, a, scalars, valid = _with_slopes(p, a, name, sign)
    out = _derivative_matrix(*scalars, p, a)
    return numpy.where(valid[..., None, None], out, numpy.nan).astype(p.dtype)


@_quiet
def angle(p):
    """phi = |phi| from p (..., 3); NaN outside the validity range."""
    p, state, valid, suffix = _prepare(p, [])
    phi = _ANGLE[suffix](state[2], state[3])
    return numpy.where(valid, phi, numpy.nan).astype(p.dtype)


@_quiet
def rotation_matrix(p):
    """R = R_0 I + R_1 (p x) + R_2 (p x)^2 (eq 16)."""
    return _tensor(p, "R")


@_quiet
def tangent(p):
    """H with omega = H pdot (eq 20)."""
    return _tensor(p, "H")


@_quiet
def tangent_inverse(p):
    """H^-1 (eq 26)."""
    return _tensor(p, "H_inverse")


@_quiet
def tangent_det(p):
    """det H (eq 24)."""
    return _scalar(p, "det_H")


@_quiet
def root_matrix(p):
    """G, the square root of R (eq 81)."""
    return _tensor(p, "G")


@_quiet
def root_tangent(p):
    """K, the tangent tensor of G (eq 83)."""
    return _tensor(p, "K")


@_quiet
def pdot(p, omega):
    """pdot = H^-1 omega (eq 25)."""
    return _apply(p, omega, "H_inverse")


@_quiet
def omega(p, pdot):
    """omega = H pdot (eq 20)."""
    return _apply(p, pdot, "H")


@_quiet
def rotation_derivative(p, a):
    """d(R a)/dp for a fixed vector a (..., 3, 3); column j is d(R a)/dp_j (R of eq 16)."""
    return _derivative(p, a, "R", 1)


@_quiet
def rotation_transpose_derivative(p, a):
    """d(R^T a)/dp for a fixed vector a (..., 3, 3)."""
    return _derivative(p, a, "R", -1)


@_quiet
def tangent_derivative(p, a):
    """d(H a)/dp for a fixed vector a (..., 3, 3) (H of eq 20); Hdot = d(H a)/dp at a = pdot, times pdot."""
    return _derivative(p, a, "H", 1)


@_quiet
def tangent_transpose_derivative(p, a):
    """d(H^T a)/dp for a fixed vector a (..., 3, 3)."""
    return _derivative(p, a, "H", -1)


@_quiet
def tangent_inverse_derivative(p, a):
    """d(H^-1 a)/dp for a fixed vector a (..., 3, 3) (H^-1 of eq 26)."""
    return _derivative(p, a, "H_inverse", 1)


@_quiet
def angular_acceleration(p, pdot, pddot):
    """alpha = d omega/dt = H pddot + Hdot pdot for omega = H pdot (eq 20)."""
    pddot = _as_float(pddot, "pddot", (3,))
    p, v, scalars, valid = _with_slopes(p, pdot, "H", 1)
    w = pddot.astype(p.dtype)
    c0, c1, c2 = scalars[:3]
    pw = _cross(p, w)
    first = c0[..., None] * w + c1[..., None] * pw + c2[..., None] * _cross(p, pw)
    out = first + _rate_vector(*scalars, p, v)
    return numpy.where(valid[..., None], out, numpy.nan).astype(p.dtype)
