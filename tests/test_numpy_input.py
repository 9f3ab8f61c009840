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


@pytest.mark.parametrize("order", [">", "<", "="])
@pytest.mark.parametrize("bits", ["4", "8"])
def test_any_byte_order_keeps_its_precision(wiener_milenkovic, order: str, bits: str) -> None:  # type: ignore[no-untyped-def]
    """A big-endian float32 p was computed and returned in float64 (issue 55, item 7)."""
    expected = np.float32 if bits == "4" else np.float64
    p = np.array([[0.1, -0.2, 0.3], [0.0, 0.0, 0.0]], dtype=order + "f" + bits)
    native = p.astype(expected)
    for function in (wiener_milenkovic.rotation_matrix, wiener_milenkovic.angle,
                     wiener_milenkovic.to_quaternion):
        result = function(p)
        assert result.dtype == expected, function.__name__
        np.testing.assert_array_equal(result, function(native))
    assert wiener_milenkovic.pdot(p, np.ones(3, dtype=order + "f" + bits)).dtype == expected


def test_masked_arrays_are_refused(wiener_milenkovic) -> None:  # type: ignore[no-untyped-def]
    """A numpy.ma masked array lost its mask silently (issue 55, item 7)."""
    masked = np.ma.masked_array([[0.1, 0.2, 0.3]], mask=[[False, True, False]])
    for function in (wiener_milenkovic.rotation_matrix, wiener_milenkovic.angle,
                     wiener_milenkovic.to_quaternion):
        with pytest.raises(ValueError, match="masked array"):
            function(masked)
    with pytest.raises(ValueError, match="masked array"):
        wiener_milenkovic.pdot(np.zeros(3), masked)


@pytest.mark.parametrize("name", ["cayley_gibbs_rodrigues", "rotation_vector", "sine_m4"])
def test_other_modules_keep_big_endian_precision_and_refuse_masks(name: str) -> None:
    module = load(GENERATED / f"{name}.py", f"input_{name}")
    p = np.array([0.1, -0.2, 0.3], dtype=">f4")
    assert module.rotation_matrix(p).dtype == np.float32
    assert module.rotation_matrix(p.astype(">f8")).dtype == np.float64
    with pytest.raises(ValueError, match="masked array"):
        module.rotation_matrix(np.ma.masked_array(p.astype(np.float64), mask=[True, False, False]))
