"""Generated NumPy modules (issue 4): identities, dtypes, p = 0, NaN outside validity, CLI, accuracy."""

from __future__ import annotations

import importlib.util
import subprocess
import sys
import warnings
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from symrot.cli import main

from .edges import FAMILIES, axis_probes, edge

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "bench"))


def load(path: Path, name: str):
    spec = importlib.util.spec_from_file_location(name, path)
    assert spec and spec.loader
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


PAPER_P = {"det_h_one": "cbrt(6*(phi - sin(phi)))", "cayley_gibbs_rodrigues": "2*tan(phi/2)",
           "euler_rodrigues": "2*sin(phi/2)"}
"""p(φ) of the modules of :func:`module` (Table 1 and eq 35), for tests/reference.py."""


@pytest.fixture(scope="module", params=["det_h_one", "cayley_gibbs_rodrigues", "euler_rodrigues"])
def module(request):
    return load(ROOT / "generated" / "numpy" / f"{request.param}.py", f"gen_{request.param}")


@pytest.mark.parametrize("dtype", [np.float64, np.float32])
def test_identities_without_warnings(module, dtype) -> None:
    rng = np.random.default_rng(3)
    p = (rng.normal(size=(2, 4, 3)) * np.array([0, 1e-30, 1e-8, 0.5])[None, :, None]).astype(dtype)
    tolerance = 30 * np.finfo(dtype).eps
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        r = module.rotation_matrix(p)
        h, h_inverse = module.tangent(p), module.tangent_inverse(p)
        g = module.root_matrix(p)
        w = rng.normal(size=(2, 4, 3)).astype(dtype)
        pdot = module.pdot(p, w)
        back = module.omega(p, pdot)
        det = module.tangent_det(p)
    assert r.dtype == dtype and r.shape == (2, 4, 3, 3) and module.angle(p).shape == (2, 4)
    assert np.allclose(r @ np.swapaxes(r, -1, -2), np.eye(3), atol=tolerance)
    assert np.allclose(h @ h_inverse, np.eye(3), atol=tolerance)
    assert np.allclose(g @ g, r, atol=tolerance)
    assert np.allclose(back, w, atol=tolerance)
    from tests.reference import GeneratingFunction, Reference

    function = GeneratingFunction(PAPER_P[module.__name__.removeprefix("gen_")])
    reference = Reference(function)
    exact = np.array([float(reference.state([float(v) for v in q]).det_H) for q in p.reshape(-1, 3)])
    det_ulp = np.abs(det.reshape(-1).astype(np.float64) - exact) / (np.abs(exact) * np.finfo(dtype).eps)
    assert det_ulp.max() <= 4, det_ulp.max()  # det H against tests/reference.py (measured ≤ 1.0 ulp)
    assert np.array_equal(r[:, 0], np.broadcast_to(np.eye(3, dtype=dtype), (2, 3, 3)))


def test_outside_validity_is_nan() -> None:
    """One ulp either side of p_max = cbrt(12π) (from tests/reference.py, not the module), along
    an axis where |p|² is one rounding of s²: NaN outside, finite inside."""
    module = load(ROOT / "generated" / "numpy" / "det_h_one.py", "gen_det_h_one_nan")
    for dtype in (np.float64, np.float32):
        found = axis_probes(edge(FAMILIES["det_h_one"]), dtype)
        decided = [probe for probe in found if probe.inside is not None]
        outside = min((probe for probe in decided if not probe.inside), key=lambda probe: probe.step)
        inside = max((probe for probe in decided if probe.inside), key=lambda probe: probe.step)
        assert outside.step - inside.step <= 2, (outside, inside)
        p = np.array([outside.p, inside.p, [0.1, 0, 0]], dtype=dtype)
        with warnings.catch_warnings():
            warnings.simplefilter("error")
            r = module.rotation_matrix(p)
        assert np.isnan(r[0]).all() and np.isfinite(r[1:]).all(), dtype
        assert np.isnan(module.angle(p)[0]) and np.isfinite(module.angle(p)[1:]).all(), dtype


def test_tiny_rotation_keeps_its_digits() -> None:
    module = load(ROOT / "generated" / "numpy" / "det_h_one.py", "gen_det_h_one_tiny")
    p = np.array([1e-200, 0.0, 0.0])
    assert module.angle(p) == pytest.approx(1e-200, rel=1e-15)
    r = module.rotation_matrix(p)
    assert r[2, 1] == pytest.approx(1e-200, rel=1e-15)


def test_cli_emits_a_ruff_clean_module(tmp_path: Path) -> None:
    code = main(["derive", "cbrt(6*(phi - sin(phi)))", "--name", "user_eq35", "--emit", "numpy",
                 "--out", str(tmp_path)])
    assert code == 0
    path = tmp_path / "user_eq35.py"
    module = load(path, "user_eq35")
    from tests.reference import GeneratingFunction, Reference

    p = [0.3, 0.4, 0.0]
    exact = float(Reference(GeneratingFunction("cbrt(6*(phi - sin(phi)))", cancels=True)).state(p).angle)
    angle = float(module.angle(np.array(p)))
    assert abs(angle - exact) <= 4 * np.spacing(exact), (angle, exact)  # measured: 0 ulp
    ruff = subprocess.run([sys.executable, "-m", "ruff", "check", "--no-cache", "--isolated",
                           "--line-length", "110",
                           "--select", "E,F,W,B,UP,SIM,RUF", "--ignore", "RUF001,RUF002,RUF003", str(path)],
                          capture_output=True, text=True)
    assert ruff.returncode == 0, ruff.stdout


def test_cli_rejects_unknown_backend(tmp_path: Path, capsys) -> None:
    assert main(["derive", "phi", "--emit", "fortran", "--out", str(tmp_path)]) == 2
    assert "unknown backend" in capsys.readouterr().err


FOLD = {"euler_rodrigues": ("2*sin(phi/2)", "pi"), "sine_m3": ("3*sin(phi/3)", "3*pi/2"),
        "det_h_one": ("cbrt(6*(phi - sin(phi)))", "2*pi")}
"""p(φ) and φ_max (the fold of m sin(φ/m) at mπ/2; eq 35 folds at 2π) from the paper, not the plan."""


def _independent_sweep(name: str, points: int) -> dict[tuple[str, str], Any]:
    """{(function, precision): Worst} of the module ``name`` (generated/numpy, or emitted when it has
    none) against tests/reference.py (φ by Newton on p(φ), R from eq 1, H from ω = H ṗ), on the sweep
    of bench/accuracy_corpus.py: accuracy.sweep(φ_max, points) (φ_max − 10⁻ᵏ, k = 1…6) plus 1e-30,
    1e-8, 1e-3, 0.1 and 1, random axes; φ_max and p_max from the reference."""
    from types import SimpleNamespace

    from accuracy_common import load_module
    from accuracy_corpus import Measurement

    from symrot.api import derive
    from symrot.plan.builder import evaluation_plan
    from tests.reference import GeneratingFunction

    function = GeneratingFunction(FOLD[name][0], phi_max_text=FOLD[name][1])
    path = ROOT / "generated" / "numpy" / f"{name}.py"
    if path.exists():
        module = load(path, f"gen_{name}_independent")
    else:
        import tempfile

        module = load_module(evaluation_plan(derive(name).derivation, name), Path(tempfile.mkdtemp()))
    edge = SimpleNamespace(phi_max=function.phi_max, p_max=function.p_max())
    measurement = Measurement(function, edge, module, None, None, points)
    measurement.run()
    assert not measurement.errors, measurement.errors
    assert all(t.nonfinite == 0 for t in measurement.tallies.values())
    return {(f, label): t.worst for (f, label, _backend), t in measurement.tallies.items()}


@pytest.mark.parametrize("name", ["euler_rodrigues", "sine_m3"])
def test_accuracy_up_to_the_fold(name: str) -> None:
    """Up to φ_max − 10⁻⁶, where p′ → 0: every kernel within 4 ulp of the independent reference (the
    fold complement d = k² − |p|² is computed with compensated arithmetic; without it the error was
    10¹² ulp)."""
    worst = _independent_sweep(name, 8)
    vectors = ("pdot", "omega")  # a v + b p×v + c p×(p×v): a and c x cancel as μ → ∞ (κ ~ 1e12)
    # float32, and the operations (compose's result, from_quaternion's e, rescale's flip next to π),
    # may exceed 4 ulp only where the input is ill-conditioned (κ in the hundreds at 0.98 φ_max)
    operations = ("compose", "from_quaternion", "rescale")
    misses = {k: (v.ulp, v.at, v.kappa) for k, v in worst.items()
              if (v.excess > 4 if k[0] in vectors + operations or k[1] == "float32" else v.ulp > 4)}
    assert not misses, misses
    assert {"rotation_matrix", "tangent", "tangent_inverse", "pdot", "omega", "angle",
            "tangent_det"} <= {k[0] for k in worst}


def test_accuracy_is_backward_stable_without_closed_inverse() -> None:
    """eq 35 (Newton angle, triple fold at 2π): errors may exceed 4 ulp only where the input is
    ill-conditioned, and never by more than 4 κ ulp (κ: condition number w.r.t. the input p)."""
    worst = _independent_sweep("det_h_one", 8)
    misses = {k: (v.ulp, v.at, v.kappa) for k, v in worst.items() if v.excess > 4}
    assert not misses, misses


def test_the_newton_angle_of_eq_35_is_within_one_ulp() -> None:
    """The residual (φ − s) + φ(g − 1) of the Newton angle (plan_ir.NewtonAngle.leading), with
    g − 1 by its series up to φ ≈ 2.4 (|p| ≈ 2.15): φ within 1 ulp of the exact angle of the rounded
    |p| there (the residual φ·g − s with g = cbrt(6φ − 6 sin φ)/φ above φ = 0.89 left it 2.3 ulp
    off at φ = 1.04). Above, the closed form's cancellation of 6φ − 6 sin φ remains (2.5 ulp at
    |p| = 3.13, 2.4 before)."""
    import mpmath

    from tests.reference import GeneratingFunction

    module = load(ROOT / "generated" / "numpy" / "det_h_one.py", "gen_det_h_one_angle")
    function = GeneratingFunction("cbrt(6*(phi - sin(phi)))", cancels=True)
    rng = np.random.default_rng(20)
    sizes = np.concatenate([10.0 ** rng.uniform(-12, 0, 32), rng.uniform(0, 2.1, 128)])
    angles = module.angle(sizes[:, None] * np.array([0.0, 0.0, 1.0]))
    errors = []
    with mpmath.workdps(40):
        for size, angle in zip(sizes, angles, strict=True):
            exact = function.inverse(mpmath.mpf(float(size)), None)
            errors.append(float(abs(mpmath.mpf(float(angle)) - exact) / exact) / np.finfo(np.float64).eps)
    over = {float(size): error for size, error in zip(sizes, errors, strict=True) if error > 1.0}
    assert not over, over


def test_the_newton_angle_of_eq_35_above_its_series() -> None:
    """Above |p| ≈ 2.15 the residual takes the closed form g = cbrt(6φ − 6 sin φ)/φ, whose
    cancellation costs a few ulp of the angle, and the angle's condition κ = p/(φp′) grows towards the
    fold at 2π (23 at |p| = 3.35): within 2.5 κ ulp of the exact angle there (measured: 1.75 κ on
    400 points of [2.1, 3.35], 8.7 ulp at κ = 23)."""
    import mpmath

    from tests.reference import GeneratingFunction

    module = load(ROOT / "generated" / "numpy" / "det_h_one.py", "gen_det_h_one_upper")
    function = GeneratingFunction("cbrt(6*(phi - sin(phi)))", cancels=True)
    sizes = np.random.default_rng(21).uniform(2.1, 3.35, 128)
    angles = module.angle(sizes[:, None] * np.array([0.0, 0.0, 1.0]))
    over = {}
    with mpmath.workdps(40):
        for size, angle in zip(sizes, angles, strict=True):
            s = mpmath.mpf(float(size))
            exact = function.inverse(s, None)
            slope = 2 * (1 - mpmath.cos(exact)) / s**2  # p′ = 2(1 − cos φ)/p² for p³ = 6(φ − sin φ)
            kappa = max(1.0, float(s / (exact * slope)))
            error = float(abs(mpmath.mpf(float(angle)) - exact) / exact) / np.finfo(np.float64).eps
            if error > 2.5 * kappa:
                over[float(size)] = (error, kappa)
    assert not over, over


def test_the_angle_at_the_fold_is_one_that_rounds_to_the_input() -> None:
    """Eq 35 at |p| = p_max rounded (the fold at 2π, p_max − p ∝ (2π − φ)³): every angle within
    3·10⁻⁵ of 2π gives a p that rounds to that |p|, and the Newton angle must be one of them. It was
    5.93 for some axes: the residual at the clipped start 2π was positive by rounding, the bracket
    bisected to π, and Newton in φ converged only linearly towards the fold (the plan's check
    excused it: its first-order width ε s/p′ was infinite there; newton_start._width). Now the
    start and the last iterate are clipped to NewtonAngle.fold_top, the smallest angle whose p
    rounds like p_max (newton_start.fold_top)."""
    import mpmath

    from tests.reference import GeneratingFunction

    module = load(ROOT / "generated" / "numpy" / "det_h_one.py", "gen_det_h_one_fold")
    function = GeneratingFunction("cbrt(6*(phi - sin(phi)))", cancels=True)
    rng = np.random.default_rng(35)
    axes = rng.normal(size=(48, 3))
    axes /= np.linalg.norm(axes, axis=1, keepdims=True)
    p_max = float(mpmath.cbrt(12 * mpmath.pi))
    points = [axis * p_max * (1 - k * 2.0 ** -53) for axis in axes for k in (0, 1, 2)]
    angles = module.angle(np.array(points))
    off = {}
    with mpmath.workdps(40):
        for point, angle in zip(points, angles, strict=True):
            if np.isnan(angle):  # |p|² rounds beyond p_max²: outside the range
                continue
            exact = function.inverse(mpmath.sqrt(sum(mpmath.mpf(float(c)) ** 2 for c in point)), None)
            if abs(angle - exact) > 3e-5:
                off[tuple(point)] = float(angle)
    assert not off, off
    assert np.sum(~np.isnan(angles)) > 48


def test_operations_accuracy_on_a_small_grid() -> None:
    from accuracy_operations import measure_operations

    worst = measure_operations("sine_m4", 6)
    misses = {k: (v.ulp, v.at, v.kappa) for k, v in worst.items() if v.excess > 4}
    assert not misses, misses
    assert {k[0] for k in worst} == {"to_quaternion", "from_quaternion", "from_rotation_matrix", "compose",
                                     "rescale"}


@pytest.mark.parametrize("name", ["rotation_vector", "wiener_milenkovic", "euler_rodrigues", "det_h_one"])
@pytest.mark.parametrize("dtype", [np.float64, np.float32])
def test_batch_size_does_not_change_the_bits(name: str, dtype: type) -> None:
    """_tensor takes scalar arithmetic for a few vectors, gathered NumPy calls up to _SMALL and
    4096-vector blocks above: the same rows give the same bits on every path, also across the
    coefficients' series switches and with |p| from 1e-30 to the edge of the range."""
    module = load(ROOT / "generated" / "numpy" / f"{name}.py", f"gen_{name}_sizes")
    rng = np.random.default_rng(11)
    axes = rng.normal(size=(300, 3))
    axes /= np.linalg.norm(axes, axis=1)[:, None]
    top = min(0.999 * module.P_MAX, 1e6)  # |p| (unbounded for Wiener-Milenkovic)
    angles = np.concatenate([10.0 ** rng.uniform(-30, 0, 100), rng.uniform(0, top, 200)])
    p = (axes * angles[:, None]).astype(dtype)
    few = module._FEW[np.dtype(dtype).char]
    assert 1 <= few < module._SMALL < len(p)
    for function in (module.rotation_matrix, module.tangent, module.tangent_inverse, module.root_matrix):
        whole = function(p)  # blocks
        assert np.isfinite(whole).all()
        for size in (1, few, few + 1, module._SMALL):
            parts = np.concatenate([function(p[start:start + size]) for start in range(0, len(p), size)])
            assert np.array_equal(parts, whole), (function.__name__, size)
