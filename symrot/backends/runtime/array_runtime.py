"""The shared runtime of every generated JAX and PyTorch module: the code that depends on neither
the plan nor the framework.

Everything below the marker line is copied verbatim into each module that
:mod:`symrot.backends.array_backend` writes, after the framework's primitives (jax_runtime.py or
torch_runtime.py: ``_xp``, ``_where``, ``_sqrt``, ``_norm``, ...) and the plan's part
(P_MAX_SQUARED, the coefficient functions and their tables, ``_inside``). It is branch-free: every
branch is selected with ``where``, so the functions trace under jit, vmap and forward and reverse
differentiation. The stand-ins above the marker give the names of those two parts, so that the file
is linted, type-checked and unit-tested on its own (tests/test_runtime.py binds them). The tensors
are T = c0 I + c1 (p x) + c2 (p x)^2 (eqs 16, 20, 26, 81, 83), the quaternion operations those of
eqs 61-67 and 74-75, rescaling eqs 40-47.
"""

import math
from collections.abc import Callable
from typing import Any

# the framework's part (jax_runtime.py, torch_runtime.py)
_xp: Any = None


def _framework(*args: Any) -> Any:
    raise NotImplementedError("defined by jax_runtime.py or torch_runtime.py")


_where = _sqrt = _stop = _wide = _narrow = _as_float = _suffix = _framework
_like = _amax = _frexp_exponent = _power_of_two = _unit = _jvp = _norm = _framework
# the plan's part
P_MAX_SQUARED: Any = math.inf
_COEFFICIENTS: dict[str, dict[str, Callable[..., Any]]] = {"64": {}, "32": {}}
_ACROSS: tuple[str, ...] = ()
_ANGLE: dict[str, Callable[..., Any]] = {}
_ANGLE_LOW: dict[str, Callable[..., Any]] = {}
_ANGLE_LOW_BOUND: dict[str, float] = {}
_SCALE: dict[str, Callable[..., Any]] = {}
_USES_PHI: dict[str, dict[str, bool]] = {"64": {}, "32": {}}
_X_LIMIT: dict[str, float] = {"64": 2.0 ** 600, "32": 2.0 ** 100}
E0_MIN = -math.inf
_ROTATION_TOLERANCE = {"64": 2.0 ** -26, "32": 2.0 ** -11}
_COMPLEMENT: float | None = None
_COMPLEMENT_LOW = 0.0


def _inside(x: Any, suffix: str) -> Any:
    return x < _X_LIMIT[suffix]


# --- copied into every generated array module from here on ---
_TINY = {"64": 2.0 ** -600, "32": 2.0 ** -100}
_HUGE = {"64": 2.0 ** 600, "32": 2.0 ** 100}


def _dot(a, b):
    return a[..., 0] * b[..., 0] + a[..., 1] * b[..., 1] + a[..., 2] * b[..., 2]


def _squared_norm(p):
    """x = |p|^2 = (p0^2 + p2^2) + p1^2, summed in the NumPy module's order: the same x, hence the
    same validity test at the edge of the range and the same coefficients, as the NumPy module."""
    return (p[..., 0] * p[..., 0] + p[..., 2] * p[..., 2]) + p[..., 1] * p[..., 1]


def _cross(a, b):
    return _xp.stack([a[..., 1] * b[..., 2] - a[..., 2] * b[..., 1],
                      a[..., 2] * b[..., 0] - a[..., 0] * b[..., 2],
                      a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0]], -1)


def _scaled(v):
    """(v / c, c > 0) with c = max |v_i| (1 where v = 0), c without a derivative."""
    scale = _amax(_xp.abs(v))
    nonzero = scale > 0
    return v / _stop(_where(nonzero, scale, 1.0))[..., None], nonzero, scale


def _norm_value(v):
    unit, nonzero, scale = _scaled(v)
    return _where(nonzero, scale * _sqrt(_where(nonzero, _dot(unit, unit), 1.0)), 0.0)


def _direction(v):
    """v / |v| (0 at v = 0), differentiable: its derivative (I - n n^T) / |v| stays finite for
    subnormal v, where 1 / |v|^2 would overflow."""
    unit, nonzero, _scale = _scaled(v)
    length = _xp.sqrt(_where(nonzero, _dot(unit, unit), 1.0))
    return _where(nonzero[..., None], unit / length[..., None], 0.0)


def _two_square(a):
    """(a*a, error) with a*a + error = a^2 exactly (Veltkamp split, no FMA needed)."""
    c = 134217729.0 * a
    high = c - (c - a)
    low = a - high
    square = a * a
    return square, ((high * high - square) + 2.0 * high * low) + low * low


def _complement(p, x):
    """d = _COMPLEMENT - |p|^2 (the distance to the pole of the plan's distance form) accurate to a
    few ulp of d (compensated products and sums, float64); its derivative is that of _COMPLEMENT - x."""
    if _suffix(p) == "32":
        q = _wide(p)
        value = _narrow(_COMPLEMENT - _dot(q, q), p)
    else:
        high = _COMPLEMENT + 0.0 * x
        low = _COMPLEMENT_LOW + 0.0 * x  # p_max^2 - float(p_max^2)
        for i in range(3):
            square, error = _two_square(p[..., i])
            total = high - square
            low = low + ((high - total) - square) - error  # Fast2Sum, exact in range (c_writer)
            high = total
        value = high + low
    return _stop(value) + (_stop(x) - x)


def _horner(coefficients, terms, t, like):
    """The polynomial of the first ``terms`` coefficients (constant term first) at t, by Horner's
    rule from the highest term down, as the plan's Branch.horner, with the shape of ``like``; a
    zero term only multiplies."""
    series = coefficients[terms - 1] + 0.0 * like
    for k in range(terms - 2, -1, -1):
        c = coefficients[k]
        series = c + t * series if c != 0 else t * series
    return series


def _clenshaw(coefficients, y):
    """The Chebyshev series sum_j coefficients[j] T_j(y) by Clenshaw's recurrence (its monomial
    form loses every digit in float32)."""
    b1 = 0.0 * y
    b2 = 0.0 * y
    for c in coefficients[:0:-1]:
        b1, b2 = c + 2.0 * y * b1 - b2, b1
    return coefficients[0] + y * b1 - b2


def _length(p, x, suffix):
    """|p| from x = |p|^2, or without underflow or overflow where x is extreme."""
    normal = (x >= _TINY[suffix]) & (x <= _HUGE[suffix])
    root = _sqrt(_where(normal, x, 1.0))
    return _where(normal, root, _norm(_where(normal[..., None], 1.0, p)))


def _prepare(p, names):
    """p, (x, phi, s, d, sin(phi/2), cos(phi/2)), valid, suffix for the coefficient functions
    ``names``; p is replaced by 0 outside the validity range (safe for every derivative)."""
    suffix = _suffix(p)
    valid = _inside(_squared_norm(p), suffix)
    p = _where(valid[..., None], p, 0.0)
    x = _squared_norm(p)
    s = _length(p, x, suffix)
    d = None if _COMPLEMENT is None else _complement(p, x)
    if any(_USES_PHI[suffix][name] for name in names):
        phi = _ANGLE[suffix](s, d)
        half = 0.5 * phi
        sin_half, cos_half = _xp.sin(half), _xp.cos(half)
        if suffix in _ANGLE_LOW:  # phi + low: the Newton angle beyond phi's last bit
            wide = _wide(_stop(phi))
            low = _stop(_ANGLE_LOW[suffix](_wide(_stop(s)), wide))
            low = _narrow(_where(_xp.abs(low) <= _ANGLE_LOW_BOUND[suffix] * wide, 0.5 * low, 0.0), s)
            sin_half, cos_half = sin_half + cos_half * low, cos_half - sin_half * low
        return p, (x, phi, s, d, sin_half, cos_half), valid, suffix
    return p, (x, None, s, d, None, None), valid, suffix


def _scalar(p, name):
    p, state, valid, suffix = _prepare(_as_float(p, "p", (3,)), [name])
    return _where(valid, _COEFFICIENTS[suffix][name](*state), math.nan)


def _coefficients(p, name):
    """p, valid, t, c1, c2 of T = c0 I + c1 (p x) + c2 (p x)^2 = t I + c1 (p x) + c2 p p^T:
    t = c0 - c2 |p|^2, the part across the axis, is a planned coefficient (next to 2 pi c0 and
    c2 |p|^2 nearly cancel), computed from c0 and c2 where c0 is a constant."""
    first = name + "_across" if name in _ACROSS else name + "_0"
    p, state, valid, suffix = _prepare(p, [first, name + "_1", name + "_2"])
    table = _COEFFICIENTS[suffix]
    t = table[first](*state)
    c = table[name + "_2"](*state)
    if name not in _ACROSS:
        t = t - c * state[0]
    return p, valid, t, table[name + "_1"](*state), c


def _tensor(p, name):
    """T = t I + c1 (p x) + c2 p p^T for p (..., 3)."""
    p, valid, a, b, c = _coefficients(_as_float(p, "p", (3,)), name)
    p0, p1, p2 = p[..., 0], p[..., 1], p[..., 2]
    c0, c1 = c * p0, c * p1
    b0, b1, b2 = b * p0, b * p1, b * p2
    q01, q02, q12 = c0 * p1, c0 * p2, c1 * p2
    m = _xp.stack([a + c * (p0 * p0), q01 - b2, q02 + b1,
                   q01 + b2, a + c * (p1 * p1), q12 - b0,
                   q02 - b1, q12 + b0, a + c * (p2 * p2)], -1)
    m = _where(valid[..., None], m, math.nan)
    return m.reshape((*m.shape[:-1], 3, 3))


def _apply(p, v, name):
    p = _as_float(p, "p", (3,))
    v = _like(_as_float(v, "the second argument", (3,)), p)
    p, valid, t, b, c = _coefficients(p, name)
    result = t[..., None] * v + b[..., None] * _cross(p, v) + (c * _dot(p, v))[..., None] * p
    return _where(valid[..., None], result, math.nan)


def angle(p):
    """phi = |phi| from p (..., 3); NaN outside the validity range."""
    p, state, valid, suffix = _prepare(_as_float(p, "p", (3,)), [])
    return _where(valid, _ANGLE[suffix](state[2], state[3]), math.nan)


def rotation_matrix(p):
    """R = R_0 I + R_1 (p x) + R_2 (p x)^2 (eq 16)."""
    return _tensor(p, "R")


def tangent(p):
    """H with omega = H pdot (eq 20)."""
    return _tensor(p, "H")


def tangent_inverse(p):
    """H^-1 (eq 26)."""
    return _tensor(p, "H_inverse")


def tangent_det(p):
    """det H (eq 24)."""
    return _scalar(p, "det_H")


def root_matrix(p):
    """G, the square root of R (eq 81)."""
    return _tensor(p, "G")


def root_tangent(p):
    """K, the tangent tensor of G (eq 83)."""
    return _tensor(p, "K")


def pdot(p, omega):
    """pdot = H^-1 omega (eq 25)."""
    return _apply(p, omega, "H_inverse")


def omega(p, pdot):
    """omega = H pdot (eq 20)."""
    return _apply(p, pdot, "H")


def _jacobian(function, p):
    """d function(p) / dp (..., 3, 3) by three forward-mode passes (column k = d/dp_k); NaN where
    the value is NaN (outside the validity range)."""
    columns = []
    value = None
    for k in range(3):
        value, column = _jvp(function, (p,), (_unit(p, k),))
        columns.append(column)
    jacobian = _xp.stack(columns, -1)
    invalid = _xp.isnan(value).any(-1)
    return _where(invalid[..., None, None], math.nan, jacobian)


def _times(matrix, a):
    return (matrix * a[..., None, :]).sum(-1)


def _transpose_times(matrix, a):
    return (matrix * a[..., :, None]).sum(-2)


def _vectors(p, a):
    p = _as_float(p, "p", (3,))
    a = _as_float(a, "a", (3,))
    return p, _like(a, p)


def rotation_derivative(p, a):
    """d(R a)/dp (..., 3, 3)."""
    p, a = _vectors(p, a)
    return _jacobian(lambda q: _times(rotation_matrix(q), a), p)


def rotation_transpose_derivative(p, a):
    """d(R^T a)/dp (..., 3, 3)."""
    p, a = _vectors(p, a)
    return _jacobian(lambda q: _transpose_times(rotation_matrix(q), a), p)


def tangent_derivative(p, a):
    """d(H a)/dp (..., 3, 3)."""
    p, a = _vectors(p, a)
    return _jacobian(lambda q: _times(tangent(q), a), p)


def tangent_transpose_derivative(p, a):
    """d(H^T a)/dp (..., 3, 3)."""
    p, a = _vectors(p, a)
    return _jacobian(lambda q: _transpose_times(tangent(q), a), p)


def tangent_inverse_derivative(p, a):
    """d(H^-1 a)/dp (..., 3, 3)."""
    p, a = _vectors(p, a)
    return _jacobian(lambda q: _times(tangent_inverse(q), a), p)


def angular_acceleration(p, pdot, pddot):
    """d omega/dt = H pddot + (dH/dt) pdot for omega = H pdot (eq 20)."""
    p, rate = _vectors(p, pdot)
    acceleration = _vectors(p, pddot)[1]
    value, derivative = _jvp(lambda q, v: omega(q, v), (p, rate), (rate, acceleration))
    return _where(_xp.isnan(value).any(-1)[..., None], math.nan, derivative)  # NaN outside, as _jacobian


def compose_jacobians(p1, p2):
    """(dp3/dp1, dp3/dp2) of p3 = compose(p1, p2), each (..., 3, 3): H(p3)^-1 R(p2) H(p1) and
    H(p3)^-1 H(p2) (the rotation increments add as d theta3 = R(p2) d theta1 + d theta2, omega = H pdot).

    Closed forms, not derivatives of compose's quaternion arithmetic; p3 is the rescaled result of
    compose, so the rescaling is included; NaN where compose is NaN.
    """
    p1 = _as_float(p1, "p1", (3,))
    p2 = _as_float(p2, "p2", (3,))
    if p1.dtype != p2.dtype:
        raise ValueError("compose_jacobians: p1 and p2 must have the same dtype")
    h3_inverse = _tensor(compose(p1, p2), "H_inverse")
    return h3_inverse @ (_tensor(p2, "R") @ _tensor(p1, "H")), h3_inverse @ _tensor(p2, "H")


def rescale_jacobian(p):
    """d rescale(p)/dp (..., 3, 3): H(rescale(p))^-1 H(p) where p is rescaled (the same rotation, so
    the same increment d theta), the identity where p is kept; NaN outside the validity range."""
    p = _as_float(p, "p", (3,))
    e0, _, valid, _ = _quaternion(p)
    flip = valid & (e0 < 0)
    jacobian = _tensor(rescale(p), "H_inverse") @ _tensor(p, "H")
    identity = _xp.stack([_unit(p, k) for k in range(3)], -1)
    return _where(valid[..., None, None], _where(flip[..., None, None], jacobian, identity), math.nan)


def _quaternion(p):
    p, state, valid, suffix = _prepare(p, ["e_0", "nu"])
    table = _COEFFICIENTS[suffix]
    e0 = table["e_0"](*state)
    e = (0.5 * table["nu"](*state))[..., None] * p
    return e0, e, valid, suffix


def _from_quaternion(e0, e, valid, suffix):
    """p = sigma e on the hemisphere e0 >= 0 after normalization; NaN where not representable."""
    # exact power-of-two scaling (two halves, each representable): no under/overflow
    biggest = _xp.maximum(_xp.abs(e0), _amax(_xp.abs(e)))
    exponent = _frexp_exponent(_where(valid & (biggest > 0) & (biggest < math.inf), biggest, 1.0))
    half = exponent // 2
    first, second = _power_of_two(-half, e0), _power_of_two(half - exponent, e0)
    e0 = e0 * first * second
    e = e * (first * second)[..., None]
    e_norm = _norm(e)
    n = _xp.hypot(e0, e_norm)
    valid = valid & (n > 0) & (n < math.inf)
    n = _where(valid, n, 1.0)
    sign = _where(e0 < 0, -1.0, 1.0)
    e0 = _xp.abs(e0) / n
    e = e * (sign / n)[..., None]
    e_norm = e_norm / n
    valid = valid & (e0 > E0_MIN)
    e0 = _where(valid, e0, 1.0)
    e_norm = _where(valid, e_norm, 0.0)
    e = _where(valid[..., None], e, 0.0)
    p = _SCALE[suffix](e0, e_norm)[..., None] * e
    valid = valid & _inside(_squared_norm(p), suffix)
    return _where(valid[..., None], p, math.nan)


def to_quaternion(p):
    """e = (e0, e1, e2, e3), e0 = cos(phi/2) = nu/epsilon (eq 74), (e1, e2, e3) = (nu/2) p (eq 75)."""
    e0, e, valid, _ = _quaternion(_as_float(p, "p", (3,)))
    q = _xp.concatenate([e0[..., None], e], -1)
    return _where(valid[..., None], q, math.nan)


def from_quaternion(e):
    """p from e = (e0, e1, e2, e3) (scalar first; normalized here; e and -e give the same p).

    phi = 2 atan2(|e|, |e0|) <= pi and p = (p(phi) / sin(phi/2)) e (inverse of eq 75), with the
    sign of e chosen so that e0 >= 0 (rescaling, eqs 40-47).  NaN where not representable.
    """
    e = _as_float(e, "e", (4,))
    finite = _xp.isfinite(e).all(-1)
    e = _where(finite[..., None], e, 0.0)
    return _from_quaternion(e[..., 0], e[..., 1:], finite, _suffix(e))


def from_rotation_matrix(R):
    """p from a rotation matrix (..., 3, 3): Shepperd's largest pivot (eqs 61-65), then from_quaternion.

    R must be a rotation within the documented tolerance: max |R^T R - I| <= _ROTATION_TOLERANCE
    and det R > 0; anything else (non-finite, singular, scaled, a reflection) gives NaN.
    """
    r = _as_float(R, "R", (3, 3))
    suffix = _suffix(r)
    rows_of = [[r[..., i, j] for j in range(3)] for i in range(3)]
    gram = [[sum(rows_of[k][i] * rows_of[k][j] for k in range(3)) - (1.0 if i == j else 0.0)
             for j in range(3)] for i in range(3)]
    det = _dot(r[..., 0, :], _cross(r[..., 1, :], r[..., 2, :]))
    finite = det > 0
    for row in gram:
        for entry in row:
            finite = finite & (_xp.abs(entry) <= _ROTATION_TOLERANCE[suffix])
    r = _where(finite[..., None, None], r, 0.0)
    r00, r01, r02 = r[..., 0, 0], r[..., 0, 1], r[..., 0, 2]
    r10, r11, r12 = r[..., 1, 0], r[..., 1, 1], r[..., 1, 2]
    r20, r21, r22 = r[..., 2, 0], r[..., 2, 1], r[..., 2, 2]
    # row k is 4 e_k e for the pivot k in (e0, e1, e2, e3): eqs 62-65
    rows = [
        [1.0 + r00 + r11 + r22, r21 - r12, r02 - r20, r10 - r01],
        [r21 - r12, 1.0 + r00 - r11 - r22, r01 + r10, r02 + r20],
        [r02 - r20, r01 + r10, 1.0 - r00 + r11 - r22, r12 + r21],
        [r10 - r01, r02 + r20, r12 + r21, 1.0 - r00 - r11 + r22],
    ]
    pivots = [r00 + r11 + r22, r00, r11, r22]
    # the first largest pivot (as argmax), selected branch-free
    best, q = pivots[0], rows[0]
    for pivot, row in zip(pivots[1:], rows[1:], strict=True):
        larger = pivot > best
        best = _where(larger, pivot, best)
        q = [_where(larger, a, b) for a, b in zip(row, q, strict=True)]
    return _from_quaternion(q[0], _xp.stack(q[1:], -1), finite, suffix)


def compose(p1, p2):
    """p3 with R(p3) = R(p2) R(p1): p1 applied first, then p2 (eqs 18-19; e3 = e2 o e1, eq 67).

    The result is rescaled (|phi3| <= pi); NaN where an input is out of range or the result
    is not representable.
    """
    a0, a, valid1, suffix = _quaternion(_as_float(p1, "p1", (3,)))
    b0, b, valid2, _ = _quaternion(_as_float(p2, "p2", (3,)))
    if a.dtype != b.dtype:
        raise ValueError("compose: p1 and p2 must have the same dtype")
    e0 = a0 * b0 - _dot(a, b)
    e = a0[..., None] * b + b0[..., None] * a + _cross(b, a)
    valid = valid1 & valid2
    e0 = _where(valid, e0, 1.0)
    e = _where(valid[..., None], e, 0.0)
    return _from_quaternion(e0, e, valid, suffix)


def rescale(p):
    """The equivalent parameter vector with |phi| <= pi (eqs 40-47); p itself when |phi| <= pi."""
    p = _as_float(p, "p", (3,))
    e0, e, valid, suffix = _quaternion(p)
    flip = valid & (e0 < 0)
    e0 = _where(valid, e0, 1.0)
    e = _where(valid[..., None], e, 0.0)
    rescaled = _from_quaternion(e0, e, valid, suffix)
    kept = _where(valid[..., None], p, math.nan)
    return _where(flip[..., None], rescaled, kept)
