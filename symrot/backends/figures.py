"""Figures 1–4 of the paper, regenerated from the derivation with matplotlib.

Figures 1–2: p(φ) for the sine and tangent families m = 1…5 (eq 36), with the rotation vector
dotted. Figures 3–4: ν (15), p′ and det H (24) versus φ for each family (top, middle, bottom).

Values are the derived closed forms evaluated with mpmath at 20 digits and rounded to double, so
the plotted data does not depend on the CPU's vector math (NumPy's transcendental functions differ
in the last bit between machines); φ = 0 takes the exact limit from the series engine.

Layout for journals: no titles (captions belong to the document); x ticks at multiples of π/2
labelled in π; each member's validity bound (its first singular angle, Section 3.4) marked with its marker
on the φ axis;
y-limits from the data, with a window of π/6 around each pole left out, and wherever a curve
leaves the panel an arrow on the frame shows the clip; a curve is broken across a pole, so no
vertical spike is drawn. ``style`` sets the width of one journal column (3.5 in) or two (7 in).
Fonts are STIX (bundled with matplotlib) embedded as TrueType (Type 42), never Type 3; PNGs are
300 dpi. Output is reproducible byte for byte (no dates, a fixed producer).
"""

from __future__ import annotations

import io
from dataclasses import dataclass
from functools import lru_cache
from typing import TYPE_CHECKING, Any

import mpmath
import numpy as np
import sympy as sp

from symrot.backends.latex import QUANTITY_SYMBOLS, latex
from symrot.core.derivation import Derivation, derive_expression
from symrot.core.functions import mpmath_namespace
from symrot.core.parsing import PHI
from symrot.core.registry import family_member, lookup

if TYPE_CHECKING:
    from collections.abc import Sequence

    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

MARKERS = {1: "+", 2: "s", 3: "^", 4: "o", 5: "v"}
"""The paper's markers: m = 1 (+), 2 (□), 3 (△), 4 (○), 5 (▽) (captions of Figures 1–4)."""
FAMILY_ORDERS = (1, 2, 3, 4, 5)
ANGLE_RANGE = (0.0, 2 * np.pi)
SAMPLES = 721
"""Every quarter degree on [0, 2π]; multiples of π/2 fall on samples."""
POLE_WINDOW = np.pi / 6
"""Half-width of the window around a pole that the y-limits leave out."""
QUANTILES = (0.02, 0.98)
PADDING = 0.05
DIGITS = 20
QUANTITY_LABELS = {q: f"${QUANTITY_SYMBOLS[q]}$" for q in ("nu", "p_prime", "det_H")}
QUANTITY_LABELS["p"] = r"$p(\varphi)$"
FIGURES = {
    1: ("sine", ("p",)),
    2: ("tangent", ("p",)),
    3: ("sine", ("nu", "p_prime", "det_H")),
    4: ("tangent", ("nu", "p_prime", "det_H")),
}


@dataclass(frozen=True)
class Style:
    """A journal layout: figure width (in), height of one panel (in), font size (pt)."""

    width: float
    panel_height: float
    font_size: float


STYLES = {"one-column": Style(3.5, 1.9, 8.0), "two-column": Style(7.0, 2.6, 9.0)}
DEFAULT_STYLE = "one-column"
DPI = 300
RC: dict[str, Any] = {"pdf.fonttype": 42, "ps.fonttype": 42, "font.family": "serif",
      "font.serif": ["STIXGeneral"], "mathtext.fontset": "stix", "axes.linewidth": 0.6,
      "lines.linewidth": 0.9, "xtick.major.width": 0.6, "ytick.major.width": 0.6,
      "svg.hashsalt": "symrot"}
"""TrueType (Type 42) fonts, matplotlib's bundled STIX for text and math."""


def _rc(style: str) -> Any:
    """The rcParams of ``style`` (``Any``: matplotlib types its keys as literals)."""
    return {**RC, "font.size": STYLES[style].font_size}


@dataclass(frozen=True)
class Curve:
    label: str
    marker: str | None
    dotted: bool
    phi: np.ndarray
    values: np.ndarray
    """The closed form on the grid, NaN where undefined (at a pole)."""
    bound: float | None
    """The validity bound (Section 3.4) when it lies in (0, 2π]: marked on the φ axis."""
    poles: tuple[float, ...]
    """Angles in (0, 2π] where the plotted quantity itself is infinite."""


def numeric(derivation: Derivation, quantity: str) -> sp.Expr:
    return derivation.p if quantity == "p" else derivation.scalars_raw[quantity]


def evaluate(derivation: Derivation, quantity: str, phi: np.ndarray) -> np.ndarray:
    """The derived closed form on the grid at 20 digits, rounded to double; NaN at a pole;
    φ = 0 gets the exact limit (series engine)."""
    function = sp.lambdify(PHI, numeric(derivation, quantity),
                           modules=[mpmath_namespace(), "mpmath"])
    values = np.empty_like(phi)
    with mpmath.workdps(DIGITS):
        for index, angle in enumerate(phi):
            try:
                value = function(mpmath.mpf(float(angle)))
            except (ZeroDivisionError, ValueError):
                value = mpmath.nan
            values[index] = float(value.real if isinstance(value, mpmath.mpc) else value)
    at_zero = phi == 0
    if at_zero.any():
        limit = 0.0 if quantity == "p" else float(derivation.taylor_in_phi(quantity, 1)[0])
        values[at_zero] = limit
    return values


def _singularities(derivation: Derivation, quantity: str) -> tuple[float | None,
                                                                    tuple[float, ...]]:
    """(validity bound if in range, poles of ``quantity`` in range) from Section 3.4's analysis."""
    from symrot.core.singularities import validity

    result = validity(derivation)
    in_range = [s for s in result.singularities if s.phi_float <= ANGLE_RANGE[1] + 1e-9]
    poles = tuple(sorted({s.phi_float for s in in_range
                          if s.quantity == quantity and s.limit == "oo"}))
    bound = result.phi_max_float if result.phi_max_float <= ANGLE_RANGE[1] + 1e-9 else None
    return bound, poles


@lru_cache(maxsize=32)
def curves(family: str, quantity: str, extra: tuple[sp.Expr, ...] = ()) -> tuple[Curve, ...]:
    """The family members m = 1…5, the rotation vector (dotted) and ``extra`` curves. Remembered
    (the curves are read, never changed), so a figure's PDF and PNG evaluate them once."""
    phi = np.linspace(*ANGLE_RANGE, SAMPLES)
    phi.flags.writeable = False
    members: list[tuple[str, str | None, bool, sp.Expr]] = [
        (f"$m = {m}$", MARKERS[m], False, family_member(family, m).expression)
        for m in FAMILY_ORDERS
    ]
    members.append((r"$p = \varphi$", None, True, lookup("rotation_vector").expression))
    members.extend((f"$p = {latex(expr)}$", None, False, expr) for expr in extra)
    out = []
    for label, marker, dotted, expr in members:
        d = derive_expression(expr)
        bound, poles = _singularities(d, quantity)
        values = evaluate(d, quantity, phi)
        values.flags.writeable = False
        out.append(Curve(label, marker, dotted, phi, values, bound, poles))
    return tuple(out)


def data_limits(shown: Sequence[Curve]) -> tuple[float, float]:
    """The 2–98 % range of every curve's values away from its poles (window ±π/6), widened to
    the whole reference curve (the rotation vector, dotted) and padded by 5 %."""
    kept = []
    for curve in shown:
        near_pole = np.zeros(curve.phi.shape, dtype=bool)
        for pole in curve.poles:
            near_pole |= np.abs(curve.phi - pole) < POLE_WINDOW
        values = curve.values[~near_pole]
        kept.append(values[np.isfinite(values)])
    low, high = (float(v) for v in np.quantile(np.concatenate(kept), QUANTILES))
    for curve in shown:
        if curve.dotted:
            low, high = min(low, float(np.nanmin(curve.values))), max(high, float(np.nanmax(curve.values)))
    pad = PADDING * max(high - low, 1.0)
    return low - pad, high + pad


def interrupt(values: np.ndarray, limits: tuple[float, float]) -> np.ndarray:
    """NaN between neighbours that jump by more than the panel height (across a pole) and
    beyond one panel height outside the limits; the rest is drawn and clipped by the frame."""
    low, high = limits
    span = high - low
    out = values.copy()
    out[~np.isfinite(out) | (out < low - span) | (out > high + span)] = np.nan
    jumps = np.abs(np.diff(out)) > span
    out[1:][jumps] = np.nan
    return out


def clip_points(values: np.ndarray, limits: tuple[float, float]) -> list[tuple[int, int]]:
    """(index, +1 top | −1 bottom) of the first sample outside the frame wherever a curve
    leaves or enters the panel through its top or bottom."""
    low, high = limits
    side = np.where(values > high, 1, np.where(values < low, -1, 0))
    inside = np.isfinite(values) & (side == 0)
    points = []
    for i in range(len(values) - 1):
        if inside[i] and side[i + 1] != 0:
            points.append((i + 1, int(side[i + 1])))
        elif inside[i + 1] and side[i] != 0:
            points.append((i, int(side[i])))
    return points


def pi_label(k: int) -> str:
    """k π/2 as mathtext: 0, π/2, π, 3π/2, 2π."""
    value = sp.Rational(k, 2)
    if value == 0:
        return "$0$"
    numerator = "" if value.p == 1 else str(value.p)
    return f"${numerator}\\pi$" if value.q == 1 else f"${numerator}\\pi/{value.q}$"


def _draw_panel(ax: Axes, shown: Sequence[Curve], quantity: str, font_size: float) -> None:
    limits = data_limits(shown)
    low, high = limits
    for curve in shown:
        values = interrupt(curve.values, limits)
        (line,) = ax.plot(curve.phi, values, linestyle=":" if curve.dotted else "-",
                          color="black" if curve.dotted else None, marker=curve.marker,
                          markevery=(len(curve.phi) // 24, len(curve.phi) // 12),
                          markersize=3.5, markerfacecolor="none", markeredgewidth=0.7,
                          label=curve.label)
        for index, side in clip_points(values, limits):
            edge = high if side > 0 else low
            ax.annotate("", xy=(curve.phi[index], edge),
                        xytext=(curve.phi[index], edge - side * 0.07 * (high - low)),
                        arrowprops={"arrowstyle": "-|>", "color": line.get_color(), "lw": 0.6,
                                    "mutation_scale": 5, "shrinkA": 0, "shrinkB": 0},
                        annotation_clip=False)
        if curve.bound is not None and curve.marker:
            ax.plot([curve.bound], [low], marker=curve.marker, color=line.get_color(),
                    markersize=4.5, markerfacecolor="none", markeredgewidth=0.8,
                    clip_on=False, zorder=5)
    ax.set_ylim(low, high)
    ax.set_ylabel(QUANTITY_LABELS[quantity])
    ax.set_xticks([k * np.pi / 2 for k in range(5)], [pi_label(k) for k in range(5)])
    ax.grid(True, linewidth=0.3, color="0.8")
    ax.tick_params(labelsize=font_size)


def build_figure(number: int, extra: tuple[sp.Expr, ...] = (),
                 style: str = DEFAULT_STYLE) -> Figure:
    """The matplotlib Figure for the paper's figure ``number`` (1–4), without a title."""
    import matplotlib

    matplotlib.use("Agg")
    from matplotlib.figure import Figure

    family, quantities = FIGURES[number]
    layout = STYLES[style]
    with matplotlib.rc_context(_rc(style)):
        figure = Figure(figsize=(layout.width, layout.panel_height * len(quantities) + 0.55),
                        layout="constrained")
        axes = figure.subplots(len(quantities), 1, sharex=True, squeeze=False)[:, 0]
        for ax, quantity in zip(axes, quantities, strict=True):
            _draw_panel(ax, curves(family, quantity, extra), quantity, layout.font_size)
        axes[-1].set_xlabel(r"$\varphi$")
        axes[-1].set_xlim(*ANGLE_RANGE)
        handles, labels = axes[0].get_legend_handles_labels()
        figure.legend(handles, labels, loc="outside upper center", frameon=False,
                      ncol=min(len(labels), 6 if style == "two-column" else 3),
                      fontsize=layout.font_size, handlelength=2.2, columnspacing=1.2)
    return figure


def render(number: int, fmt: str, extra: tuple[sp.Expr, ...] = (),
           style: str = DEFAULT_STYLE) -> bytes:
    """Figure ``number`` as PDF or PNG bytes: fonts as Type 42, PNG at 300 dpi, reproducible
    (no dates, a fixed producer)."""
    import matplotlib

    figure = build_figure(number, extra, style)
    buffer = io.BytesIO()
    metadata: dict[str, Any] = (
        {"CreationDate": None, "ModDate": None, "Producer": "symrot", "Creator": "symrot"}
        if fmt == "pdf" else {"Software": "symrot"})
    with matplotlib.rc_context(_rc(style)):
        figure.savefig(buffer, format=fmt, dpi=DPI, metadata=metadata)
    return buffer.getvalue()
