"""Input handling of the generated NumPy modules (issue 17): wrong dtypes and shapes are a clear
ValueError, never a silent conversion."""

from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np
import pytest

from tests.test_numpy_backend import load

GENERATED = Path(__file__).resolve().parent.parent / "generated" / "numpy"


@pytest.fixture(scope="module")
def wiener_milenkovic():  # type: ignore[no-untyped-def]
    return load(GENERATED / "wiener_milenkovic.py", "input_wm")


@pytest.mark.parametrize("bad", [np.array([1 + 1j, 0, 0]), np.array([True, False, True]),
                                 np.array(["1", "2", "3"]), np.array([1.0, 2.0, 3.0], dtype=object),
                                 np.array(["2026-01-01"] * 3, dtype="datetime64[D]")],
                         ids=["complex", "bool", "str", "object", "datetime"])
def test_non_real_input_is_a_value_error(wiener_milenkovic, bad: np.ndarray) -> None:  # type: ignore[no-untyped-def]
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # no ComplexWarning on the way to the error either
        for function in (wiener_milenkovic.rotation_matrix, wiener_milenkovic.angle,
                         wiener_milenkovic.to_quaternion):
            with pytest.raises(ValueError, match="real float or integer"):
                function(bad)
        with pytest.raises(ValueError, match="real float or integer"):
            wiener_milenkovic.pdot(np.zeros(3), bad)


def test_second_argument_shape_is_checked(wiener_milenkovic) -> None:  # type: ignore[no-untyped-def]
    for function in (wiener_milenkovic.pdot, wiener_milenkovic.omega):
        with pytest.raises(ValueError, match=r"second argument must have shape \(\.\.\., 3\)"):
            function(np.zeros(3), np.ones(2))
        assert function(np.zeros((4, 3)), np.ones(3)).shape == (4, 3)  # broadcasting still works


def test_integer_input_is_float64(wiener_milenkovic) -> None:  # type: ignore[no-untyped-def]
    assert wiener_milenkovic.rotation_matrix([1, 2, 3]).dtype == np.float64
    assert wiener_milenkovic.rotation_matrix(np.array([1, 2, 3], dtype=np.int8)).dtype == np.float64
