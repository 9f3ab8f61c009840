"""The domain of generated code for unbounded p (issue 17): right up to x_limit, NaN beyond it.

Wiener–Milenkovic's tangent was 1.6e-159·I for p = (6e79, 8e79, 0) (exact first row
[-4.48e-160, 1.536e-159, 1.024e-238]) because 128/(x + 16)² overflowed; the plan's x_limit
(symrot/domain.py) now ends the domain before any printed form goes wrong, and the C header and the
NumPy module both print it."""

from __future__ import annotations

import math
from pathlib import Path

import mpmath
import numpy as np
import pytest

from symrot.api import derive
from symrot.core import tensor_definitions
from symrot.plan import evaluation_plan
from tests.helpers import axial_matrix
from tests.test_numpy_backend import load

ROOT = Path(__file__).resolve().parent.parent
UNBOUNDED = ("wiener_milenkovic", "cayley_gibbs_rodrigues")
FUNCTIONS = {"rotation_matrix": "R", "tangent": "H", "tangent_inverse": "H_inverse", "root_matrix": "G",
             "root_tangent": "K"}


def _reference(name: str, tensor: str, p: np.ndarray) -> np.ndarray:
    """The tensor at p from the derivation's u-basis form, φ = 4 atan(s/4) or 2 atan(s/2), 200 digits."""
    expression = derive(name).p
    with mpmath.workdps(200):
        vector = mpmath.matrix([mpmath.mpf(float(c)) for c in p])
        s = mpmath.norm(vector)
        phi = _closed_inverse(name, s)
        matrix = axial_matrix(tensor_definitions(expression)[tensor], phi, vector / s)
        return np.array([[float(matrix[i, j]) for j in range(3)] for i in range(3)])


def _closed_inverse(name: str, s: mpmath.mpf) -> mpmath.mpf:
    return 4 * mpmath.atan(s / 4) if name == "wiener_milenkovic" else 2 * mpmath.atan(s / 2)


@pytest.mark.parametrize("name", UNBOUNDED)
def test_numpy_module_is_right_below_x_limit_and_nan_beyond(name: str) -> None:
    module = load(ROOT / "generated" / "numpy" / f"{name}.py", f"domain_{name}")
    plan = evaluation_plan(derive(name).derivation, name)
    axis = np.array([0.6, 0.8, 0.0])
    for label, dtype in (("float64", np.float64), ("float32", np.float32)):
        limit = plan.precisions[label].x_limit
        assert limit < (2.0**600 if dtype is np.float64 else 2.0**100)  # the forms do overflow earlier
        eps = float(np.finfo(dtype).eps)
        inside = axis * math.sqrt(limit) * 0.5
        outside = axis * math.sqrt(limit) * 1.01
        for function, tensor in FUNCTIONS.items():
            got = getattr(module, function)(inside.astype(dtype)).astype(np.float64)
            exact = _reference(name, tensor, inside.astype(dtype).astype(np.float64))
            assert np.all(np.isfinite(got)), (function, label)
            assert np.max(np.abs(got - exact)) <= 64 * eps * np.max(np.abs(exact)), (function, label)
            assert np.all(np.isnan(getattr(module, function)(outside.astype(dtype)))), (function, label)


def test_the_reported_wiener_milenkovic_tangent_is_nan_not_wrong() -> None:
    module = load(ROOT / "generated" / "numpy" / "wiener_milenkovic.py", "domain_wm_report")
    assert np.all(np.isnan(module.tangent(np.array([6e79, 8e79, 0.0]))))


def test_c_header_prints_the_same_limit() -> None:
    plan = evaluation_plan(derive("wiener_milenkovic").derivation, "wiener_milenkovic")
    header = (ROOT / "generated" / "c" / "symrot_wiener_milenkovic.h").read_text(encoding="utf-8")
    for label in ("float64", "float32"):
        power = math.frexp(plan.precisions[label].x_limit)[1] - 1
        assert f"|p|^2 < 2^{power}" in header
