"""``symrot derive EXPR|NAME``: the derived scalar functions, tensors and series."""

from __future__ import annotations

import argparse
import json
from typing import Any

from ..api import DEFAULT_SERIES_TERMS, DerivationResult, derive
from ..core import SCALAR_EQUATIONS, TENSOR_EQUATIONS, TENSOR_NAMES

SCALAR_LABELS = {
    "p_prime": "p'",
    "nu": "nu",
    "epsilon": "epsilon",
    "mu": "mu",
    "det_H": "det H",
}
TENSOR_LABELS = {"R": "R", "H": "H", "H_inverse": "H^-1", "G": "G", "K": "K"}


def register(subparsers: Any) -> None:
    parser = subparsers.add_parser(
        "derive",
        help="derive p', nu, epsilon, mu, det H, R, H, H^-1, G, K and their series",
        description="Derive every quantity of the vectorial parameterization for a generating "
        "function p(phi) given as an expression (e.g. 'cbrt(6*(phi-sin(phi)))') or a "
        "registry name (e.g. wiener_milenkovic, sine_m4, tangent_m3, cayley_m2).",
    )
    parser.add_argument("expression", help="p(phi) or a registry identifier")
    parser.add_argument("--json", action="store_true", help="print one JSON object")
    parser.add_argument("--normalize", action="store_true", help="divide p by kappa (eq 12)")
    parser.add_argument(
        "--terms", type=int, default=DEFAULT_SERIES_TERMS, choices=range(1, 25),
        metavar="N", help=f"series terms in x = |p|^2 (default {DEFAULT_SERIES_TERMS}, max 24)",
    )
    parser.add_argument("--emit", metavar="BACKEND", help="write code with this backend (e.g. numpy)")
    parser.add_argument("--name", help="module name for --emit (default: registry name or 'rotation')")
    parser.add_argument("--out", default=".", help="output directory for --emit (default: .)")
    parser.set_defaults(run=run)


def emit_code(result: DerivationResult, args: argparse.Namespace) -> int:
    import re
    from pathlib import Path

    from ..backends import emitter
    from ..errors import SymrotError

    name = args.name or (result.entry.identifier if result.entry else "rotation")
    if not re.fullmatch(r"[A-Za-z_][A-Za-z0-9_]*", name):
        raise SymrotError(f"--name {name!r} is not a valid identifier")
    for path in emitter(args.emit)(result.derivation, name, Path(args.out)):
        print(path)
    return 0


def run(args: argparse.Namespace) -> int:
    result = derive(args.expression, normalize=args.normalize)
    if getattr(args, "emit", None):
        return emit_code(result, args)
    if args.json:
        print(json.dumps(result.to_dict(series_terms=args.terms), indent=2))
    else:
        print(summary(result, args.terms))
    return 0


def _series_text(coefficients: list[Any]) -> str:
    terms = []
    for j, c in enumerate(coefficients):
        if c == 0:
            continue
        power = "" if j == 0 else (" x" if j == 1 else f" x^{j}")
        terms.append(f"({c}){power}" if j else f"{c}")
    return " + ".join(terms) + f" + O(x^{len(coefficients)})" if terms else "0 (identically)"


def validity_lines(derivation: Any) -> list[str]:
    from ..singularities import validity

    result = validity(derivation)
    if not result.singularities:
        return ["Validity (Section 3.4): no singular angle in (0, 4 pi]"]
    p_max = "oo" if result.p_max_float == float("inf") else f"{result.p_max_float:.15g}"
    lines = [f"Validity (Section 3.4): |phi| < {result.phi_max} = {result.phi_max_float:.15g}, "
             f"|p| < {p_max}" + ("  (located numerically)" if result.numeric_only else "")]
    lines.extend(f"  phi = {s.phi}: {s.cause}" for s in result.listed())
    return lines


def summary(result: DerivationResult, terms: int) -> str:
    d = result.derivation
    lines = []
    title = f"p(phi) = {d.p}"
    if result.entry:
        title += f"    [{result.entry.identifier}, eq {result.entry.equation}]"
    lines.append(title)
    kappa_note = "" if d.kappa == 1 else "   (not unit-normalized; --normalize divides p by it)"
    lines.append(f"kappa = lim p/phi (eq 12) = {d.kappa}{kappa_note}")
    lines.append("")
    lines.append("Scalar functions")
    for name, label in SCALAR_LABELS.items():
        lines.append(f"  {label:<8} (eq {SCALAR_EQUATIONS[name]:>2}) = {d.scalars[name]}")
    lines.append("")
    lines.append("Tensors  T = c0 I + c1 (p x) + c2 (p x)^2   [canonical basis: axial; re +- i im]")
    for name in TENSOR_NAMES:
        tensor = d.tensors[name]
        label = f"{TENSOR_LABELS[name]} (eq {TENSOR_EQUATIONS[name]})"
        lines.append(f"  {label}")
        for k, c in enumerate(tensor.simplified):
            lines.append(f"      c{k} = {c}")
        axial, real, imag = tensor.canonical[0, 0], tensor.canonical[1, 1], tensor.canonical[2, 1]
        lines.append(f"      eigenvalues: {axial};  {real} +- i ({imag})")
    lines.append("")
    lines.extend(validity_lines(d))
    lines.append("")
    lines.append(f"Leading series in x = |p|^2 (exact, {terms} terms)")
    for name in ("nu", "mu", "det_H", "R_1", "R_2", "H_2", "H_inverse_2"):
        lines.append(f"  {name:<12} = {_series_text(d.series_in_x(name, terms))}")
    return "\n".join(lines)
