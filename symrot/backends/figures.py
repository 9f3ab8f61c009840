"""Figures 1–4 of the paper, regenerated from the derivation with matplotlib.

Figures 1–2: p(φ) for the sine and tangent families m = 1…5, with the rotation vector dotted.
Figures 3–4: ν, p′ and det H versus φ for each family (top, middle, bottom).
Values are the derived closed forms evaluated in double precision; φ = 0 takes the exact limit
from the series engine. Curves stop at singularities: points beyond the axis range are dropped and
a curve is broken wherever consecutive points jump by more than that range, so no vertical spike
is drawn across a pole. Output is reproducible byte for byte (no timestamps in PDF or PNG).
"""

from __future__ import annotations

import io
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
import sympy as sp

from ..core import Derivation, derive_expression
from ..parsing import PHI
from ..registry import family_member, lookup
from .latex import latex

if TYPE_CHECKING:
    from matplotlib.figure import Figure

MARKERS = {1: "+", 2: "s", 3: "^", 4: "o", 5: "v"}
FAMILY_ORDERS = (1, 2, 3, 4, 5)
ANGLE_RANGE = (0.0, 2 * np.pi)
SAMPLES = 1201
QUANTITY_LIMITS = {"p": (-8.0, 8.0), "nu": (-3.0, 3.0), "p_prime": (-3.0, 3.0),
                   "det_H": (-3.0, 3.0)}
QUANTITY_LABELS = {"p": r"$p(\varphi)$", "nu": r"$\nu$", "p_prime": r"$p'$",
                   "det_H": r"$\det\mathbf{H}$"}
FIGURES = {
    1: ("sine", ("p",)),
    2: ("tangent", ("p",)),
    3: ("sine", ("nu", "p_prime", "det_H")),
    4: ("tangent", ("nu", "p_prime", "det_H")),
}


@dataclass(frozen=True)
class Curve:
    label: str
    marker: str | None
    dotted: bool
    phi: np.ndarray
    values: np.ndarray
    """NaN where the curve is interrupted (beyond the axis range or across a singularity)."""


def numeric(derivation: Derivation, quantity: str) -> sp.Expr:
    return derivation.p if quantity == "p" else derivation.scalars_raw[quantity]


def evaluate(derivation: Derivation, quantity: str, phi: np.ndarray) -> np.ndarray:
    """The derived closed form on the grid; φ = 0 gets the exact limit (series engine)."""
    expr = numeric(derivation, quantity)
    function = sp.lambdify(PHI, expr, modules=[{"RealCbrt": np.cbrt}, "numpy"])
    with np.errstate(all="ignore"):
        values = np.asarray(function(phi), dtype=float) * np.ones_like(phi)
    at_zero = phi == 0
    if at_zero.any():
        limit = 0.0 if quantity == "p" else float(derivation.taylor_in_phi(quantity, 1)[0])
        values[at_zero] = limit
    return values


def interrupt(values: np.ndarray, limits: tuple[float, float]) -> np.ndarray:
    """NaN outside ``limits`` and between neighbours that jump by more than the axis range."""
    low, high = limits
    out = values.copy()
    out[~np.isfinite(out) | (out < low) | (out > high)] = np.nan
    jumps = np.abs(np.diff(out)) > (high - low) / 2
    out[1:][jumps] = np.nan
    return out


def curves(family: str, quantity: str, extra: tuple[sp.Expr, ...] = ()) -> list[Curve]:
    phi = np.linspace(*ANGLE_RANGE, SAMPLES)
    limits = QUANTITY_LIMITS[quantity]
    out = []
    for m in FAMILY_ORDERS:
        d = derive_expression(family_member(family, m).expression)
        out.append(Curve(f"m = {m}", MARKERS[m], False, phi,
                         interrupt(evaluate(d, quantity, phi), limits)))
    reference = derive_expression(lookup("rotation_vector").expression)
    out.append(Curve(r"$p = \varphi$", None, True, phi,
                     interrupt(evaluate(reference, quantity, phi), limits)))
    for expr in extra:
        d = derive_expression(expr)
        out.append(Curve(f"$p = {latex(expr)}$", None, False, phi,
                         interrupt(evaluate(d, quantity, phi), limits)))
    return out


def build_figure(number: int, extra: tuple[sp.Expr, ...] = ()) -> Figure:
    """The matplotlib Figure for the paper's figure ``number`` (1–4)."""
    import matplotlib

    matplotlib.use("Agg")
    from matplotlib.figure import Figure

    family, quantities = FIGURES[number]
    figure = Figure(figsize=(6.0, 2.6 * len(quantities) + 0.8))
    axes = figure.subplots(len(quantities), 1, sharex=True, squeeze=False)[:, 0]
    for ax, quantity in zip(axes, quantities, strict=True):
        for curve in curves(family, quantity, extra):
            ax.plot(curve.phi, curve.values, linestyle=":" if curve.dotted else "-",
                    color="black" if curve.dotted else None, marker=curve.marker,
                    markevery=100, markersize=5, linewidth=1.0, label=curve.label)
        ax.set_ylim(*QUANTITY_LIMITS[quantity])
        ax.set_ylabel(QUANTITY_LABELS[quantity])
        ax.grid(True, linewidth=0.3)
    axes[-1].set_xlabel(r"$\varphi$ (rad)")
    axes[-1].set_xlim(*ANGLE_RANGE)
    axes[0].legend(fontsize=7, ncol=4, loc="best")
    title = "Sine" if family == "sine" else "Tangent"
    axes[0].set_title(f"Figure {number}: {title} family")
    figure.tight_layout()
    return figure


def render(number: int, fmt: str, extra: tuple[sp.Expr, ...] = ()) -> bytes:
    """Figure ``number`` as PDF or PNG bytes, reproducible (no dates, fixed software tag)."""
    figure = build_figure(number, extra)
    buffer = io.BytesIO()
    metadata = ({"CreationDate": None, "ModDate": None, "Producer": "symrot"}
                if fmt == "pdf" else {"Software": "symrot"})
    figure.savefig(buffer, format=fmt, dpi=120, metadata=metadata)
    return buffer.getvalue()
