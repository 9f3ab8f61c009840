"""Long-run test of issue 6 (short version of bench/long_run.py): N = 10⁴ compositions in C.

A body tumbles at constant angular velocity about a fixed random axis: starting from p = 0 the
generated C ``compose`` (double) applies the rotation by δ = 0.01 rad N times (16 turns). The C
driver checks at every step: status 0, no NaN, |p_k| ≤ p(π)(1 + 1e-12), and the orientation error
against the exact rotation by kδ (long double) ≤ c (k + 1) ε, the worst-case bound derived in
``bench/long_run.py``. Here the observed error must also stay under an empirical ceiling of
64 √k ε at every k ≤ N = 10⁴ (measured: ≤ 8.3 √k ε for these parameterizations; at N = 10⁶ the error
grows nearly linearly, ≤ 0.04 ε per step, see docs/long_run.md), about 100 times below the worst-case
bound c (N + 1) ε at this N: it catches a systematic drift (e.g. a biased rescaling) that the
worst-case bound would only see after many more steps.
"""

from __future__ import annotations

import math
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "bench"))

import long_run  # noqa: E402

COUNT = 10_000
RANDOM_WALK = 64.0


@pytest.mark.parametrize("name", ["rotation_vector", "wiener_milenkovic", "sine_m4", "tangent_m3",
                                  long_run.USER_NAME])
def test_long_run(name: str, tmp_path: Path) -> None:
    result = long_run.run(name, COUNT, delta=0.01, seed=6, directory=tmp_path)
    assert result.passed, f"{name}: {result.failure} at step {result.failed_step}"
    assert result.max_norm <= result.p_pi * (1 + 1e-12)
    # the rescaling happened: |φ| came close to π (δ = 0.01 past π flips it)
    assert result.max_norm >= result.p_pi * 0.99
    assert result.max_error <= result.bound
    assert result.max_sqrt_ratio <= RANDOM_WALK * long_run.EPS, result.max_sqrt_ratio / long_run.EPS
    assert result.final_error <= RANDOM_WALK * math.sqrt(COUNT) * long_run.EPS


def test_driver_detects_a_wrong_step(tmp_path: Path) -> None:
    """The checks can fail: with a per-step bound c = 0.01 the driver must stop at the first step
    (its error, a few ε, exceeds 0.02 ε) and report it."""
    header = long_run.header("rotation_vector", tmp_path)
    binary = long_run.compile_driver("rotation_vector", header, tmp_path)
    axis = long_run.random_axis(6)
    out = subprocess.run([str(binary), "100", "0.01", *map(repr, axis), repr(math.pi), "0.01"],
                         capture_output=True, text=True, check=False)
    assert out.returncode == 1 and "bad=error" in out.stdout, out.stdout
    # and a norm bound below p(π) is caught as soon as |p| exceeds it
    out = subprocess.run([str(binary), "1000", "0.01", *map(repr, axis), "1.0", "1e6"],
                         capture_output=True, text=True, check=False)
    assert out.returncode == 1 and "bad=norm step=101" in out.stdout, out.stdout
