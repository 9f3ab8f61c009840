"""Figures 1–4: the plotted data is the derivation's (not pixels), laid out for a journal."""

from __future__ import annotations

import shutil
import subprocess
from pathlib import Path

import mpmath
import numpy as np
import pytest

from symrot.backends.figures import DPI, FAMILY_ORDERS, FIGURES, STYLES, build_figure, pi_label, render
from symrot.cli import main
from symrot.core.derivation import derive_expression
from symrot.core.registry import family_member, lookup

from .helpers import mp_function


@pytest.mark.parametrize("number", sorted(FIGURES))
def test_plotted_data_matches_the_derivation(number: int) -> None:
    family, quantities = FIGURES[number]
    figure = build_figure(number)
    assert not figure.texts and all(not ax.get_title() for ax in figure.axes)  # no baked-in title
    expected_entries = [family_member(family, m).expression for m in FAMILY_ORDERS]
    expected_entries.append(lookup("rotation_vector").expression)
    for ax, quantity in zip(figure.axes, quantities, strict=True):
        low, high = ax.get_ylim()
        lines = [line for line in ax.get_lines() if len(line.get_xdata()) > 1]
        assert len(lines) == len(expected_entries)
        for line, p in zip(lines, expected_entries, strict=True):
            d = derive_expression(p)
            expr = d.p if quantity == "p" else d.scalars_raw[quantity]
            reference = mp_function(expr)
            phi, values = np.asarray(line.get_xdata()), np.asarray(line.get_ydata())
            shown = np.flatnonzero(np.isfinite(values))
            assert np.count_nonzero((values >= low) & (values <= high)) > 50
            # No segment is drawn across a pole: consecutive drawn points stay within a panel.
            pairs = shown[np.flatnonzero(np.diff(shown) == 1)]
            assert np.all(np.abs(values[pairs + 1] - values[pairs]) <= high - low)
            for index in shown[1::97]:
                exact = reference(mpmath.mpf(float(phi[index])))
                assert abs(values[index] - float(exact)) <= 1e-12 * max(1.0, abs(float(exact)))
        assert np.allclose(ax.get_xticks(), np.arange(5) * np.pi / 2)
    labels = [t.get_text() for t in figure.axes[-1].get_xticklabels()]
    assert labels == [pi_label(k) for k in range(5)] == ["$0$", r"$\pi/2$", r"$\pi$", r"$3\pi/2$", r"$2\pi$"]


def test_y_limits_come_from_the_data_and_clips_are_shown() -> None:
    figure = build_figure(2)  # tangent family: poles inside the panel
    ax = figure.axes[0]
    low, high = ax.get_ylim()
    assert 2 * np.pi < high < 100 and -100 < low < 0  # not fixed, not swamped by the poles
    assert ax.texts, "an arrow on the frame marks each clipped curve"
    sine = build_figure(1).axes[0]
    assert sine.get_ylim()[1] < 2 * np.pi * 1.1  # bounded family: tight around the data


def test_pole_of_tan_is_interrupted() -> None:
    figure = build_figure(2)
    first = figure.axes[0].get_lines()[0]  # tan(phi): poles at pi/2 and 3pi/2
    phi, values = np.asarray(first.get_xdata()), np.asarray(first.get_ydata())
    near_pole = np.abs(phi - np.pi / 2) < 0.05
    assert np.isnan(values[near_pole]).any()


def test_validity_bounds_are_marked() -> None:
    ax = build_figure(1).axes[0]  # sine family: bounds m pi/2 for m = 1..4
    marks = [line for line in ax.get_lines() if len(line.get_xdata()) == 1]
    assert sorted(float(line.get_xdata()[0]) for line in marks)[:4] == pytest.approx(
        [np.pi / 2, np.pi, 3 * np.pi / 2, 2 * np.pi])


@pytest.mark.parametrize("style", sorted(STYLES))
def test_style_width_and_png_resolution(style: str) -> None:
    figure = build_figure(1, style=style)
    assert figure.get_size_inches()[0] == STYLES[style].width
    png = render(1, "png", style=style)
    width = int.from_bytes(png[16:20], "big")
    assert width == round(STYLES[style].width * DPI) and DPI >= 300


@pytest.mark.skipif(shutil.which("pdffonts") is None, reason="needs poppler (make setup-system)")
@pytest.mark.parametrize("number", sorted(FIGURES))
def test_figure_pdfs_embed_no_type_3_fonts(number: int, tmp_path: Path) -> None:
    pdf = tmp_path / f"figure{number}.pdf"
    pdf.write_bytes(Path(f"generated/figures/figure{number}.pdf").read_bytes())
    fonts = subprocess.run(["pdffonts", str(pdf)], capture_output=True, text=True,
                           check=True).stdout
    assert "Type 3" not in fonts and "TrueType" in fonts


def test_legend_labels_are_math() -> None:
    figure = build_figure(3, extra=(derive_expression(lookup("det_h_one").expression).p,))
    labels = [t.get_text() for t in figure.legends[0].get_texts()]
    assert labels[:6] == [*(f"$m = {m}$" for m in FAMILY_ORDERS), r"$p = \varphi$"]
    assert labels[-1].startswith(r"$p = \sqrt[3]{") and labels[-1].endswith("$")


def test_plot_cli_with_a_user_curve_is_reproducible(tmp_path) -> None:  # type: ignore[no-untyped-def]
    args = ["plot", "--figure", "3", "--format", "png", "--style", "two-column",
            "--add", "cbrt(6*(phi-sin(phi)))"]
    assert main([*args, "--out", str(tmp_path / "a")]) == 0
    assert main([*args, "--out", str(tmp_path / "b")]) == 0
    first = (tmp_path / "a" / "figure3.png").read_bytes()
    assert first == (tmp_path / "b" / "figure3.png").read_bytes()
    assert first.startswith(b"\x89PNG")
    assert render(3, "pdf")[:4] == b"%PDF"
