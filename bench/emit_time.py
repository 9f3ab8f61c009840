"""How long `symrot derive EXPR [--emit numpy|c]` takes, for every corpus function and named family.

Issue 16 asks for ≤ 10 s wall per emit of a user function (≤ 5 s for the paper's families); the
derivation summary alone (backend ``derive``: ``symrot derive EXPR``, no emit) has a target of 5 s
for any function. Each run is what a user runs, its own ``python -m symrot derive …`` process
(with ``--timeout 600``, so that a slow emit is measured rather than cut at the CLI's 60 s default),
one at a time. Reported: wall seconds and the CPU seconds of the process and its children (the
CLI's worker), which the load of a shared machine inflates less than wall time; and the machine's
load average before the run.

Run: ``python bench/emit_time.py [--only I,J] [--names] [--backends numpy,c] [--warm] [--out
docs/emit_time.md] [--json FILE]``; ``--backends derive`` times the summary, ``numpy+c`` one
``--emit numpy,c``; ``--warm`` times a repeated emit, whose plan comes from the plan cache.
``--only`` takes indices of tests/corpus.py; ``--names`` adds the named parameterizations and the
sine/tangent family headers of generated/c (their C emits).
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from tests.corpus import CORPUS  # noqa: E402

sys.path.insert(0, str(ROOT / "bench"))
from accuracy_derivatives import commit as checked_out_commit  # noqa: E402
from machine import description  # noqa: E402

USER_TARGET_S = 10.0
FAMILY_TARGET_S = 5.0
SUMMARY_TARGET_S = 5.0
TIMEOUT_S = 600


def target_seconds(kind: str, backend: str) -> float:
    """The wall-time target of one run: the summary's, or the emit's for this kind of function."""
    if backend == "derive":
        return SUMMARY_TARGET_S
    return USER_TARGET_S if kind == "user" else FAMILY_TARGET_S


def time_emit(expression: str, backend: str, warm: bool = False) -> dict[str, float | str]:
    """Wall and CPU seconds of one ``symrot derive EXPR --emit BACKEND`` process (no ``--emit`` for
    the backend ``derive``; ``a+b`` is ``--emit a,b``, one plan for both), or its error. Without the
    plan cache (``--no-cache``: a first emit), or with ``warm``: after an untimed run of the same
    command has kept the plan in a temporary cache directory (a repeated emit)."""
    with tempfile.TemporaryDirectory() as out, tempfile.TemporaryDirectory() as plans:
        emit = [] if backend == "derive" else ["--name", "timed", "--emit", backend.replace("+", ","),
                                               "--out", out, "-q"]
        if backend != "derive" and not warm:
            emit.append("--no-cache")
        command = [sys.executable, "-m", "symrot", "derive", expression, *emit, "--timeout", str(TIMEOUT_S)]
        environment = {**os.environ, "SYMROT_CACHE_DIR": plans, "SYMROT_NO_CACHE": ""}
        if warm:
            subprocess.run(command, capture_output=True, cwd=out, env=environment, check=False)
        before = resource.getrusage(resource.RUSAGE_CHILDREN)
        start = time.perf_counter()
        run = subprocess.run(command, capture_output=True, text=True, cwd=out, env=environment, check=False)
        wall = time.perf_counter() - start
        after = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    result: dict[str, float | str] = {"wall": wall, "cpu": cpu}
    if run.returncode != 0:
        result["error"] = (run.stderr.strip().splitlines() or [f"exit {run.returncode}"])[-1][:160]
    return result


def family_names() -> list[str]:
    """The named parameterizations and the family members with a header under generated/c."""
    from symrot.backends.c_backend import COVERED

    return list(COVERED)


def table(rows: list[dict[str, Any]], backends: list[str]) -> str:
    head = ("| # | p(φ) or name | " + " | ".join(f"{b} wall s | {b} CPU s" for b in backends)
            + " | emit target |")
    lines = [head, "|" + "---|" * (3 + 2 * len(backends))]
    for row in rows:
        cells = []
        for backend in backends:
            timing = row[backend]
            if "error" in timing:
                cells += [f"**failed** ({timing['error']})", f"{timing['cpu']:.1f}"]
            else:
                cells += [f"{timing['wall']:.1f}", f"{timing['cpu']:.1f}"]
        expression = f"`{row['expression']}`"
        lines.append(f"| {row['index']} | {expression} | {' | '.join(cells)} | {row['target']:g} s |")
    return "\n".join(lines) + "\n"


def summary(rows: list[dict[str, Any]], backends: list[str]) -> str:
    out = []
    for kind in ("user", "family"):
        chosen = [r for r in rows if r["kind"] == kind]
        if not chosen:
            continue
        for backend in backends:
            target = target_seconds(kind, backend)
            command = "derive (summary)" if backend == "derive" else f"--emit {backend}"
            walls = sorted(float(r[backend]["wall"]) for r in chosen)
            failed = sum("error" in r[backend] for r in chosen)
            within = sum(float(r[backend]["wall"]) <= target and "error" not in r[backend] for r in chosen)
            out.append(f"- {kind} functions, `{command}`: {within} of {len(chosen)} within "
                       f"{target:g} s wall; median {walls[len(walls) // 2]:.1f} s, max {walls[-1]:.1f} s; "
                       f"{failed} failed.")
    return "\n".join(out) + "\n"


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--only", default=None, help="comma-separated indices of tests/corpus.py")
    parser.add_argument("--names", action="store_true", help="also the named parameterizations and families")
    parser.add_argument("--no-corpus", action="store_true")
    parser.add_argument("--backends", default="numpy,c",
                        help="comma-separated; numpy+c times one --emit numpy,c (one plan for both)")
    parser.add_argument("--warm", action="store_true",
                        help="time a repeated emit: the plan read back from the cache an untimed "
                        "first run filled (default: a first emit, --no-cache)")
    parser.add_argument("--out", type=Path, default=None)
    parser.add_argument("--json", type=Path, default=None)
    args = parser.parse_args(argv)
    backends = args.backends.split(",")
    indices = [int(i) for i in args.only.split(",")] if args.only else list(range(len(CORPUS)))
    work: list[tuple[str, str, str]] = [] if args.no_corpus else [
        (str(i), CORPUS[i].expression, "user") for i in indices]
    if args.names:
        work += [("—", name, "family") for name in family_names()]
    load = os.getloadavg()[0]
    commit = checked_out_commit()
    rows: list[dict[str, Any]] = []
    for index, expression, kind in work:
        row: dict[str, Any] = {"index": index, "expression": expression, "kind": kind,
                                  "target": USER_TARGET_S if kind == "user" else FAMILY_TARGET_S}
        for backend in backends:
            row[backend] = time_emit(expression, backend, args.warm)
        rows.append(row)
        print(f"{index} {expression}: " + ", ".join(
            f"{b} {row[b]['wall']:.1f} s" for b in backends), flush=True)
        if args.json:
            args.json.write_text(json.dumps(rows, indent=1), encoding="utf-8")
    command = "python bench/emit_time.py " + " ".join(argv if argv is not None else sys.argv[1:])
    title = "Derivation summary time" if backends == ["derive"] else "Emit time"
    report = (f"# {title}\n\nProduced by `{command}` at commit {commit} "
              f"({time.strftime('%Y-%m-%d')}; {description()}; 1-minute load average {load:.2f} before the "
              "run). "
              "Each run is its own `python -m symrot derive EXPR [--emit BACKEND] --timeout 600` "
              "process (backend `derive`: no `--emit`, the printed summary; `a+b`: `--emit a,b`), one at a "
              "time; CPU s counts the process and its children. "
              + ("Warm: each timed run reads the plan that an untimed run of the same command kept in the "
                 "plan cache (a repeated emit).\n\n" if args.warm else
                 "Each emit computes its plan (`--no-cache`: a first emit).\n\n")
              + summary(rows, backends) + "\n" + table(rows, backends))
    print(report)
    if args.out:
        args.out.write_text(report, encoding="utf-8")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
