"""User generating functions (issue 16): the corpus, the independent reference, generated code.

* the corpus and the grammar of tests/strategies.py (a seeded sample) produce odd p(φ) with κ = 1
  whose validity range is the declared one;
* the reference of tests/reference.py (eq 1 and ω = H ṗ alone) reproduces the paper's closed forms
  for named parameterizations (eqs 22, 26, 33, 35, the Wiener–Milenkovic square root, eqs 28–29),
  so that agreement with it is evidence;
* a sample of the corpus spanning its categories, and seeded functions of the grammar, emitted as
  NumPy modules and measured against the reference with bench/accuracy_corpus.py over its sweep:
  every function must meet the 4-ulp target of docs/accuracy.md (or 4 κ ulp where the input is
  ill-conditioned) in float64 and float32 with no NaN/Inf inside the validity range. Functions
  that miss today are ``xfail(strict=True)`` with the measured miss, so the suite flips when the
  plan is fixed.
"""

from __future__ import annotations

import sys
import tempfile
from pathlib import Path
from typing import Any

import mpmath
import pytest
import sympy as sp

from symrot.core.parsing import parse_expression
from symrot.core.registry import find_by_expression
from symrot.core.timeouts import time_limit

from .corpus import CORPUS, by_expression
from .reference import PHI, GeneratingFunction, Reference, State, skew, validity_edge
from .strategies import MIN_PHI_MAX, sampled_expression

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "bench"))

from accuracy_common import load_module  # noqa: E402
from accuracy_corpus import Measurement, emit, verdict  # noqa: E402

CATEGORIES = {"polynomial", "rational", "hyperbolic", "inverse hyperbolic", "inverse trigonometric",
              "trig x polynomial", "trig + hyperbolic", "composition"}
GRAMMAR_SEED = 61
GRAMMAR_SAMPLE = 3
GRAMMAR_TERMS = 2
"""Functions of tests/strategies.py's grammar emitted and measured, sampled_expression(GRAMMAR_SEED,
i, GRAMMAR_TERMS): one or two terms cost 9–30 s CPU each (derive, plan, sweep), three terms 18–36 s,
so three functions fit the suite's budget; bench/accuracy_hypothesis.py measures more. (The first
four three-term functions of the seed, 25–36 s each, met the target too.)"""
VALIDITY_SEED = 16
VALIDITY_SAMPLE = 25
"""Functions of the grammar checked for oddness, κ = 1 and p′ > 0 up to φ_max (0.1–4 s each)."""
SAFETY_LIMIT = 600.0
"""Seconds the hypothesis sample's emits may take: a bound on a hang, never the verdict (its
slowest function takes ~19 s CPU; issue 16's 10 s target is measured by bench/accuracy_hypothesis.py
and bench/accuracy_corpus.py). The corpus sample had a 30 s limit: `phi*cos(phi/4)` and
`sin(phi)/2 + sinh(phi)/2` take 15-20 s alone and ran past it beside the rest of the suite."""
POINTS = 4
"""Log-spaced angles of the sweep in the tests (bench/accuracy_corpus.py runs 8 or more)."""


def _mp(p: Any) -> list[mpmath.mpf]:
    return [mpmath.mpf(v) for v in p]


def _close(a: mpmath.matrix, b: mpmath.matrix, digits: int = 50) -> bool:
    return mpmath.mnorm(a - b, 1) <= mpmath.mpf(10) ** -digits * max(1, mpmath.mnorm(b, 1))


# -- the corpus ---------------------------------------------------------------------------------

def test_corpus_spans_the_issue() -> None:
    assert len(CORPUS) >= 40
    assert len({e.expression for e in CORPUS}) == len(CORPUS)
    assert {e.category for e in CORPUS} >= CATEGORIES
    assert {e.edge for e in CORPUS} == {"nu", "fold", "pole", "slope"}
    assert {e.closed_inverse for e in CORPUS} == {True, False}


@pytest.mark.parametrize("entry", CORPUS, ids=[e.expression for e in CORPUS])
def test_corpus_entry_is_odd_normalized_and_valid_up_to_its_edge(entry: Any) -> None:
    function = entry.generating_function()
    with mpmath.workdps(40):
        for phi in (mpmath.mpf("0.3"), mpmath.mpf("0.7") * function.phi_max):
            assert abs(function.value(-phi) + function.value(phi)) < mpmath.mpf(10) ** -35
        tiny = mpmath.mpf(10) ** -20
        assert abs(function.value(tiny) / tiny - 1) < mpmath.mpf(10) ** -30  # κ = 1
        declared = entry.declared_phi_max()
        scanned = validity_edge(function.p, function.dp, grid=2000)
        assert abs(declared - scanned) < mpmath.mpf(10) ** -25, (declared, scanned)
        near = function.phi_max * (1 - mpmath.mpf(10) ** -8)
        if entry.edge == "fold":
            assert abs(function.dp(near)) < 1e-6
        elif entry.edge == "pole":
            closer = function.phi_max * (1 - mpmath.mpf(10) ** -24)
            assert abs(function.value(closer)) > 2 * abs(function.value(near)) > 2  # also log poles
        elif entry.edge == "slope":
            assert function.dp(near) > 1e3
        else:
            assert abs(function.phi_max - 2 * mpmath.pi) < 1e-30 and abs(function.value(near)) < 1e6


@pytest.mark.parametrize("index", range(VALIDITY_SAMPLE))
def test_generated_functions_are_odd_normalized_and_valid(index: int) -> None:
    """VALIDITY_SAMPLE seeded functions of the grammar (not hypothesis's draw, which changes with
    its version): odd, κ = 1, φ_max ≥ MIN_PHI_MAX and p′ > 0 up to it."""
    function = GeneratingFunction(sampled_expression(VALIDITY_SEED, index))
    expr = function.expr
    assert sp.simplify(expr.subs(PHI, -PHI) + expr) == 0
    assert sp.limit(expr / PHI, PHI, 0) == 1
    assert function.phi_max >= MIN_PHI_MAX
    with mpmath.workdps(30):
        for k in range(1, 50):
            assert function.dp(function.phi_max * k / 50) > 0


def test_the_grammar_sample_is_fixed_and_beyond_the_named_families() -> None:
    """The seeded sample does not depend on hypothesis: its first functions are these (a change of
    the grammar or of the sampler shows here), and none is a named parameterization."""
    sample = [sampled_expression(GRAMMAR_SEED, i, GRAMMAR_TERMS) for i in range(GRAMMAR_SAMPLE)]
    assert sample[:2] == ["4*phi**3 + tanh(2*phi)/2",
                          "4*sqrt(phi**2/4 + 1)*tan(phi/2)/5 + 3*cos(2*phi)*tanh(2*phi)/10"]
    assert all(find_by_expression(parse_expression(text)) is None for text in sample)
    assert sampled_expression(VALIDITY_SEED, 0) == (
        "32*sqrt(3*phi**2/2 + 1)*asinh(phi/4)/11 + 9*sqrt(2*phi**2 + 1)*atan(phi/3)/11")


# -- the reference against the paper's closed forms ------------------------------------------------

POINTS_P = ([0.3, -0.2, 0.5], [1e-200, -3e-200, 2e-200], [1.9, 0.4, -1.1])


@pytest.mark.parametrize("p", POINTS_P)
def test_reference_reproduces_the_cayley_gibbs_rodrigues_closed_forms(p: list[float]) -> None:
    """p = 2 tan(φ/2) (eq 33): ε = 1, μ = ν² = 1/(1 + p²/4), so R = I + ν²((p×) + (p×)²/2) (eq 14)
    and H = ν²(I + (p×)/2) (eq 22), H⁻¹ = I − (p×)/2 + (p⊗p)/4 (eq 26), det H = ν⁴ (eq 24)."""
    state = Reference(GeneratingFunction("2*tan(phi/2)")).state(p)
    with mpmath.workdps(80):
        q = _mp(p)
        cross, x = skew(q), sum(v * v for v in q)
        nu2 = 1 / (1 + x / 4)
        assert _close(state.R, mpmath.eye(3) + nu2 * (cross + cross * cross / 2))
        assert _close(state.H, nu2 * (mpmath.eye(3) + cross / 2))
        assert _close(state.H_inverse, mpmath.eye(3) - cross / 2 + mpmath.matrix(q) * mpmath.matrix(q).T / 4)
        assert abs(state.det_H - nu2 ** 2) < mpmath.mpf(10) ** -50


@pytest.mark.parametrize("p", POINTS_P)
def test_reference_reproduces_the_rotation_vector_tangent(p: list[float]) -> None:
    """p = φ (eq 30): H = I + (1 − cos φ)/φ² (p×) + (φ − sin φ)/φ³ (p×)² (eqs 22, 15–16, 21)."""
    state = Reference(GeneratingFunction("phi")).state(p)
    with mpmath.workdps(80):
        q = _mp(p)
        cross = skew(q)
        phi = mpmath.sqrt(sum(v * v for v in q))
        expected = mpmath.eye(3) + 2 * mpmath.sin(phi / 2) ** 2 / phi ** 2 * cross + \
            (phi - mpmath.sin(phi)) / phi ** 3 * cross * cross
        assert _close(state.H, expected)
        assert abs(state.angle - phi) < mpmath.mpf(10) ** -55 * phi


@pytest.mark.parametrize("text, kappa", [("phi + tanh(phi)", 2), ("2*(1 - cos(phi))/phi", 1),
                                         ("sin(phi) + sin(3*phi)/9", sp.Rational(4, 3))])
def test_reference_tangent_at_the_identity_is_the_limit_next_to_it(text: str, kappa: sp.Expr) -> None:
    """H(0) = I/κ and K(0) = I/(2κ) (ω = H ṗ with ṗ = κ φ̇ n): the reference returned I and I/2 for
    every κ, so correct tangents of φ + tanh φ measured 2.25·10¹⁵ ulp at p = 0."""
    reference = Reference(GeneratingFunction(text))
    at_zero, next_to_it = reference.state([0.0, 0.0, 0.0]), reference.state([1e-40, -2e-40, 3e-40])
    with mpmath.workdps(60):
        assert abs(reference.kappa() - mpmath.mpf(sp.N(kappa, 70))) < mpmath.mpf(10) ** -55
        assert _close(at_zero.H, next_to_it.H, 35) and _close(at_zero.K, next_to_it.K, 35)
        assert _close(at_zero.H, mpmath.eye(3) / mpmath.mpf(sp.N(kappa, 70)))


@pytest.mark.parametrize("p", ([0.4, 0.3, -1.2], [1e-100, 2e-100, 0.0], [2.0, -1.5, 1.0]))
def test_reference_tangent_of_eq_35_has_unit_determinant(p: list[float]) -> None:
    """p = cbrt(6(φ − sin φ)) (eq 35) is defined by det H = 1; it cancels at small φ."""
    state = Reference(GeneratingFunction("cbrt(6*(phi - sin(phi)))", cancels=True)).state(p)
    assert abs(state.det_H - 1) < mpmath.mpf(10) ** -50


def test_reference_wiener_milenkovic_root_and_tangent() -> None:
    """p = 4 tan(φ/4) (eq 34): H² = α² R with α = cos²(φ/4); the root G is R at φ/2 (G² = R)."""
    state = Reference(GeneratingFunction("4*tan(phi/4)")).state([1.1, -2.0, 0.7])
    with mpmath.workdps(80):
        alpha = mpmath.cos(state.angle / 4) ** 2
        assert _close(state.H * state.H, alpha ** 2 * state.R)
        assert _close(state.G * state.G, state.R)


@pytest.mark.parametrize("entry", [by_expression(e) for e in ("sinh(phi)", "phi*cos(phi/4)",
                                                              "asinh(tan(phi))")], ids=str)
def test_reference_satisfies_eqs_28_29_and_the_quaternion(entry: Any) -> None:
    """R = H H⁻ᵀ (28), R − I = (p×) H (29), R of the quaternion (eq 74) and H = I at p = 0."""
    reference = Reference(entry.generating_function())
    p = [0.5, -0.3, 0.6]
    state: State = reference.state(p)
    with mpmath.workdps(80):
        assert _close(state.R, state.H * state.H_inverse.T)
        assert _close(state.R - mpmath.eye(3), skew(_mp(p)) * state.H)
        w, *e = state.quaternion
        e_cross = skew(e)
        assert _close(state.R, mpmath.eye(3) + 2 * w * e_cross + 2 * e_cross * e_cross)
    zero = reference.state([0.0, 0.0, 0.0])
    identity = mpmath.eye(3)
    assert (zero.H, zero.R, zero.angle) == (identity, identity, 0)
    tiny = reference.state([1e-200, 2e-200, -1e-200])
    assert _close(tiny.H, mpmath.eye(3))


@pytest.mark.parametrize("text, closed", [
    ("2*(1 - cos(phi))/phi", "4*sin(phi/2)**2/phi"),
    ("2*(tan(phi) - sin(phi))/phi**2", "4*tan(phi)*sin(phi/2)**2/phi**2")])
def test_reference_keeps_its_digits_where_an_unflagged_p_cancels(text: str, closed: str) -> None:
    """A function typed without ``cancels`` (any user function) that loses digits at small φ gets its
    guard digits from the reference itself: 2(1 − cos φ)/φ at φ = 3.5·10⁻⁸⁶ was 0 at 70 digits, and a
    correct from_quaternion measured 5·10²³⁷ ulp against it."""
    function, exact = GeneratingFunction(text), GeneratingFunction(closed)
    assert function.cancels and not exact.cancels
    with mpmath.workdps(60):
        for phi in (mpmath.mpf("3.53e-86"), mpmath.mpf("1e-300"), mpmath.mpf("1e-5")):
            assert abs(function.value(phi) / exact.value(phi) - 1) < mpmath.mpf(10) ** -55


def test_reference_composition_is_the_product_of_rotations() -> None:
    reference = Reference(by_expression("2*sinh(phi/2)").generating_function())
    p1, p2 = [0.7, 0.2, -0.4], [-0.3, 1.1, 0.5]
    p3 = [float(v) for v in reference.compose(p1, p2)]
    product = reference.state(p2).R * reference.state(p1).R
    assert mpmath.mnorm(reference.state(p3).R - product, 1) < 1e-14  # p3 is rounded to float64


# -- generated code ----------------------------------------------------------------------------

SAMPLE: dict[str, str | None] = {
    # expression: None when it meets the target, else the measured miss (xfail, strict);
    # one per category where the emit is fast (the whole corpus: bench/accuracy_corpus.py)
    "phi - phi**3/50": None,
    "phi + phi**5/120": None,  # float32 root_matrix 9.2 ulp at 6.28 before G_k was measured as c_k |p|^k
    # float32 omega 55 ulp at 6.28 before t = c0 - c2 |p|^2 was planned, 15.9 at 6.18 before the
    # angle was asinh(s) (sp.solve's log form cancels) and H_2 through sqrt(1 + x) (6.5 ulp in phi)
    "sinh(phi)": None,
    "atan(phi)": None,
    "phi*cos(phi/4)": None,
    # root_matrix 6 ulp (float64) and 8.7 ulp (float32), float32 omega 61 ulp at 6.27-6.28 before
    # the across-axis part t = c0 - c2 |p|^2 was planned and forms in x found inside sums
    "sin(phi)/2 + sinh(phi)/2": None,
    # a pole at 2*pi: NaN in every output from |p|^2 = 2^32 before symrot/plan/pole.py (126 NaN/Inf)
    "phi/cos(phi/4)": None,
    # NaN in every output for |p| > 1.11415 (phi > 0.99995) before Newton in sqrt(1 - phi)
    "4*phi/5 + asin(phi)/5": None,
    # float64 rotation_matrix 102 ulp, omega 195 ulp at 2/3 - 1e-6 before atanh(3 phi/2) = 3 s/(2 cos(phi/4))
    "2*cos(phi/4)*atanh(3*phi/2)/3": None,
    # NaN in every float64 output from phi = 6.273 before asin(tanh(phi)) was measured as
    # atan(sinh(phi)) (the Newton residual was 80 ulp off next to 2 pi, the range ended early)
    "asin(tanh(phi))": None,
    # tangent_inverse and pdot 2.2e5 ulp, tangent_det 2.3e5 (float64) and 6.1e5 (float32) at
    # pi/2 - 1e-6 before cos(phi) = 1/cosh(s) (pole._gudermannian_pole) and det H judged relative to
    # itself where p' -> oo at the edge
    "asinh(tan(phi))": None,
}


def measure(function: GeneratingFunction, name: str,
            limit: float = SAFETY_LIMIT) -> dict[str, list[dict[str, Any]]]:
    """{precision: tallies} of the emitted NumPy module over the sweep with POINTS angles."""
    with time_limit(limit, "emit"):
        plan, _source, _seconds = emit(function.expression, name)
    with tempfile.TemporaryDirectory() as tmp:
        module = load_module(plan, Path(tmp))
        measurement = Measurement(function, plan, module, None, None, POINTS)
        measurement.run()
    assert not measurement.errors, measurement.errors
    out: dict[str, list[dict[str, Any]]] = {}
    for (f, label, _backend), tally in measurement.tallies.items():
        out.setdefault(label, []).append({"function": f, "ulp": tally.worst.ulp, "at": tally.worst.at,
                                          "excess": tally.worst.excess, "nonfinite": tally.nonfinite})
    return out


def misses(results: dict[str, list[dict[str, Any]]]) -> list[str]:
    return [f"{label} {t['function']} {t['ulp']:.3g} ulp at {t['at']:.3g}"
            + (f" ({t['nonfinite']} NaN/Inf)" if t["nonfinite"] else "")
            for label, tallies in results.items() for t in tallies
            if verdict([t]) not in ("meets", "conditioned")]


def _sample_params() -> list[Any]:
    params = []
    for expression, reason in SAMPLE.items():
        marks = [pytest.mark.xfail(strict=True, reason=reason)] if reason else []
        params.append(pytest.param(expression, marks=marks, id=expression))
    return params


@pytest.mark.parametrize("expression", _sample_params())
def test_corpus_sample_meets_the_target(expression: str) -> None:
    entry = by_expression(expression)
    results = measure(entry.generating_function(), f"sample_{CORPUS.index(entry)}")
    assert not misses(results), misses(results)


@pytest.mark.slow
@pytest.mark.parametrize("index", range(GRAMMAR_SAMPLE))
def test_grammar_sample_meets_the_target(index: int) -> None:
    """Functions of the grammar of tests/strategies.py drawn by a seeded sampler (the same on every
    hypothesis version), each emitted and measured. The verdict is the measured accuracy only: the
    emit's time limit (SAFETY_LIMIT) is far above what the functions take, so a loaded machine
    cannot flip the outcome (the plan itself is deterministic)."""
    function = GeneratingFunction(sampled_expression(GRAMMAR_SEED, index, GRAMMAR_TERMS))
    try:
        missed = misses(measure(function, f"grammar_{index}", SAFETY_LIMIT))
    except Exception as error:  # an emit that raises is a miss like any other
        missed = [f"emit: {type(error).__name__}: {str(error)[:120]}"]
    assert not missed, f"{function.expression}: {missed[:3]}"


@pytest.mark.slow
def test_a_logarithmic_pole_meets_the_target() -> None:
    """3 cosh(2φ) atanh(φ/3), the hypothesis sample's function until it was replaced by the seeded
    one, missed next to its logarithmic pole at φ = 3 (float64 rotation_matrix 9.4·10¹⁶ ulp) until
    p⁻¹ = 1/(3 cosh(2φ) atanh(φ/3)) in the coefficients was written as 1/s
    (:func:`symrot.plan.measurement.with_length` on products)."""
    missed = misses(measure(GeneratingFunction("3*cosh(2*phi)*atanh(phi/3)"), "log_pole", SAFETY_LIMIT))
    assert not missed, missed


def test_the_c_sweep_measures_the_quaternion_operations() -> None:
    """bench/accuracy_corpus.py measures C's to_quaternion, from_quaternion, rescale and compose
    beside the nine kinematic functions of tests/c_harness.py (before, only NumPy's were swept)."""
    from accuracy_corpus import C_OPERATIONS, measure_expression

    result = measure_expression(GeneratingFunction("4*atan(phi/4)"), "c_operations", 1, True, {})
    assert "operations_error" not in result["c"], result["c"]
    swept = [t for t in result["tallies"] if t["backend"] == "c" and t["function"] in C_OPERATIONS]
    assert {(t["function"], t["precision"]) for t in swept} == {
        (f, p) for f in C_OPERATIONS for p in ("float64", "float32")}
    assert all(t["points"] > 0 and verdict([t]) in ("meets", "conditioned") for t in swept), swept


def test_a_miss_is_reported_where_its_error_exceeds_the_condition() -> None:
    """The worst ulp and the worst ulp/κ may be at different angles: corpus entry 5 (φ − φ³/6 + φ⁵/120)
    had 1.15·10¹² ulp at its fold, within κ there, and was reported at the fold while it missed by
    9·10⁵ κ at φ = 0.1. A tally keeps both, and the report names the second."""
    from accuracy_common import Worst
    from accuracy_corpus import miss_text

    worst = Worst()
    worst.add(7.8e4, 0.1, 0.09)
    worst.add(1.15e12, 1.59, 1.09e12)
    worst.add(2.0, 1.0, 1.0)
    assert (worst.ulp, worst.at, worst.excess, worst.excess_at) == (1.15e12, 1.59, 7.8e4, 0.1)
    tally = {"ulp": worst.ulp, "at": worst.at, "kappa": worst.kappa, "excess": worst.excess,
             "excess_at": worst.excess_at, "nonfinite": 0}
    assert miss_text(tally).startswith("7.8e+04 κ ulp at φ = 0.1 (worst 1.15e+12 ulp at φ = 1.59")
