"""Code generation is bit-reproducible across machines (issue 15).

Nothing whose result depends on the CPU may feed ``generated/``: NumPy dispatches ``sin``,
``power``, ``geomspace``, … to SIMD kernels chosen at run time (their last bits differ between
AVX-512, AVX2 and baseline x86-64), and OpenBLAS picks its kernels by CPU (``OPENBLAS_CORETYPE``).
The plan layer therefore measures with :mod:`symrot.plan.evaluation` (an mpmath-backed ideal libm) and
fits with exact Chebyshev interpolation. These tests regenerate the files whose plans use every
such measurement (a Newton start and its fit: eq 35; closed forms with switches: the rotation
vector; the sine-family fold: euler_rodrigues) in fresh interpreters made to behave like other
machines, and compare bytes with ``generated/``.
"""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import mpmath
import numpy as np
import pytest
import sympy as sp

from symrot.core.parsing import PHI
from symrot.plan.evaluation import log_grid, model_function
from symrot.plan.newton_start import chebyshev_interpolant, clenshaw

from .blas_core import openblas_core

ROOT = Path(__file__).resolve().parent.parent
NAMES = ("det_h_one", "rotation_vector", "euler_rodrigues")
RENDER = """
import sys
from tests.blas_core import openblas_core
from symrot.api import derive
from symrot.backends.numpy_backend import module_source
from symrot.plan.builder import evaluation_plan
import mpmath.libmp
import sympy.external.gmpy
sys.stdout.write(str(openblas_core()) + "\\0")
sys.stdout.write(mpmath.libmp.BACKEND + " " + sympy.external.gmpy.GROUND_TYPES + "\\0")
for name in sys.argv[1:]:
    sys.stdout.write(module_source(evaluation_plan(derive(name).derivation, name)))
    sys.stdout.write("\\0")
"""


def _numpy_dispatched_features() -> list[str]:
    """The SIMD targets NumPy dispatches to on this CPU (beyond its baseline)."""
    from numpy._core import _multiarray_umath as umath

    return [f for f in umath.__cpu_dispatch__ if umath.__cpu_features__.get(f)]


def _other_machine() -> dict[str, str]:
    """An environment in which this CPU computes like another machine: NumPy without its SIMD targets
    beyond the baseline (as on a CPU without AVX2/AVX-512) and OpenBLAS with another kernel set on
    one thread, chosen to differ from the set OpenBLAS picks for this CPU (Haswell and Zen, tried
    here before, are that set or its copy on AMD EPYC: they repeated the native run)."""
    native = (openblas_core() or "").lower()
    machine = {"OPENBLAS_CORETYPE": "Nehalem" if native == "sandybridge" else "Sandybridge",
               "OPENBLAS_NUM_THREADS": "1",
               # and without GMP: mpmath's and SymPy's pure-Python integers (an install without gmpy2)
               "MPMATH_NOGMPY": "1", "SYMPY_GROUND_TYPES": "python"}
    features = " ".join(_numpy_dispatched_features())
    if features:
        machine["NPY_DISABLE_CPU_FEATURES"] = features
    return machine


@pytest.mark.slow
def test_generated_numpy_modules_are_the_same_on_another_cpu() -> None:
    machine = _other_machine()
    env = {**os.environ, **machine}
    result = subprocess.run([sys.executable, "-c", RENDER, *NAMES], capture_output=True, text=True,
                            env=env, cwd=ROOT, timeout=600, check=False)
    assert result.returncode == 0, result.stderr[-2000:]
    core, integers, *rendered = result.stdout.split("\0")[:-1]
    assert integers == "python python", integers  # mpmath's and SymPy's integers without GMP
    if openblas_core() is not None:  # the variant took effect: OpenBLAS runs other kernels
        assert core.lower() == machine["OPENBLAS_CORETYPE"].lower(), (core, machine)
    for name, text in zip(NAMES, rendered, strict=True):
        committed = (ROOT / "generated" / "numpy" / f"{name}.py").read_text(encoding="utf-8")
        assert text == committed, (f"generated/numpy/{name}.py differs under {machine}: "
                                   "the plan depends on the CPU")


def test_model_functions_are_correctly_rounded() -> None:
    """Each elementary call of the model is the nearest float to the exact value (mpmath, 60 digits)."""
    x = np.array([1e-300, 1e-8, 0.3, 1.0, 2.5, 6.2, 1e3])
    function = model_function(sp.sin(PHI) + 0 * PHI, [PHI])
    with mpmath.workdps(60):
        exact = [float(mpmath.sin(mpmath.mpf(float(v)))) for v in x]
    assert function(x).tolist() == exact
    single = model_function(sp.exp(-PHI / 3) * sp.atan(PHI), [PHI])(x.astype(np.float32))
    assert single.dtype == np.float32


def test_a_remembered_model_call_is_the_call_and_its_result_belongs_to_the_caller() -> None:
    """The model remembers whole results of an elementary call by its arguments' bytes (a plan makes
    the same call dozens of times): a repeated call returns the same values in the same dtype, a
    caller that writes into a result changes no later one, and arguments that differ in one lane,
    in dtype or in shape are other calls."""
    from symrot.plan import evaluation

    evaluation._ARRAYS.clear()
    sine = model_function(sp.sin(PHI / 2), [PHI])
    x = np.array([0.1, 1.0, 3.0])
    first = sine(x)
    first[:] = -7.0  # the caller owns what it got
    again = sine(x)
    with mpmath.workdps(60):
        exact = [float(mpmath.sin(mpmath.mpf(float(v)) / 2)) for v in x]
        moved = float(mpmath.sin(mpmath.mpf(1.75)))
    assert again.tolist() == exact
    other = x.copy()
    other[2] = 3.5
    assert sine(other)[2] == moved
    assert sine(x.astype(np.float32)).dtype == np.float32
    assert sine(x[:2]).shape == (2,)
    assert float(sine(np.float64(1.0))) == exact[1]
    assert len(evaluation._ARRAYS) == 5


def test_a_model_source_is_printed_once_per_form_and_can_come_from_another_process() -> None:
    """Model sources are remembered per (form, variables): the plan prints the candidate forms'
    models where it computes the forms (half in a forked child) and takes the child's sources."""
    from symrot.plan import evaluation

    form = sp.cos(PHI / 3) / (1 + PHI**2)
    key = evaluation.model_key(form, [PHI])
    source = evaluation.model_source(key)
    assert evaluation.model_source(key) is source
    evaluation._SOURCES.pop(key)
    evaluation.remember_sources({key: source})
    assert evaluation.model_source(key) is source
    with mpmath.workdps(60):
        cosine = float(mpmath.cos(mpmath.mpf(2 / 3)))  # the model's cos is correctly rounded
    assert model_function(form, [PHI])(np.array([2.0])).tolist() == [cosine / 5]


def test_model_treats_points_off_the_real_domain_as_nan() -> None:
    values = model_function(sp.sqrt(1 - PHI) + sp.asin(PHI), [PHI])(np.array([0.5, 2.0]))
    assert np.isfinite(values[0]) and np.isnan(values[1])


def test_model_evaluates_sign_on_arrays() -> None:
    """sign appears in derived slopes (asinh(tan(phi)): |cos φ| sign(cos φ)); it printed as a scalar
    conditional and made the emit of that corpus function an internal error on arrays."""
    function = model_function(sp.sign(sp.cos(PHI)) * sp.Abs(sp.cos(PHI)), [PHI])
    x = np.array([0.0, 1.0, 2.0, 4.0, 5.0])
    assert function(x).tolist() == model_function(sp.cos(PHI), [PHI])(x).tolist()  # no libm of the CPU
    assert function(x.astype(np.float32)).dtype == np.float32


def test_log_grid_is_exact_at_the_ends_and_monotone() -> None:
    grid = log_grid(1e-7, 6.283185307179586, 56)
    assert grid[0] == 1e-7 and grid[-1] == 6.283185307179586 and np.all(np.diff(grid) > 0)
    with mpmath.workdps(40):
        ratio = mpmath.mpf(grid[1]) / mpmath.mpf(grid[0])
    assert abs(float(ratio) - (6.283185307179586 / 1e-7) ** (1 / 55)) < 1e-13


def test_chebyshev_interpolant_reproduces_a_polynomial_exactly() -> None:
    # 1 − 2y + 3y³ = T₀ + T₁/4 + 3T₃/4
    coefficients = chebyshev_interpolant(lambda y: 1 - 2 * y + 3 * y**3, 5)
    assert np.allclose(coefficients, [1, 0.25, 0, 0.75, 0, 0], atol=1e-15)
    y = np.linspace(-1, 1, 7)
    assert np.allclose(clenshaw(coefficients, y), 1 - 2 * y + 3 * y**3, atol=1e-15)


def test_symrot_fixes_the_dummy_base_when_imported() -> None:
    """SymPy draws the base of its Dummy numbering at random per process (symrot.entry)."""
    from symrot.core.parsing import DUMMY_BASE

    assert sp.Dummy._base_dummy_index == DUMMY_BASE


def test_the_commands_run_with_a_fixed_hash_seed(tmp_path: Path) -> None:
    (tmp_path / "print_seed.py").write_text("import os\nprint(os.environ['PYTHONHASHSEED'])\n")
    driver = "from symrot.entry import run_with_fixed_hash_seed\nrun_with_fixed_hash_seed('print_seed')\n"
    for seed in ("random", "7"):
        environment = {**os.environ, "PYTHONHASHSEED": seed,
                       "PYTHONPATH": os.pathsep.join([str(tmp_path), str(ROOT)])}
        done = subprocess.run([sys.executable, "-c", driver], env=environment, capture_output=True,
                              text=True, timeout=60, check=True)
        assert done.stdout.strip() == "0"


@pytest.mark.slow
def test_a_user_module_is_the_same_whatever_the_hash_seed(tmp_path: Path) -> None:
    """sinh(phi) has equally accurate forms that differ only in sign arrangement; which one SymPy
    returned followed the process's hash seed and Dummy base: 4 different modules in 16 runs."""
    runs = {seed: subprocess.Popen(
        [sys.executable, "-m", "symrot", "derive", "sinh(phi)", "--emit", "numpy", "--out",
         str(tmp_path / seed), "-q"], env={**os.environ, "PYTHONHASHSEED": seed},
        stdout=subprocess.DEVNULL) for seed in ("1", "2")}
    for run in runs.values():
        assert run.wait(timeout=300) == 0
    first, second = ((tmp_path / seed / "rotation.py").read_bytes() for seed in runs)
    assert first == second


def test_symrot_keeps_sympys_assumption_facts_in_their_listed_order() -> None:
    """SymPy shuffles the facts its assumptions system tries with a generator seeded from the OS,
    and the order decides whether a sign query answers: ``derive 'sinh(phi)' --emit numpy`` wrote
    one of two modules (the base-angle reduction of K₂ returned either sign arrangement), so the
    next test failed in one run of three (symrot.core.parsing turns the shuffle off)."""
    import importlib

    facts = list(range(32))
    importlib.import_module("sympy.core.assumptions").shuffle(facts)
    assert facts == list(range(32))
