"""Figures 1–4: the plotted data is the derivation's (not pixels), with no spikes at poles."""

from __future__ import annotations

import mpmath
import numpy as np
import pytest

from symrot.backends.figures import FAMILY_ORDERS, FIGURES, QUANTITY_LIMITS, build_figure, render
from symrot.cli import main
from symrot.core import derive_expression
from symrot.registry import family_member, lookup

from .helpers import mp_function


@pytest.mark.parametrize("number", sorted(FIGURES))
def test_plotted_data_matches_the_derivation(number: int) -> None:
    family, quantities = FIGURES[number]
    figure = build_figure(number)
    expected_entries = [family_member(family, m).expression for m in FAMILY_ORDERS]
    expected_entries.append(lookup("rotation_vector").expression)
    for ax, quantity in zip(figure.axes, quantities, strict=True):
        lines = ax.get_lines()
        assert len(lines) == len(expected_entries)
        low, high = QUANTITY_LIMITS[quantity]
        for line, p in zip(lines, expected_entries, strict=True):
            d = derive_expression(p)
            expr = d.p if quantity == "p" else d.scalars_raw[quantity]
            reference = mp_function(expr)
            phi, values = np.asarray(line.get_xdata()), np.asarray(line.get_ydata())
            shown = np.flatnonzero(np.isfinite(values))
            assert len(shown) > 50
            assert np.all((values[shown] >= low) & (values[shown] <= high))
            # No segment is drawn across a singularity: consecutive shown points stay close.
            pairs = shown[np.flatnonzero(np.diff(shown) == 1)]
            assert np.all(np.abs(values[pairs + 1] - values[pairs]) <= (high - low) / 2)
            for index in shown[1::97]:
                exact = reference(mpmath.mpf(float(phi[index])))
                assert abs(values[index] - float(exact)) <= 1e-9 * max(1.0, abs(float(exact)))


def test_pole_of_tan_is_interrupted() -> None:
    figure = build_figure(2)
    first = figure.axes[0].get_lines()[0]  # tan(phi): poles at pi/2 and 3pi/2
    phi, values = np.asarray(first.get_xdata()), np.asarray(first.get_ydata())
    near_pole = np.abs(phi - np.pi / 2) < 0.05
    assert np.isnan(values[near_pole]).any()


def test_plot_cli_with_a_user_curve_is_reproducible(tmp_path) -> None:  # type: ignore[no-untyped-def]
    args = ["plot", "--figure", "3", "--format", "png", "--add", "cbrt(6*(phi-sin(phi)))"]
    assert main([*args, "--out", str(tmp_path / "a")]) == 0
    assert main([*args, "--out", str(tmp_path / "b")]) == 0
    first = (tmp_path / "a" / "figure3.png").read_bytes()
    assert first == (tmp_path / "b" / "figure3.png").read_bytes()
    assert first.startswith(b"\x89PNG")
    assert render(3, "pdf")[:4] == b"%PDF"
