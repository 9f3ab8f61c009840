"""``symrot derive EXPR|NAME``: the derived scalar functions, tensors and series."""

from __future__ import annotations

import argparse
import keyword
import os
import re
import sys
from pathlib import Path
from typing import Any

from symrot.api import DEFAULT_SERIES_TERMS, DerivationResult, derive
from symrot.cli import strict_json
from symrot.cli.output import check_writable, write_files
from symrot.core.budget import stage
from symrot.core.derivation import SCALAR_EQUATIONS, TENSOR_EQUATIONS, TENSOR_NAMES
from symrot.core.errors import SymrotError

SCALAR_LABELS = {
    "p_prime": "p'",
    "nu": "nu",
    "epsilon": "epsilon",
    "mu": "mu",
    "det_H": "det H",
}
IDENTIFIER = re.compile(r"[A-Za-z_][A-Za-z0-9_]*")
TENSOR_LABELS = {"R": "R", "H": "H", "H_inverse": "H^-1", "G": "G", "K": "K"}
NAME_LENGTH = 64
"""The longest ``--name`` (the C header adds ``symrot_``/``.h``; file systems stop at 255 bytes)."""
RESERVED_NAMES = frozenset({
    "numpy", "scipy", "jax", "jaxlib", "torch", "sympy", "mpmath", "symrot", "functools", "math",
    "lax", "typing", "conftest", "setup",
})
"""Module names ``--name`` may not take besides the standard library's: the numeric libraries,
symrot itself and every module a generated file imports (a module of that name beside them would
shadow it)."""


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
    parser.add_argument("--emit", metavar="BACKEND[,BACKEND...]",
                        help="write code with this backend (e.g. numpy); several, comma-separated (e.g. "
                        "c,numpy), or all, share one evaluation plan and write into OUT/BACKEND/")
    parser.add_argument("--name", help="module name for --emit (default: registry name or 'rotation'): "
                        f"an identifier of at most {NAME_LENGTH} characters, no keyword, dunder or "
                        "module name (numpy, math, ...)")
    parser.add_argument("--out", default=".", help="output directory for --emit (default: .); checked "
                        "before any work; no symbolic link inside it is followed")
    parser.add_argument("--no-cache", action="store_true",
                        help="compute the evaluation plan even when an earlier --emit of the same p "
                        "kept it (in symrot-plans-v1 under $SYMROT_CACHE_DIR, else $XDG_CACHE_HOME/symrot, "
                        "else ~/.cache/symrot; no cache without any of them)")
    parser.set_defaults(run=run)


def backend_names(text: str) -> list[str]:
    """The backends of ``--emit`` (comma-separated, each once, in the order given; ``all``: every
    registered backend)."""
    from symrot.backends import EMITTERS, emitter

    names = list(EMITTERS) if text.strip() == "all" else [part.strip() for part in text.split(",")]
    if not all(names):
        raise SymrotError(f"--emit {text!r}: an empty backend name")
    for name in names:
        emitter(name)
    return list(dict.fromkeys(names))


def _check_emit_options(args: argparse.Namespace) -> None:
    """Refuse a bad --name or --emit before any derivation is spent on them."""
    if args.name is not None:
        check_name(args.name)
    backend_names(args.emit)
    check_writable(Path(args.out))


def check_name(name: str) -> None:
    """Refuse a ``--name`` that is no identifier, longer than :data:`NAME_LENGTH`, a keyword, a
    dunder name or the name of a module the generated code or its user would import."""
    if not IDENTIFIER.fullmatch(name):
        raise SymrotError(f"--name {name[:NAME_LENGTH]!r} is not a valid identifier")
    if len(name) > NAME_LENGTH:
        raise SymrotError(f"--name has {len(name)} characters; at most {NAME_LENGTH}")
    if keyword.iskeyword(name):
        raise SymrotError(f"--name {name!r} is a Python keyword")
    if name.startswith("__") and name.endswith("__"):
        raise SymrotError(f"--name {name!r} is a special (dunder) name")
    if name in RESERVED_NAMES or name in sys.stdlib_module_names:
        raise SymrotError(f"--name {name!r} would shadow the module {name} (choose another name)")


SCRATCH_PREFIX = "symrot-emit-"
"""Scratch directories of ``--emit`` are ``$TMPDIR/symrot-emit-PID-RANDOM``."""


def remove_stale_scratch() -> None:
    """Remove the scratch directories that a killed ``--emit`` (SIGKILL) left behind: those of
    this user whose process id no longer runs."""
    import shutil
    import tempfile

    from symrot.core.atomic import process_running

    try:
        entries = list(Path(tempfile.gettempdir()).glob(f"{SCRATCH_PREFIX}*-*"))
    except OSError:
        return
    for entry in entries:
        pid = entry.name[len(SCRATCH_PREFIX):].split("-", 1)[0]
        try:
            if not pid.isdigit() or process_running(int(pid)) or entry.lstat().st_uid != os.getuid():
                continue
        except OSError:
            continue
        shutil.rmtree(entry, ignore_errors=True)


def emit_code(result: DerivationResult, args: argparse.Namespace) -> int:
    """Plan once, print with every backend of ``--emit`` into a scratch directory, then replace
    the files in ``--out`` all or none (nothing is written when a backend fails)."""
    import tempfile

    from symrot.backends import emitter
    from symrot.cli.plan_cache import cached_plan
    from symrot.cli.progress import stages
    from symrot.core.singularities import validity
    from symrot.plan.builder import evaluation_plan

    name = args.name or (result.entry.identifier if result.entry else "rotation")
    backends = backend_names(args.emit)
    out = Path(args.out)
    with stages(f"symrot: --emit {','.join(backends)}", 3) as progress:
        progress.start("validity range (Section 3.4)")
        with stage("validity analysis"):
            validity(result.derivation)
        progress.start("evaluation plan (float64, float32)")
        with stage("planning"):  # remembered in this process: the backends print it
            if args.no_cache:
                evaluation_plan(result.derivation, name)
            else:
                cached_plan(result.derivation, name)
        progress.start("printing")
        remove_stale_scratch()
        with tempfile.TemporaryDirectory(prefix=f"{SCRATCH_PREFIX}{os.getpid()}-") as scratch:
            printed: list[tuple[Path, str]] = []
            with stage("printing"):
                for backend in backends:  # several: each into OUT/BACKEND (NumPy, JAX, PyTorch: NAME.py)
                    target = out / backend if len(backends) > 1 else out
                    printed += [(target / path.name, path.read_text(encoding="utf-8")) for path in
                                emitter(backend)(result.derivation, name, Path(scratch) / backend)]
            write_files(out, printed)  # all or none
    return 0


def run(args: argparse.Namespace) -> int:
    if getattr(args, "emit", None):
        _check_emit_options(args)
    result = derive(args.expression, normalize=args.normalize)
    if getattr(args, "emit", None):
        return emit_code(result, args)
    from symrot.core.singularities import validity
    from symrot.core.two_processes import simplify_tensors

    derivation = result.derivation
    simplify_tensors(derivation, beside=lambda: validity(derivation))
    if args.json:
        text = strict_json.dumps(result.to_dict(series_terms=args.terms), indent=2)
    else:
        text = summary(result, args.terms)
    print(text)
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
    from symrot.core.singularities import validity

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
    if result.original_kappa is not None:
        kappa_note = (f"   (normalized: p divided by the kappa {result.original_kappa} of the input)"
                      if result.normalized else "   (--normalize: already unit-normalized)")
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
