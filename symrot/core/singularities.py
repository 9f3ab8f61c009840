"""Singular angles and the validity range of a parameterization (Section 3.4).

Sources of singularity, for 0 < φ ≤ 4π:

* ``p``: p → ±∞, the generating function itself is singular;
* ``nu``: ν → 0 or ∞, the kinematic inversion through Euler–Rodrigues parameters (eq 75) fails;
* ``p_prime``: p′ → 0 or ∞ (μ → ∞ or 0), H (22) or H⁻¹ (26) is singular;
* ``det_H``: det H (24) → 0 or ∞;
* ``monotonicity``: p′ changes sign, so |p| no longer determines φ: through a zero, or by a jump
  where p has a kink (asin(sin φ) at π/2, found by :func:`_first_sign_jump`).

Method (bounded, numeric-first): each scalar function is scanned in double precision on a fine
grid; sign changes, near-touching zeros (local minima of |f|) and poles (local maxima of |f|)
are bracketed and polished at 50 digits with mpmath; one-sided values at φ* ± 10⁻²⁰ classify the
limit. Symbolic candidates, each bounded by :func:`symrot.core.timeouts.bounded`, are bracketed too and
preferred as exact angles: the poles of p from ``sympy.calculus.util.singularities`` (the only
SymPy tool that finds poles inside tan) and the zeros of p′ from ``solveset``. When ``solveset``
returns a ConditionSet or times out, the analysis is numeric and ``numeric_only`` is set.
Identically constant functions (e.g. ν for 2 sin(φ/2), det H for eq 35) have no singularity.

Past the edge of its real domain (asin(φ) beyond 1) a function is complex: NaN in double
precision, an ``mpc`` at 50 digits. The first grid point where it is complex ends the scan, the
edge is bisected at 50 digits, and the edge itself is a singularity: p → ∞ or p′ → ∞ there when
the one-sided values grow without bound (a pole or a logarithm), else "p is not real beyond".
Other angles are matched against rational multiples of π (denominators ≤ 24, to 25 digits:
multiple roots polish to fewer digits than simple ones); an angle matching neither is reported
as a Float and ``numeric_only`` is set. The validity range is the smallest singular angle.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from functools import lru_cache

import mpmath
import numpy as np
import sympy as sp
from sympy.functions.elementary.hyperbolic import InverseHyperbolicFunction
from sympy.functions.elementary.trigonometric import InverseTrigonometricFunction

from symrot.core.budget import stage
from symrot.core.derivation import Derivation, derive_expression
from symrot.core.functions import mpmath_namespace
from symrot.core.parsing import PHI
from symrot.core.timeouts import bounded

SCAN_END = 4 * np.pi
SCAN_POINTS = 4001
DIGITS = 50
QUANTITIES = ("p", "nu", "p_prime", "det_H")
CAUSES = {
    ("p", "oo"): "p -> oo: the generating function is singular",
    ("nu", "0"): "nu -> 0: kinematic inversion through Euler-Rodrigues parameters fails",
    ("nu", "oo"): "nu -> oo: kinematic inversion through Euler-Rodrigues parameters fails",
    ("p_prime", "0"): "p' -> 0 (mu -> oo): H is unbounded and H^-1 singular",
    ("p_prime", "oo"): "p' -> oo (mu -> 0): H is singular",
    ("det_H", "0"): "det H -> 0: H is singular",
    ("det_H", "oo"): "det H -> oo: H^-1 is singular",
    ("monotonicity", "0"): "p' changes sign: |p| no longer determines phi",
    ("p", "edge"): "p is not real beyond this angle (the edge of its real domain)",
    ("monotonicity", "jump"): "p' jumps across 0 (p has a kink): |p| no longer determines phi",
    ("p", "jump"): "p jumps (is discontinuous): |p| no longer determines phi",
}
MAX_CANDIDATES = 48
"""Brackets polished per function, smallest angles first (the validity range is the smallest). Each
costs a 50-digit root search of ~10 ms; functions with zeros in infinite families have hundreds
in (0, 4π]: with 400, the validity analysis of sin(sinh φ) polished 1600 and took 15 s (1143 listed
singularities), with 48 it takes 1 s (185 listed, the same edge 1.2334); 2 sin(tan(φ/2)) 5.0 → 2.6 s.
The named parameterizations and the other corpus functions have at most 16 per function."""
JUMP_STEPS = 100
"""Bisection steps that locate a jump of p′ or of p, at twice DIGITS (to ~10⁻³² of the grid step, enough
to match a multiple of π to the 25 digits of :func:`_exact_angle`; p′ such as cos φ/√(1 − sin²φ)
is resolved there)."""
EDGE_STEPS = 200
"""Bisection steps that locate the edge of the real domain to 50 digits."""


@dataclass(frozen=True)
class Singularity:
    phi: sp.Expr
    phi_float: float
    cause: str
    quantity: str
    limit: str


@dataclass(frozen=True)
class Validity:
    phi_max: sp.Expr
    phi_max_float: float
    p_max_float: float
    singularities: tuple[Singularity, ...]
    numeric_only: bool

    def listed(self) -> tuple[Singularity, ...]:
        """The singular angles up to twice the validity bound: what ``symrot derive`` prints and
        what the table's causes column and the derivation sheets show."""
        return tuple(s for s in self.singularities if s.phi_float <= 2 * self.phi_max_float)


SYMBOLIC_TIME_LIMIT = 0.5
SCAN_INTERVAL = sp.Interval.Lopen(0, 4 * sp.pi)


def validity(derivation: Derivation) -> Validity:
    """The validity range of ``derivation``'s parameterization and every singular angle."""
    with stage("validity analysis"):
        return _validity_of(derivation.p)


@lru_cache(maxsize=256)
def _validity_of(p: sp.Expr) -> Validity:
    derivation = derive_expression(p)
    candidates, confirmed = _symbolic_candidates(p, derivation.scalars_raw["p_prime"])
    brackets = tuple(float(c) for c in candidates)
    found: list[Singularity] = []
    numeric_only = not confirmed
    for quantity in QUANTITIES:
        if quantity != "p" and derivation.constant_value(quantity) is not None:
            continue
        expr = p if quantity == "p" else derivation.scalars_raw[quantity]
        for angle, limit, sign_change in _events(expr, brackets):
            if (quantity, limit) not in CAUSES:
                continue  # p = 0 away from the origin is caught through nu and p'
            exact = _exact_angle(angle, candidates)
            numeric_only |= exact is None
            phi = exact if exact is not None else sp.Float(mpmath.nstr(angle, 30), 30)
            found.append(Singularity(phi, float(angle), CAUSES[(quantity, limit)], quantity, limit))
            if quantity == "p_prime" and limit == "0" and sign_change:
                found.append(Singularity(phi, float(angle), CAUSES[("monotonicity", "0")],
                                         "monotonicity", "0"))
    # asin(sin φ): p′ = cos φ/√(1 − sin²φ) is ±1, never 0 nor ∞; 2 atan(tan(φ/2)) falls from π to −π
    # at π while p′ = 1 says nothing
    jumps = (("monotonicity", _first_sign_jump(derivation.scalars_raw["p_prime"])), ("p", _first_drop(p)))
    for quantity, angle in jumps:
        if angle is None or any(abs(s.phi_float - float(angle)) < 1e-9 * float(angle) for s in found):
            continue  # p falls across a pole or a logarithm (asinh(tan φ) at π/2): already listed
        exact = _exact_angle(angle, candidates)
        numeric_only |= exact is None
        phi = exact if exact is not None else sp.Float(mpmath.nstr(angle, 30), 30)
        found.append(Singularity(phi, float(angle), CAUSES[(quantity, "jump")], quantity, "jump"))
    found.sort(key=lambda s: (s.phi_float, QUANTITIES.index(s.quantity)
                              if s.quantity in QUANTITIES else len(QUANTITIES)))
    if not found:
        return Validity(sp.oo, float("inf"), float("inf"), (), False)
    edge = found[0]
    p_at_edge = float("inf") if any(s.quantity == "p" and s.limit == "oo"
                                    and abs(s.phi_float - edge.phi_float) < 1e-9
                                    for s in found) else _magnitude_at(p, edge)
    return Validity(edge.phi, edge.phi_float, p_at_edge, tuple(found), numeric_only)


def _scan(expr: sp.Expr) -> tuple[np.ndarray, np.ndarray]:
    """(grid, values): ``expr`` in double precision on SCAN_POINTS angles up to SCAN_END."""
    grid = np.linspace(SCAN_END / SCAN_POINTS, SCAN_END, SCAN_POINTS)
    numeric = sp.lambdify(PHI, expr, modules=[{"RealCbrt": np.cbrt}, "numpy"])
    with np.errstate(all="ignore"):
        values = np.asarray(numeric(grid), dtype=float) * np.ones_like(grid)
    return grid, values


def _first_sign_jump(p_prime: sp.Expr) -> mpmath.mpf | None:
    """The first angle in (0, 4π] where p′ changes sign without passing through 0 or ∞ (a jump, as
    where p has |g| or sign(g) in it), bisected at twice DIGITS; None when p′ keeps its sign or every
    sign change is a zero or a pole (which :func:`_events` finds and classifies)."""
    grid, values = _scan(p_prime)
    finite = np.flatnonzero(np.isfinite(values))  # 0/0 on a grid point next to the jump is skipped
    change = np.flatnonzero(np.sign(values[finite[:-1]]) * np.sign(values[finite[1:]]) < 0)
    if not change.size:
        return None
    before, after = finite[change[0]], finite[change[0] + 1]
    exact = _safe(_mp(p_prime))
    with mpmath.workdps(2 * DIGITS):
        sign = mpmath.sign(exact(mpmath.mpf(grid[before])))
        found = _bisected(exact, grid[before], grid[after], lambda value: mpmath.sign(value) == sign,
                          stop=lambda value: value == 0)
        if found is None:
            return None
        low, left, right = found
        size = max(abs(values[before]), abs(values[after]))
        if min(abs(left), abs(right)) < 1e-6 * size or max(abs(left), abs(right)) > 1e6 * size:
            return None  # a zero or a pole of p′ (found by _events), not a jump
        return low


def _first_drop(p: sp.Expr) -> mpmath.mpf | None:
    """The first angle in (0, 4π] where p falls by a jump (a discontinuity), bisected at twice
    DIGITS; None where p only decreases continuously (after a zero of p′, which :func:`_events`
    finds) or never decreases."""
    grid, values = _scan(p)
    finite = np.flatnonzero(np.isfinite(values))
    falls = np.flatnonzero(values[finite[1:]] < values[finite[:-1]])
    if not falls.size:
        return None
    before, after = finite[falls[0]], finite[falls[0] + 1]
    exact = _safe(_mp(p))
    with mpmath.workdps(2 * DIGITS):
        start = exact(mpmath.mpf(grid[before]))
        found = _bisected(exact, grid[before], grid[after], lambda value: value >= start)
        if found is None:
            return None
        low, left, right = found
        scale = max(abs(values[before]), abs(values[after]), 1.0)
        if left - right < 1e-6 * scale:
            return None  # a continuous decrease: p′ < 0 there, a sign change _events reports
        if max(abs(left), abs(right)) > 1e6 * scale:
            return None  # a pole (tan φ from +∞ to −∞), which _events reports
        return low


def _bisected(exact: Callable[[mpmath.mpf], mpmath.mpf], low: float, high: float,
              keeps_left: Callable[[mpmath.mpf], bool],
              stop: Callable[[mpmath.mpf], bool] = lambda value: False,
              ) -> tuple[mpmath.mpf, mpmath.mpf, mpmath.mpf] | None:
    """(low, f(low − δ), f(high + δ)) after JUMP_STEPS bisections of [low, high] that keep the left
    end where ``keeps_left``(f) holds (stopping early at a value that is not finite or ``stop``s),
    with δ = 10⁻¹⁵ high: the two sides of a jump of f; None when a side is not finite."""
    left_end, right_end = mpmath.mpf(low), mpmath.mpf(high)
    for _ in range(JUMP_STEPS):
        middle = (left_end + right_end) / 2
        value = exact(middle)
        if not mpmath.isfinite(value) or stop(value):
            break
        left_end, right_end = (middle, right_end) if keeps_left(value) else (left_end, middle)
    step = mpmath.mpf(10) ** -15 * right_end
    left, right = exact(left_end - step), exact(right_end + step)
    if not (mpmath.isfinite(left) and mpmath.isfinite(right)):
        return None
    return left_end, left, right


def _magnitude_at(p: sp.Expr, edge: Singularity) -> float:
    """|p| at the edge of the validity range: exact when SymPy can, else from the left side (always
    at a jump of p, whose value there is not the limit from the left)."""
    value = p.subs(PHI, edge.phi).evalf(30) if edge.limit != "jump" else sp.nan
    if value.is_Number and value.is_real and value.is_finite:
        return abs(float(value))
    with mpmath.workdps(DIGITS):
        if edge.limit == "jump":  # p stays finite up to a jump: its limit from the left, to 30 digits
            angle = mpmath.mpf(sp.N(edge.phi, DIGITS)) * (1 - mpmath.mpf(10) ** -30)
        else:
            angle = mpmath.mpf(edge.phi_float) * (1 - mpmath.mpf(10) ** -12)
        left = _safe(_mp(p))(angle)
    return float(abs(left)) if mpmath.isfinite(left) else float("inf")


def _mp(expr: sp.Expr) -> Callable[[mpmath.mpf], mpmath.mpf]:
    return sp.lambdify(PHI, expr, modules=[mpmath_namespace(), "mpmath"])


def _symbolic_candidates(p: sp.Expr, p_prime: sp.Expr) -> tuple[tuple[sp.Expr, ...], bool]:
    """Exact poles of p and zeros of p′ in (0, 4π]; False when SymPy could not list them all."""

    def poles() -> sp.Set | None:
        return sp.calculus.util.singularities(p, PHI, SCAN_INTERVAL)

    def zeros() -> sp.Set | None:
        if not (_periodic_in_phi(p_prime) and _one_frequency_or_polynomial(p_prime)
                and _plain_hyperbolic(p_prime) and _low_degree_in_calls(p_prime)
                and not p_prime.has(*_INVERSE)):
            return None  # solveset runs past any bound (cos(sinh φ) cosh φ: > 20 s); numeric scan only
        return sp.solveset(p_prime, PHI, SCAN_INTERVAL)

    found: list[sp.Expr] = []
    confirmed = True
    for compute in (poles, zeros):
        try:
            result = bounded(SYMBOLIC_TIME_LIMIT, None, compute)
        except (NotImplementedError, ValueError, TypeError, AttributeError):
            result = None
        if not isinstance(result, sp.FiniteSet):
            confirmed &= result is sp.S.EmptySet
            continue
        found.extend(x for x in result if x.is_real and x.is_number)
    return tuple(found), confirmed


_PERIODIC = (sp.sin, sp.cos, sp.tan, sp.cot, sp.sec, sp.csc)


def _periodic_in_phi(expr: sp.Expr) -> bool:
    """Whether every trigonometric function in ``expr`` has an argument linear in φ: the shape on
    which ``solveset`` is attempted. Trigonometric functions of a transcendental argument
    (cos(sinh φ), tan(sin φ), cos(tan(φ/2))) have zeros in infinite families that ``solveset``
    either returns as a ConditionSet or spends minutes on; a shape, not a time, decides, so the
    validity analysis is the same on every machine (the corpus: tests/corpus.py)."""
    for call in expr.atoms(*_PERIODIC):
        argument = call.args[0]
        if not (argument.is_polynomial(PHI) and sp.degree(argument, PHI) <= 1):
            return False
    return True


def _one_frequency_or_polynomial(expr: sp.Expr) -> bool:
    """Whether the trigonometric calls of ``expr`` share one argument, or are all sin and cos (a
    polynomial in the sine and cosine of a base angle): the other shapes, tangents of several
    frequencies, are rational in them, and ``solveset`` took 7.2 s on p′ of tan(φ/2) + sin(φ)/4,
    9.4 s for tan(φ/4) + tan(φ/2)/8 and 400 s for tan(φ/3) + 8 tan(3φ/4)/9 (a shape, not a time,
    decides: the numeric scan finds their zeros)."""
    calls = expr.atoms(*_PERIODIC)
    return len({call.args[0] for call in calls}) <= 1 or all(isinstance(call, (sp.sin, sp.cos))
                                                                for call in calls)


def _low_degree_in_calls(expr: sp.Expr) -> bool:
    """Whether ``expr``, where it is a polynomial in its trigonometric and hyperbolic calls, has
    total degree at most :data:`MAX_CALL_DEGREE` in them: p′ = 1 + 3 sin²φ cos φ of φ + sin³φ is a
    cubic in cos φ, and ``solveset`` ran past its 15 s safety bound on it (Cardano's roots inside
    acos), which ended ``derive`` with exit 2. A shape, not a time, decides."""
    calls = expr.atoms(*_HYPERBOLIC, *_PERIODIC)
    if not calls:
        return True
    opaque = {call: sp.Dummy() for call in calls}
    replaced = expr.xreplace(opaque)
    generators = list(opaque.values())
    if not replaced.is_polynomial(*generators):
        return True
    return bool(sp.Poly(replaced, *generators).total_degree() <= MAX_CALL_DEGREE)


_INVERSE = (InverseTrigonometricFunction, InverseHyperbolicFunction)
"""Inverse functions in p′ (p = √(aφ² + 1)·atan(bφ), cos(φ/4)·atanh(3φ/2)) leave ``solveset`` an
equation that mixes them with algebraic or trigonometric terms: on the 62 distinct such p′ of the
corpus and the default hypothesis sample it returned a ConditionSet (alone, in a Complement or in a
Union), raised NotImplementedError or ran past 20 s, never a finite or empty set; on 4√(3φ²/2 + 1)
atan(2φ)/35 + 2 atan(3φ/2)/(35(3φ²/2 + 1)) + 36 asin(2φ/3)/(35(2φ²/3 + 1)) it ran 283 s, past the
safety bound, and ``--emit`` exited 2 (held-out seed 2028, docs/accuracy_holdout.md). Such p′ are
left to the numeric scan: a shape, not a time, decides."""

MAX_CALL_DEGREE = 2
"""Largest total degree of p′ in its trigonometric and hyperbolic calls on which ``solveset`` runs."""

_HYPERBOLIC = (sp.sinh, sp.cosh, sp.tanh, sp.coth, sp.sech, sp.csch)


def _plain_hyperbolic(expr: sp.Expr) -> bool:
    """Whether ``expr`` has no root of φ beside its trigonometric and hyperbolic functions, and its
    hyperbolic functions (if any) share one argument: the other shapes are where ``solveset``
    spent seconds to minutes and returned no finite set (a Union, ConditionSet or Complement, which
    leaves the analysis numeric anyway). Measured on p′ of the corpus and 96 hypothesis
    functions: tanh(φ/3)√(2φ²/3 + 1) with tanh φ/(φ²/3 + 1) took 7.9 s, √(φ²/2 + 1) sinh 2φ with
    cos(2φ) asinh(φ/4) 8.7 s, and cosh(3φ/2) beside tanh(φ/4) and tanh(φ/3) ran past its 90 s
    bound; √(φ²/3 + 1) asin(φ/3) with cos φ asin(φ/4) (rows 140 and 142) ran past 15 s under load.
    Roots of the calls themselves are allowed (√(1 − tanh²φ), √(1 − sin²φ/4)): with those shapes
    solveset returned its empty or finite set within 0.5 s (sinh φ, sinh(sin φ), asin(tanh φ),
    2 asin(sin(φ)/2))."""
    calls = expr.atoms(*_HYPERBOLIC, *_PERIODIC)
    if not calls:
        return True
    opaque = {call: sp.Dummy() for call in calls}
    roots = any(not power.exp.is_integer and power.base.xreplace(opaque).has(PHI)
                for power in expr.atoms(sp.Pow))
    return len({call.args[0] for call in expr.atoms(*_HYPERBOLIC)}) <= 1 and not roots


def _events(expr: sp.Expr, extra: tuple[float, ...] = ()) -> list[tuple[mpmath.mpf, str, bool]]:
    """(angle, limit '0'|'oo', sign change?) for the zeros and poles of ``expr`` in (0, 4π].

    ``extra`` are candidate angles from the symbolic analysis, bracketed in addition to the scan.
    """
    grid, values = _scan(expr)
    exact = _mp(expr)
    events: list[tuple[mpmath.mpf, str, bool]] = []
    with mpmath.workdps(DIGITS):
        inside, edge = _real_domain(exact, grid, values)
        grid, values = grid[:inside], values[:inside]
        for low, high in _brackets(grid, values, complete=edge is None)[:MAX_CANDIDATES]:
            event = _polish(exact, mpmath.mpf(low), mpmath.mpf(high))
            if event is not None and not any(abs(event[0] - e[0]) < 1e-9 for e in events):
                events.append(event)
        for candidate in extra:  # exact angles: classify in place, no root search
            angle = mpmath.mpf(sp.N(candidate, DIGITS))
            if (edge is None or angle < edge) and not any(abs(angle - e[0]) < 1e-9 for e in events):
                event = _classify(_safe(exact), angle)
                if event is not None:
                    events.append(event)
        if edge is not None and not any(abs(edge - e[0]) < 1e-9 for e in events):
            events.append(_classify_edge(_safe(exact), edge))
    return events


def _brackets(grid: np.ndarray, values: np.ndarray, complete: bool) -> list[tuple[float, float]]:
    """Grid intervals around sign changes, near-zeros and poles (the start of an overflow run);
    ``complete``: the grid reaches 4π, so a tiny or huge last value is bracketed too."""
    magnitude = np.abs(values)
    finite = magnitude[np.isfinite(magnitude)]
    scale = max(float(np.median(finite)) if finite.size else 1.0, 1.0)
    candidates: list[tuple[float, float]] = []
    for i in range(1, len(grid) - 1):
        a, b, c = magnitude[i - 1], magnitude[i], magnitude[i + 1]
        sign_change = np.sign(values[i]) != np.sign(values[i + 1])
        local_min = b <= a and b <= c and b < 1e-3 * scale
        local_max = (b >= a and b >= c and b > 1e3 * scale) or (not np.isfinite(b) and np.isfinite(a))
        if sign_change or local_min or local_max:
            candidates.append((grid[i - 1], grid[i + 1]))
    if complete and len(grid) > 1 and (magnitude[-1] < 1e-9 * scale or magnitude[-1] > 1e9 * scale):
        candidates.append((grid[-2], grid[-1]))
    return candidates


def _is_complex(f: Callable[[mpmath.mpf], mpmath.mpf], t: mpmath.mpf) -> bool:
    """True past the edge of the real domain: f(t) has a non-zero imaginary part (or no value)."""
    try:
        value = f(t)
    except (ValueError, ZeroDivisionError, OverflowError):
        return False  # a pole or an overflow, not the end of the domain
    return isinstance(value, mpmath.mpc) and value.imag != 0


def _real_domain(f: Callable[[mpmath.mpf], mpmath.mpf], grid: np.ndarray, values: np.ndarray
                 ) -> tuple[int, mpmath.mpf | None]:
    """(grid points before the first one where f is complex, the bisected edge or None).

    NaN in double precision is either the complex region or an overflow (inf − inf); only the
    first few NaN points are checked at 50 digits, the rest of a NaN run belongs to the same.
    """
    checked = 0
    for i in np.flatnonzero(np.isnan(values)):
        if i and np.isnan(values[i - 1]):
            continue
        if _is_complex(f, mpmath.mpf(grid[i])):
            low = mpmath.mpf(grid[i - 1]) if i else mpmath.mpf(0)
            high = mpmath.mpf(grid[i])
            for _ in range(EDGE_STEPS):
                middle = (low + high) / 2
                if middle in (low, high):
                    break
                low, high = (low, middle) if _is_complex(f, middle) else (middle, high)
            return int(i), low
        checked += 1
        if checked >= 20:
            break
    return len(grid), None


def _classify_edge(safe: Callable[[mpmath.mpf], mpmath.mpf], edge: mpmath.mpf
                   ) -> tuple[mpmath.mpf, str, bool]:
    """Classify the edge of the real domain from the left: a pole (or a logarithm: values that
    keep growing as the edge nears), a zero, or a plain end of the domain."""
    near, nearer = safe(edge * (1 - mpmath.mpf(10) ** -15)), safe(edge * (1 - mpmath.mpf(10) ** -30))
    huge, tiny = mpmath.mpf(10) ** 12, mpmath.mpf(10) ** -12
    if not mpmath.isfinite(nearer) or abs(nearer) > huge or abs(nearer) > 1.5 * abs(near):
        return edge, "oo", False
    if abs(nearer) < tiny or abs(nearer) < abs(near) / 1.5:
        return edge, "0", False
    return edge, "edge", False


def _polish(f: Callable[[mpmath.mpf], mpmath.mpf], low: mpmath.mpf, high: mpmath.mpf
            ) -> tuple[mpmath.mpf, str, bool] | None:
    """Locate a zero or pole of f in [low, high] at 50 digits and classify it."""

    safe = _safe(f)

    def reciprocal(t: mpmath.mpf) -> mpmath.mpf:
        value = safe(t)
        return mpmath.mpf(0) if mpmath.isinf(value) else 1 / value

    def newton_quotient(h: Callable[[mpmath.mpf], mpmath.mpf]) -> Callable[[mpmath.mpf], mpmath.mpf]:
        # h/h' has a simple root at every multiple root of h (touching zeros such as cos^4).
        return lambda t: h(t) / mpmath.diff(h, t)

    angle = None
    for g in (safe, reciprocal, newton_quotient(safe), newton_quotient(reciprocal)):
        try:
            root = mpmath.findroot(g, (low, high), solver="anderson")
        except (ValueError, ZeroDivisionError, TypeError):
            continue
        if low - 1e-12 <= root <= high + 1e-12:
            angle = root
            break
    if angle is None:
        return None
    return _classify(safe, angle)


def _safe(f: Callable[[mpmath.mpf], mpmath.mpf]) -> Callable[[mpmath.mpf], mpmath.mpf]:
    """``f`` with division by zero read as a pole and complex rounding noise dropped."""

    def safe(t: mpmath.mpf) -> mpmath.mpf:
        try:
            value = f(t)
        except (ZeroDivisionError, ValueError, OverflowError, MemoryError):
            return mpmath.inf  # overflow: an exponent beyond mpmath's range (sinh of sinh...)
        return value.real if isinstance(value, mpmath.mpc) else value

    return safe


NEAR = mpmath.mpf(10) ** -4
"""How far from a zero :func:`_classify` compares its one-sided values with."""


def _classify(safe: Callable[[mpmath.mpf], mpmath.mpf], angle: mpmath.mpf
              ) -> tuple[mpmath.mpf, str, bool] | None:
    """Zero ('0') or pole ('oo') of ``safe`` at ``angle`` from one-sided values at ± 10⁻²⁰. A zero is
    small both absolutely and next to the values at ± :data:`NEAR` (f ~ f′·10⁻²⁰ against f′·10⁻⁴ at a
    simple zero): det H ~ cos¹⁰(φ/2) of 2 sin(φ/2)/cos³(φ/2) is 10⁻²⁸ at 3.1377 and below 10⁻¹² all
    around there; read as a zero, it ended the range at |p| = 2.6·10⁸ short of the pole at π."""
    delta = mpmath.mpf(10) ** -20
    left, right = safe(angle - delta), safe(angle + delta)
    tiny, huge = mpmath.mpf(10) ** -12, mpmath.mpf(10) ** 12
    around = max(abs(safe(angle - NEAR)), abs(safe(angle + NEAR)))
    if abs(left) < tiny and abs(right) < tiny and max(abs(left), abs(right)) < tiny * around:
        crosses = mpmath.sign(safe(angle - 10 * delta)) != mpmath.sign(safe(angle + 10 * delta))
        return angle, "0", bool(crosses)
    if abs(left) > huge or abs(right) > huge:
        return angle, "oo", bool(mpmath.sign(left) != mpmath.sign(right))
    return None


def _exact_angle(angle: mpmath.mpf, candidates: tuple[sp.Expr, ...] = ()) -> sp.Expr | None:
    """The symbolic candidate, k π / n or k / n that the 50-digit root matches (n ≤ 24), else
    None (k / n: edges of real domains, such as 1 for asin(phi))."""
    with mpmath.workdps(DIGITS):
        for candidate in candidates:
            if abs(angle - mpmath.mpf(sp.N(candidate, DIGITS))) < mpmath.mpf(10) ** -25:
                return candidate
        for unit, exact in ((mpmath.pi, sp.pi), (mpmath.mpf(1), sp.S.One)):
            for n in range(1, 25):
                k = int(mpmath.nint(angle * n / unit))
                if k and abs(angle - k * unit / n) < mpmath.mpf(10) ** -25:
                    return sp.Rational(k, n) * exact
    return None
