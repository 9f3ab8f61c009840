"""``make generate`` / ``make check-generated``: the complete outputs for the named parameterizations.

Each producer maps a registry entry (or the whole registry) to ``{relative path: text}``. Writing
is deterministic (sorted, no timestamps), so a rerun is byte-identical, and ``--check`` fails with
a unified diff and the fix command when ``generated/`` is stale.

Run as ``python -m symrot.generate [--check] [--only PREFIX[,PREFIX…]] [--name NAME] DIR``.
"""

from __future__ import annotations

import argparse
import difflib
import sys
from collections.abc import Callable, Iterable
from functools import lru_cache, partial
from pathlib import Path

from symrot.api import derive
from symrot.cli import strict_json
from symrot.core.atomic import write_atomic
from symrot.core.forked import in_child
from symrot.core.registry import NAMED
from symrot.core.timeouts import deterministic

Producer = Callable[[], dict[str, str | bytes]]
Content = str | bytes


def derivation_json() -> dict[str, str | bytes]:
    """generated/derivations/NAME.json: ``symrot derive NAME --json`` for each named entry."""
    out: dict[str, str | bytes] = {}
    for name in NAMED:
        data = derive(name).to_dict(series_terms=8)
        out[f"derivations/{name}.json"] = strict_json.dumps(data, indent=2, sort_keys=True) + "\n"
    return out


@lru_cache(maxsize=1)
def latex_documents() -> dict[str, str | bytes]:
    """generated/latex/: Table 1 and the derivation sheets of the named parameterizations,
    each as a fragment (NAME.tex) and a complete document (NAME_standalone.tex)."""
    from symrot.backends.latex import sheet, standalone, table
    from symrot.core.registry import PAPER_TABLE_1_VALIDITY, TABLE_1

    out: dict[str, str | bytes] = {}
    rows = table([derive(name) for name in TABLE_1], (), PAPER_TABLE_1_VALIDITY)
    out["latex/table1.tex"] = rows
    out["latex/table1_standalone.tex"] = standalone(rows)
    for name in NAMED:
        body = sheet(derive(name))
        out[f"latex/{name}.tex"] = body
        out[f"latex/{name}_standalone.tex"] = standalone(body)
    return out


def renderings() -> dict[str, str | bytes]:
    """generated/renderings/: the pages of Table 1 and of every derivation sheet as 100 dpi PNG
    (pdflatex, then pdftoppm; byte-reproducible), to read them without a TeX installation."""
    from symrot.backends.typeset import page_pngs

    out: dict[str, str | bytes] = {}
    for name, source in latex_documents().items():
        if not name.endswith("_standalone.tex") or not isinstance(source, str):
            continue
        stem = Path(name).name.removesuffix("_standalone.tex")
        for number, png in enumerate(page_pngs(source), start=1):
            out[f"renderings/{stem}-{number}.png"] = png
    return out


def figures() -> dict[str, str | bytes]:
    """generated/figures/: the paper's Figures 1–4, as PDF (for papers) and PNG."""
    from symrot.backends.figures import FIGURES
    from symrot.backends.figures import render as render_figure

    return {f"figures/figure{n}.{fmt}": render_figure(n, fmt) for n in FIGURES for fmt in ("pdf", "png")}


def numpy_modules(names: Iterable[str] | None = None) -> dict[str, str | bytes]:
    """generated/numpy/NAME.py: the NumPy kernels of every named parameterization (or ``names``)."""
    from symrot.backends.numpy_backend import module_source
    from symrot.plan.builder import evaluation_plan

    return {f"numpy/{name}.py": module_source(evaluation_plan(derive(name).derivation, name))
            for name in (NAMED if names is None else names)}


def _array_modules(framework: str, names: Iterable[str] | None = None) -> dict[str, str | bytes]:
    from symrot.backends.array_backend import module_source
    from symrot.plan.builder import evaluation_plan

    return {f"{framework}/{name}.py": module_source(evaluation_plan(derive(name).derivation, name), framework)
            for name in (NAMED if names is None else names)}


def jax_modules(names: Iterable[str] | None = None) -> dict[str, str | bytes]:
    """generated/jax/NAME.py: the JAX kernels of every named parameterization."""
    return _array_modules("jax", names)


def torch_modules(names: Iterable[str] | None = None) -> dict[str, str | bytes]:
    """generated/torch/NAME.py: the PyTorch kernels of every named parameterization."""
    return _array_modules("torch", names)


def c_headers(names: Iterable[str] | None = None) -> dict[str, str | bytes]:
    """generated/c/symrot_NAME.h: the C99 headers (Table 1, eq 35, sine/tangent m <= 6), or those
    of ``names``."""
    from symrot.backends.c_backend import generated_headers

    return dict(generated_headers(None if names is None else tuple(names)))


def producers() -> list[tuple[str, Producer]]:
    """All producers, by the path prefix they own. Backends add theirs here."""
    return [("derivations/", derivation_json), ("latex/", latex_documents),
            ("renderings/", renderings), ("figures/", figures),
            ("numpy/", numpy_modules), ("c/", c_headers),
            ("jax/", jax_modules), ("torch/", torch_modules)]


SHARED_DERIVATIONS = ("derivations/", "latex/", "renderings/")
"""Producers run as one task, in one process: they derive the same named parameterizations, and the
renderings typeset the very documents of ``latex/`` (:func:`latex_documents` is remembered)."""

PER_NAME = ("numpy/", "c/", "jax/", "torch/")
"""Producers that are split into one task per parameterization when ``render`` runs in parallel
(a name's NumPy, JAX and PyTorch modules and C header share one task, so its plan is computed once)."""


def tasks(selected: list[str]) -> list[tuple[str, ...]]:
    """Independent units of work, longest first (idle workers take the next one): the producers that
    derive every named parameterization (the documents of :data:`SHARED_DERIVATIONS` as one task, the
    figures), then ("names", name) for the per-name producers (the tangent and sine families of the C
    headers first)."""
    from symrot.backends.c_backend import COVERED

    names = [*COVERED] if "c/" in selected else []
    array_prefixes = ("numpy/", "jax/", "torch/")
    if any(prefix in selected for prefix in array_prefixes):
        names += [name for name in NAMED if name not in names]
    per_name: list[tuple[str, ...]] = [("names", name) for name in reversed(names)]
    documents = tuple(prefix for prefix in SHARED_DERIVATIONS if prefix in selected)
    rest = [(prefix,) for prefix in selected if prefix not in PER_NAME and prefix not in documents]
    return ([documents] if documents else []) + rest + per_name


def _run_task(task: tuple[str, ...], selected: tuple[str, ...]) -> dict[str, Content]:
    with deterministic():  # no result of a bounded step may depend on this machine's speed or load
        if task[0] != "names":
            made: dict[str, Content] = {}
            for prefix in task:
                made.update(dict(producers())[prefix]())
            return made
        from symrot.backends.c_backend import COVERED

        name = task[1]
        out: dict[str, Content] = {}
        if "numpy/" in selected and name in NAMED:
            out.update(numpy_modules([name]))
        if "jax/" in selected and name in NAMED:
            out.update(jax_modules([name]))
        if "torch/" in selected and name in NAMED:
            out.update(torch_modules([name]))
        if "c/" in selected and name in COVERED:
            out.update(c_headers([name]))
        return out


def names_of(prefix: str) -> tuple[str, ...]:
    """The parameterizations that have a file under the per-name ``prefix`` (:data:`PER_NAME`)."""
    from symrot.backends.c_backend import COVERED

    return tuple(COVERED) if prefix == "c/" else tuple(NAMED)


def name_of(relative: str) -> str:
    """The parameterization a per-name file belongs to: numpy/NAME.py, jax/NAME.py, torch/NAME.py,
    c/symrot_NAME.h."""
    prefix, _, file = relative.partition("/")
    stem = Path(file).stem
    return stem.removeprefix("symrot_") if prefix == "c" else stem


def stale_names(root: Path) -> list[str]:
    """Files under the per-name prefixes that belong to no parameterization which has one (left
    behind by a renamed or removed entry; ``make generate`` deletes them)."""
    return sorted(relative for prefix in PER_NAME for relative in owned(root, [prefix])
                  if name_of(relative) not in names_of(prefix))


def selected_prefixes(only: str | None) -> list[str]:
    """The producer prefixes that start with one of the comma-separated ``only`` (all without it)."""
    starts = only.split(",") if only else [""]
    return [prefix for prefix, _ in producers() if any(prefix.startswith(start) for start in starts)]


BACKEND_MODULES = ("numpy_backend", "array_backend", "c_backend", "latex", "typeset", "figures")
"""The backend modules the tasks import (matplotlib with the figures)."""


def warm_shared_state() -> None:
    """Do once, before the tasks fork, the work every task would repeat that depends on no
    parameterization: import the backends, compile every template, and derive the p-free algebra of
    :mod:`symrot.core.derivatives` (∂(T a)/∂p and Ṫ ṗ on their bases). Each task inherits it. The state is
    the same in every run and for every split of the work (``--name`` and ``--only`` too: every
    backend is imported even when only one is selected, about 0.6 s for matplotlib), so what a task
    prints still depends only on its own work."""
    import importlib

    from symrot.backends.templating import environment
    from symrot.core.derivatives import rate_vector, tensor_derivative

    for module in BACKEND_MODULES:
        importlib.import_module(f".backends.{module}", __package__)
    templates = environment()
    for template in templates.list_templates(extensions=["j2"]):
        templates.get_template(template)
    tensor_derivative()
    rate_vector()


def render(only: str | None = None, jobs: int = 1, name: str | None = None) -> dict[str, Content]:
    """Every selected file; with ``jobs`` > 1 the work runs in that many processes at once. Each
    task runs in a process of its own, forked from this one, so that what it prints cannot depend on
    which tasks ran before it in the same process (SymPy's caches, remembered derivations whose
    tensors another task simplified in another order) nor on how the work is split: the result is
    the one ``--name NAME`` gives in a fresh process (tests/test_generated.py). With ``name``, only
    that parameterization's files of the per-name producers (one task)."""
    import multiprocessing

    from symrot.cli.progress import each

    files: dict[str, Content] = {}
    selected = selected_prefixes(only)
    work = [("names", name)] if name is not None else tasks(selected)
    run = partial(_run_task, selected=tuple(selected))
    warm_shared_state()
    if jobs <= 1:
        for task in each(work, "symrot.generate"):
            with in_child(partial(run, task)) as wait:
                files.update(wait())
        return dict(sorted(files.items()))
    with multiprocessing.get_context("fork").Pool(processes=jobs, maxtasksperchild=1) as pool:
        for made in each(pool.imap_unordered(run, work), "symrot.generate", total=len(work)):
            files.update(made)
    return dict(sorted(files.items()))


def default_jobs() -> int:
    """Processes for ``render``: the CPUs this process may use, at most 4."""
    import os

    try:
        available = len(os.sched_getaffinity(0))
    except AttributeError:  # not Linux
        available = os.cpu_count() or 1
    return max(1, min(available, 4))


def owned(root: Path, prefixes: Iterable[str]) -> set[str]:
    found: set[str] = set()
    for prefix in prefixes:
        base = root / prefix
        if base.is_dir():
            found.update(str(p.relative_to(root)) for p in base.rglob("*") if p.is_file())
    return found


def _encode(content: Content) -> bytes:
    return content.encode("utf-8") if isinstance(content, str) else content


def write(root: Path, files: dict[str, Content], prefixes: list[str]) -> None:
    for stale in owned(root, prefixes) - set(files):
        (root / stale).unlink()
    for relative, content in files.items():
        path = root / relative
        path.parent.mkdir(parents=True, exist_ok=True)
        data = _encode(content)
        if not path.exists() or path.read_bytes() != data:
            write_atomic(path, data)


def check(root: Path, files: dict[str, Content], prefixes: list[str], name: str | None = None) -> list[str]:
    """Unified diffs between ``root`` and what would be generated (empty when current); with
    ``name``, of that parameterization's files only."""
    diffs = []
    existing = owned(root, prefixes)
    if name is not None:
        existing = {relative for relative in existing
                    if relative.split("/")[0] + "/" in PER_NAME and name_of(relative) == name}
    for relative in sorted(existing | set(files)):
        path = root / relative
        old_bytes = path.read_bytes() if path.exists() else b""
        new_content = files.get(relative, "")
        if old_bytes == _encode(new_content):
            continue
        if isinstance(new_content, bytes):
            diffs.append(f"{relative}: binary content differs\n")
            continue
        old, new = old_bytes.decode("utf-8", "replace"), new_content
        if old != new:
            diffs.append("".join(difflib.unified_diff(
                old.splitlines(keepends=True), new.splitlines(keepends=True),
                f"a/{relative}", f"b/{relative}", n=2,
            )) or f"{relative}: differs\n")
    return diffs


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m symrot.generate")
    parser.add_argument("directory", nargs="?", default="generated")
    parser.add_argument("--check", action="store_true", help="compare instead of writing")
    parser.add_argument("--only", help="only producers whose prefix starts with this "
                        "(several: comma-separated)")
    parser.add_argument("--name", help="only this parameterization's files of the per-name producers "
                        f"({', '.join(PER_NAME)})")
    parser.add_argument("--list", action="store_true", help="list producer prefixes")
    parser.add_argument("--jobs", type=int, default=None,
                        help="worker processes (default: the CPUs available, at most 4; 1: none)")
    args = parser.parse_args(argv)
    prefixes = selected_prefixes(args.only)
    if args.list:
        print("\n".join(prefixes))
        return 0
    root = Path(args.directory)
    if args.name is not None:
        if args.name not in {*names_of("c/"), *names_of("numpy/")}:
            print(f"error: {args.name!r} has no per-name files", file=sys.stderr)
            return 2
        if not args.check:
            print("error: --name only checks (make generate writes every file)", file=sys.stderr)
            return 2
        prefixes = [prefix for prefix in prefixes if prefix in PER_NAME]
    files = render(args.only, args.jobs if args.jobs is not None else default_jobs(), args.name)
    if args.check:
        diffs = check(root, files, prefixes, args.name)
        if diffs:
            sys.stdout.writelines(d if d.endswith("\n") else d + "\n" for d in diffs[:20])
            print(f"generated/ is stale ({len(diffs)} files differ). Fix: make generate",
                  file=sys.stderr)
            return 1
        print(f"generated/ is current ({len(files)} files)")
        return 0
    write(root, files, prefixes)
    print(f"wrote {len(files)} files under {root}/")
    return 0


if __name__ == "__main__":
    from symrot.entry import run_with_fixed_hash_seed

    run_with_fixed_hash_seed("symrot.generate")  # the same files on every run (symrot.entry)
    raise SystemExit(main())
