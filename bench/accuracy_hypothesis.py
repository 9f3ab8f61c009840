"""Accuracy of the generated code for hypothesis-generated generating functions (issue 16).

Draws ``--count`` distinct functions from the grammar of tests/strategies.py (derandomized, so
every run draws the same ones), emits each through the public API and measures it exactly as
bench/accuracy_corpus.py measures the corpus (independent reference of tests/reference.py,
verdicts of docs/accuracy.md), each in its own worker process with a time limit. Writes the
fraction meeting the target and every miss (function, size, where) as markdown.

Run: ``python bench/accuracy_hypothesis.py [--count 200] [--points 4] [--no-c] [--json FILE]
[--out docs/accuracy_hypothesis.md] [--jobs N] [--resume] [--seed S]``. With ``--seed`` it measures a
held-out sample instead (docs/accuracy_holdout.md): functions drawn with another seed, none of them
among the default 200 on which plan changes were checked, so its fraction is an estimate for
functions nobody has looked at.
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
import time
from concurrent.futures import ThreadPoolExecutor, as_completed
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "bench"))

from accuracy_corpus import COLUMNS, _verdicts, measure_expression  # noqa: E402

WORKER_TIMEOUT = 600
DEFAULT_COUNT = 200
GOOD = ("meets", "conditioned")


def draw(count: int) -> list[str]:
    """The first ``count`` distinct expressions the derandomized strategy generates."""
    from hypothesis import HealthCheck, Phase, given, settings

    from tests.strategies import generating_functions

    found: list[str] = []

    @settings(derandomize=True, max_examples=count + count // 4, deadline=None, database=None,
              phases=[Phase.generate], suppress_health_check=list(HealthCheck))
    @given(generating_functions())
    def collect(function: Any) -> None:
        if function.expression not in found and len(found) < count:
            found.append(function.expression)

    collect()
    return found


def draw_held_out(count: int, seed: int, excluded: frozenset[str]) -> list[str]:
    """The first ``count`` distinct expressions that hypothesis's generator seeded with ``seed``
    draws, skipping ``excluded`` (the default sample): functions no change was tuned on, the same on
    every run. (:func:`draw` stays as it was: a derandomized draw depends on its function's source.)"""
    from hypothesis import HealthCheck, Phase, given, settings
    from hypothesis import seed as seeded

    from tests.strategies import generating_functions

    found: list[str] = []

    @seeded(seed)
    @settings(max_examples=count + count // 4 + 4 * len(excluded) // 3, deadline=None, database=None,
              phases=[Phase.generate], suppress_health_check=list(HealthCheck))
    @given(generating_functions())
    def collect(function: Any) -> None:
        if function.expression not in found and function.expression not in excluded and len(found) < count:
            found.append(function.expression)

    collect()
    return found


def worker(expression: str, points: int, with_c: bool) -> dict[str, Any]:
    from tests.reference import GeneratingFunction

    return measure_expression(GeneratingFunction(expression), "generated", points, with_c,
                              {"expression": expression})


def misses(result: dict[str, Any]) -> list[str]:
    """'backend precision function: worst ulp/κ at φ (worst ulp at φ)' of every tally that misses
    the target."""
    from accuracy_corpus import miss_text, verdict

    return [f"{t['backend']} {t['precision']} {t['function']} {miss_text(t)}"
            for t in result.get("tallies", []) if verdict([t]) not in GOOD]


def report(results: list[dict[str, Any]], command: str, with_c: bool, held_out: bool = False,
           indices: list[int] | None = None) -> str:
    """The markdown table of ``results``; a row's number is its index in the sample (``indices``,
    default 0, 1, …)."""
    columns = COLUMNS if with_c else COLUMNS[:2]
    met = [r for r in results if "tallies" in r and all(_verdicts(r).get(k) in GOOD for k in columns)]
    failed = [r for r in results if "tallies" not in r]
    sample = ("a held-out sample: seeded, none of the default sample's first 200" if held_out
              else "derandomized")
    lines = ["# Accuracy of the generated code for hypothesis-generated functions (issue 16)", "",
             f"Produced by `{command}`: the grammar of tests/strategies.py, {sample}; each function "
             "emitted and measured as in docs/accuracy_corpus.md "
             f"({'NumPy and C' if with_c else 'NumPy only'}, both precisions).", "",
             f"**Target met** (meets or conditioned, no NaN/Inf): {len(met)} of {len(results)}; "
             f"emit or worker failures: {len(failed)}.", "",
             "| # | p(φ) | emit s | φ_max | verdicts (" + ", ".join(f"{b} {p}" for b, p in columns)
             + ") | misses (worst 3) |", "|---|---|---|---|---|---|"]
    for i, r in zip(indices or range(len(results)), results, strict=True):
        if "tallies" not in r:
            reason = r.get("emit_error") or r.get("worker_error") or "no result"
            lines.append(f"| {i} | `{r['expression']}` | — | — | **failed**: {reason} | |")
            continue
        found = _verdicts(r)
        cells = ", ".join(found.get(k, "—") for k in columns)
        worst = "; ".join(misses(r)[:3])
        lines.append(f"| {i} | `{r['expression']}` | {r['emit_seconds']:.1f} | "
                     f"{r['phi_max_reference']:.4g} | {cells} | {worst} |")
    return "\n".join(lines)


def run_worker(expression: str, points: int, with_c: bool) -> dict[str, Any]:
    """Emit and measure one function in its own process, bounded by WORKER_TIMEOUT."""
    run = [sys.executable, __file__, "--worker", expression, "--points", str(points)]
    run += [] if with_c else ["--no-c"]
    try:
        done = subprocess.run(run, capture_output=True, text=True, timeout=WORKER_TIMEOUT, check=False)
    except subprocess.TimeoutExpired:
        return {"expression": expression, "worker_error": f"timeout after {WORKER_TIMEOUT} s"}
    if done.returncode != 0:
        return {"expression": expression,
                "worker_error": f"worker exit {done.returncode}: {done.stderr.strip().splitlines()[-1:]}"}
    result: dict[str, Any] = json.loads(done.stdout.strip().splitlines()[-1])
    return result


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--count", type=int, default=DEFAULT_COUNT)
    parser.add_argument("--points", type=int, default=4)
    parser.add_argument("--no-c", action="store_true")
    parser.add_argument("--jobs", type=int, default=1, help="functions measured at once (one process each)")
    parser.add_argument("--out", default="docs/accuracy_hypothesis.md")
    parser.add_argument("--json", help="also write the raw results here (after every function)")
    parser.add_argument("--resume", action="store_true",
                        help="keep the results already in --json and measure only the missing functions")
    parser.add_argument("--seed", type=int,
                        help="a held-out sample: draw with this seed instead, leaving out the default "
                             "sample's first 200 functions")
    parser.add_argument("--leave-out", type=int, default=0, metavar="COUNT",
                        help="measure only the functions that a run with --count COUNT did not (its "
                             "functions are a subset, in another order); rows keep their index")
    parser.add_argument("--worker", help=argparse.SUPPRESS)
    args = parser.parse_args(argv)
    if args.worker is not None:
        print(json.dumps(worker(args.worker, args.points, not args.no_c)))
        return 0
    if args.resume and not args.json:
        parser.error("--resume needs --json")
    command = "python bench/accuracy_hypothesis.py " + " ".join(
        a for a in (argv if argv is not None else sys.argv[1:]) if a != "--resume")
    expressions = (draw(args.count) if args.seed is None
                   else draw_held_out(args.count, args.seed, frozenset(draw(DEFAULT_COUNT))))
    left_out = frozenset(draw(args.leave_out)) if args.leave_out else frozenset()
    index = {e: i for i, e in enumerate(expressions)}
    expressions = [e for e in expressions if e not in left_out]
    found: dict[str, dict[str, Any]] = {}
    if args.resume and Path(args.json).exists():
        found = {r["expression"]: r for r in json.loads(Path(args.json).read_text(encoding="utf-8"))
                 if r["expression"] in expressions}
    pending = [e for e in expressions if e not in found]
    print(f"{len(found)} of {len(expressions)} already measured; {len(pending)} to go", flush=True)
    started = time.perf_counter()
    with ThreadPoolExecutor(max_workers=max(1, args.jobs)) as pool:
        futures = {pool.submit(run_worker, e, args.points, not args.no_c): e for e in pending}
        for future in as_completed(futures):
            result = future.result()
            found[result["expression"]] = result
            print(f"{len(found)}/{len(expressions)} {result['expression']}: "
                  f"{time.perf_counter() - started:.0f} s "
                  f"{result.get('emit_error') or result.get('worker_error') or ''}", flush=True)
            results = [found[e] for e in expressions if e in found]
            if args.json:
                Path(args.json).write_text(json.dumps(results, indent=1), encoding="utf-8")
            Path(args.out).write_text(report(results, command.strip(), not args.no_c, args.seed is not None,
                                             [index[r["expression"]] for r in results]) + "\n",
                                      encoding="utf-8")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
