"""Mutation check (issue 61): does the suite catch the faults that would hurt a user?

Each entry of :data:`MUTATIONS` (bench/mutation_list.py) is a small, deliberate fault in the
core, the plan, a backend's printer, a generated module's runtime or the command line. For each,
this script

1. copies the working tree (without .git and caches) into a temporary directory,
2. applies the edit: every ``old`` text must occur exactly as often as the entry says, so a
   mutation that no longer applies fails loudly instead of passing silently,
3. regenerates the generated files the fault reaches (``python -m symrot.generate``), and checks
   that they changed — a fault that leaves every output identical is *equivalent* and reported
   as an error of the list, not as a kill,
4. runs the tests that should catch it with ``PYTHONPATH`` on the copy, without the staleness
   check of generated/ (:data:`NOT_COUNTED`: it compares bytes, so it would "kill" every edit of
   a generated file without saying whether anything checks the values),
5. records the tests that failed. *Killed* means a test failed (pytest exit 1, or 2 when
   pytest-xdist stops the session at the first failure); any other outcome (collection error,
   time limit) is an error of the check.

Before the mutations, the same tests run on an unmutated copy and must pass (``--no-baseline``
skips it): a test that fails in a copy of the tree for another reason would count as a kill.

It writes docs/mutations.md (which tests killed each mutation, with the command that produced
it) and exits 1 unless every mutation is killed. The tests it runs are tests of ``make test``;
the unmutated suite must pass first (``make test`` does that in CI before ``make mutations``).

Run: ``python bench/mutations.py [--only NAME ...] [--jobs N] [--out docs/mutations.md]``.
"""

from __future__ import annotations

import argparse
import os
import re
import shutil
import subprocess
import sys
import tempfile
import time
from dataclasses import dataclass, field
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path[:0] = [str(ROOT), str(ROOT / "bench")]

from mutation_list import MUTATIONS, Mutation  # noqa: E402

from symrot.core.atomic import write_atomic  # noqa: E402

NOT_COUNTED = ("tests/test_generated.py::test_generated_files_are_current",)
"""Byte comparisons with a fresh generation: they see any edit of generated/, never its effect."""
IGNORED = (".git", "__pycache__", ".mypy_cache", ".ruff_cache", ".pytest_cache", ".hypothesis",
           "*.egg-info", "build", "dist", "docs/_build")
REGENERATE = """
import sys
from pathlib import Path
from symrot.core.atomic import write_atomic
from symrot.generate import render
for relative, content in render(sys.argv[1], 1, sys.argv[2] or None).items():
    write_atomic(Path("generated") / relative, content.encode() if isinstance(content, str) else content)
"""
"""``symrot.generate``'s files of one producer (and one parameterization) written into generated/
(its command line writes only whole producers)."""
TEST_TIMEOUT = 1500
"""Seconds one mutant's tests may take (a hang is an error, not a kill)."""


@dataclass
class Outcome:
    """What happened to one mutation."""

    mutation: Mutation
    status: str = "error"
    """killed, survived or error."""
    killers: list[str] = field(default_factory=list)
    detail: str = ""
    seconds: float = 0.0


def copy_tree(destination: Path) -> Path:
    """The working tree at ``destination`` (tracked and untracked files, no caches)."""
    shutil.copytree(ROOT, destination, ignore=shutil.ignore_patterns(*IGNORED), symlinks=True)
    return destination


def apply(mutation: Mutation, tree: Path) -> None:
    """Apply every edit of ``mutation`` in ``tree``; ValueError when one does not match."""
    for edit in mutation.edits:
        paths = sorted(tree.glob(edit.path))
        if not paths:
            raise ValueError(f"{edit.path}: no such file")
        for path in paths:
            text = path.read_text(encoding="utf-8")
            found = text.count(edit.old)
            if found != edit.count and not (edit.count == 0 and found > 0):
                expected = "some" if edit.count == 0 else str(edit.count)
                raise ValueError(f"{path.relative_to(tree)}: {found} occurrences of {edit.old!r}, "
                                 f"expected {expected}")
            path.write_text(text.replace(edit.old, edit.new), encoding="utf-8")


def environment(tree: Path) -> dict[str, str]:
    """This process's environment with the mutant first on the import path and its own cache."""
    env = dict(os.environ)
    env["PYTHONPATH"] = str(tree) + (os.pathsep + env["PYTHONPATH"] if env.get("PYTHONPATH") else "")
    env["SYMROT_CACHE_DIR"] = str(tree / ".mutant-cache")
    env.pop("PYTEST_ADDOPTS", None)
    return env


def regenerate(mutation: Mutation, tree: Path) -> None:
    """Rewrite the generated files the fault reaches; ValueError when none of them changed."""
    if not mutation.regenerate:
        return
    before = {path: path.read_bytes() for path in (tree / "generated").rglob("*") if path.is_file()}
    for only, name in mutation.regenerate:
        command = [sys.executable, "-c", REGENERATE, only, name]
        result = subprocess.run(command, cwd=tree, env=environment(tree), capture_output=True,
                                text=True, timeout=TEST_TIMEOUT, check=False)
        if result.returncode != 0:
            raise ValueError(f"regeneration failed: {result.stderr.strip().splitlines()[-1:]}")
    after = {path: path.read_bytes() for path in (tree / "generated").rglob("*") if path.is_file()}
    if after == before:
        raise ValueError("equivalent: the regenerated files are byte-identical")


def pytest_command(mutation: Mutation, jobs: int) -> list[str]:
    """The pytest run of ``mutation``'s tests (first failure stops it)."""
    command = [sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider", "-x", "-rf",
               "--no-header"]
    if jobs > 1 and mutation.parallel:
        command += ["-n", str(jobs), "--dist", "worksteal"]
    else:
        command += ["-p", "no:xdist"]
    for node in NOT_COUNTED:
        command += ["--deselect", node]
    return command + list(mutation.tests)


def failed_tests(output: str) -> list[str]:
    """The node ids pytest reported as failed (``-rf``: ``FAILED <node id> - <message>``). A node
    id's parameters may hold spaces and " - " (``[phi - sin(phi)]``): it ends at the first "]"
    followed by the message or the end of the line."""
    found = set()
    for line in re.findall(r"^FAILED (.+)$", output, flags=re.MULTILINE):
        head = line.split(" ", 1)[0]
        if "[" in head:
            ends = [m.end() for m in re.finditer(r"\](?= - |$)", line)]
            head = line[:ends[0]] if ends else head
        found.add(head)
    return sorted(found)


def run(mutation: Mutation, jobs: int, with_tests: bool = True) -> Outcome:
    """Apply, regenerate and test one mutation in a fresh copy of the tree (``with_tests`` False:
    only check that it applies and changes what it should)."""
    outcome = Outcome(mutation)
    start = time.monotonic()
    with tempfile.TemporaryDirectory(prefix=f"symrot-mutant-{mutation.name}-") as scratch:
        tree = copy_tree(Path(scratch) / "tree")
        try:
            apply(mutation, tree)
            regenerate(mutation, tree)
        except (ValueError, subprocess.TimeoutExpired) as error:
            outcome.detail = str(error)
            outcome.seconds = time.monotonic() - start
            return outcome
        missing = [t for t in mutation.tests if not (tree / t.split("::")[0]).exists()]
        if not with_tests or missing:
            outcome.status = "applies" if not missing else "error"
            outcome.detail = f"no such test file: {', '.join(missing)}" if missing else ""
            outcome.seconds = time.monotonic() - start
            return outcome
        try:
            result = subprocess.run(pytest_command(mutation, jobs), cwd=tree, env=environment(tree),
                                    capture_output=True, text=True, timeout=TEST_TIMEOUT, check=False)
        except subprocess.TimeoutExpired:
            outcome.detail = f"tests did not finish in {TEST_TIMEOUT} s"
        else:
            output = result.stdout + result.stderr
            outcome.killers = failed_tests(output)
            if result.returncode in (1, 2) and outcome.killers:  # 2: xdist's -x stops the session
                outcome.status = "killed"
            elif result.returncode == 0:
                outcome.status = "survived"
                outcome.detail = (output.strip().splitlines() or [""])[-1]
            else:
                tail = " | ".join(output.strip().splitlines()[-3:])
                outcome.detail = f"pytest exit {result.returncode}: {tail}"
    outcome.seconds = time.monotonic() - start
    return outcome


def report(outcomes: list[Outcome], command: str, baseline: float | None) -> str:
    """docs/mutations.md: one row per mutation, the tests that killed it."""
    killed = sum(o.status == "killed" for o in outcomes)
    lines = [
        "# Mutation check",
        "",
        f"Generated by `{command}` (bench/mutations.py; the list is bench/mutation_list.py).",
        "",
        "Each mutation is applied to a copy of the tree, the generated files it reaches are regenerated",
        "(and must change), and the tests listed for it run with the first failure stopping the run, "
        "without",
        "the byte comparison of generated/ (`" + "`, `".join(NOT_COUNTED) + "`).",
        "Killed: a test failed. The first failing test is what is listed (`-x`); more may fail.",
        "",
        "Baseline: " + ("not run (`--no-baseline`)." if baseline is None
                        else f"the same tests pass on an unmutated copy ({baseline:.0f} s)."),
        "",
        f"**{killed} of {len(outcomes)} killed.**",
        "",
        "| # | mutation | layer | fault | result | killed by | s |",
        "|---|---|---|---|---|---|---|",
    ]
    for index, o in enumerate(outcomes, 1):
        result = o.status if not o.detail or o.status == "killed" else f"{o.status}: {o.detail}"
        killers = "<br>".join(f"`{k}`" for k in o.killers) or "—"
        lines.append(f"| {index} | `{o.mutation.name}` | {o.mutation.layer} | {o.mutation.fault} | "
                     f"{result.replace('|', '/')} | {killers} | {o.seconds:.0f} |")
    return "\n".join(lines) + "\n"


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--only", nargs="*", default=None, help="names of the mutations to run")
    parser.add_argument("--jobs", type=int, default=2, help="pytest-xdist workers per mutant")
    parser.add_argument("--out", type=Path, default=None, help="write the markdown report here")
    parser.add_argument("--list", action="store_true", help="list the mutations and exit")
    parser.add_argument("--no-baseline", dest="baseline", action="store_false",
                        help="skip the first run: the listed tests on an unmutated copy must pass")
    parser.add_argument("--no-tests", action="store_true",
                        help="only check that each mutation applies and changes the files it regenerates")
    args = parser.parse_args(argv)
    if args.list:
        for mutation in MUTATIONS:
            print(f"{mutation.name:32} {mutation.layer:10} {mutation.fault}")
        return 0
    names = {m.name for m in MUTATIONS}
    unknown = sorted(set(args.only or ()) - names)
    if unknown:
        print(f"error: no mutation named {', '.join(unknown)}", file=sys.stderr)
        return 2
    chosen = [m for m in MUTATIONS if args.only is None or m.name in args.only]
    baseline = None
    if args.baseline:
        tests = tuple(dict.fromkeys(t for m in chosen for t in m.tests))
        clean = run(Mutation("baseline", "-", "none", (), tests), args.jobs, not args.no_tests)
        verdict = "passed" if clean.status == "survived" else f"{clean.status} {clean.detail}"
        print(f"baseline {clean.seconds:6.0f} s  {verdict} {' '.join(clean.killers)}", flush=True)
        if clean.status not in ("survived", "applies"):
            print("error: the unmutated copy does not pass the tests of the list", file=sys.stderr)
            return 2
        baseline = clean.seconds
    outcomes = []
    for mutation in chosen:
        outcome = run(mutation, args.jobs, not args.no_tests)
        outcomes.append(outcome)
        shown = ", ".join(outcome.killers[:2]) if outcome.status == "killed" else outcome.detail
        print(f"{outcome.status:8} {mutation.name:32} {outcome.seconds:6.0f} s  {shown}", flush=True)
    killed = sum(o.status == "killed" for o in outcomes)
    if args.no_tests:
        applies = sum(o.status == "applies" for o in outcomes)
        print(f"{applies} of {len(outcomes)} mutations apply")
        return 0 if applies == len(outcomes) else 1
    print(f"{killed} of {len(outcomes)} mutations killed")
    if args.out is not None:
        command = " ".join(["python bench/mutations.py", *(argv if argv is not None else sys.argv[1:])])
        write_atomic(args.out, report(outcomes, command, baseline))
    return 0 if killed == len(outcomes) else 1


if __name__ == "__main__":
    sys.exit(main())
