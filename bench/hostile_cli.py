"""A hostile user at the command line: every input answered in time, exit 0 or 2, no traceback.

The corpus covers every subcommand with code injections (``__import__``, lambda, attribute
access, f-strings...), resource bombs (nested powers, huge literals in every base, towers of
exponentials), invalid and borderline-valid generating functions, bad paths for ``--out`` and bad
options. Each input runs as a subprocess ``python -m symrot --timeout BUDGET ...`` (so through the
worker process of :mod:`symrot.cli.worker`) in a scratch directory, two at a time, and must:

* exit with status 0 or 2 (never 70, the internal error, nor a signal);
* finish within BUDGET plus a margin for interpreter start-up;
* print no "Traceback" and no "internal error" on stderr.

``tests/test_hostile_cli.py`` runs :data:`QUICK` with a small budget and :data:`HEAVY` as a slow
test; ``python bench/hostile_cli.py [BUDGET]`` runs those and :data:`EXTRA` with the default
budget of 60 s and prints one line per input (status, seconds, the last line of stderr).
``python bench/hostile_cli.py --cache`` runs the plan cache's cases instead (:func:`run_cache_cases`,
the last section).

:func:`run_all_preloaded` is the quick tier's runner: the same command line (``symrot.cli.main``
on ``sys.argv``, its worker process and budget included), each input in a process forked from a
server that imported ``symrot.cli`` once (:func:`serve`), so that 166 inputs do not pay 166
interpreter and SymPy start-ups (about 1.4 s each on this machine). What start-up itself does is tested by
:func:`run_all` (``HEAVY``, the long run) and by tests/test_install.py.
"""

from __future__ import annotations

import argparse
import json
import os
import queue
import signal
import subprocess
import sys
import tempfile
import time
import traceback
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass
from pathlib import Path
from typing import Any, NoReturn

MARGIN = 12.0
"""Seconds allowed beyond the budget: interpreter start-up and the worker's grace period on a
loaded two-core machine."""

INJECTIONS = [
    "__import__('os').system('touch pwned')",
    "__import__('subprocess').call(['true'])",
    "eval('1+1')",
    "exec('import os')",
    "open('/etc/passwd').read()",
    "compile('1', 'f', 'eval')",
    "globals()",
    "getattr(phi, 'func')",
    "phi.func",
    "phi.__class__.__mro__",
    "().__class__.__bases__[0].__subclasses__()",
    "sin.__call__(phi)",
    "sympy.sin(phi)",
    "lambda: 1",
    "(lambda x: x)(phi)",
    "f'{phi}'",
    "f'{__import__(\"os\").getcwd()}'",
    "[phi for phi in range(10**9)]",
    "phi if phi else 1",
    "(x := 1)",
    "phi[0]",
    "{'a': phi}",
    "'string'",
    "b'bytes'",
    "None",
    "True * phi",
    "...",
    "1j * phi",
    "breakpoint()",
    "print(phi)",
    "__builtins__",
    "phi.evalf(10**9)",
    "phi; import os",
    "phi\nimport os",
    "await phi",
    "sin(*[phi])",
    "sin(x=phi)",
    "ᵖʰⁱ.__class__",
    "phi @ phi",
    "phi // 2",
]

BOMBS = [
    "(((1+phi)**64)**64)**64",
    "((1+phi)**64)**64",
    "(phi**64)**64",
    "(1+phi+phi**2+phi**3+phi**4)**64",
    "phi*(sqrt(2)+sqrt(3)+sqrt(5)+sqrt(7))**64",
    "(10**30)**64*phi",
    "phi + (10**30)**64*phi**3",
    "0x" + "f" * 256 + "*phi",
    "0o" + "7" * 100 + "*phi",
    "0b" + "1" * 400 + "*phi",
    "9" * 5000,
    "1" + "_0" * 60 + "*phi",
    "1e999999*phi",
    "9.9e-400*phi",
    "2**2**2**2**2",
    "phi**10**100",
    "phi**(10**6)",
    "phi**(1/10**6)",
    "exp(" * 34 + "phi" + ")" * 34,
    "(" * 300 + "phi" + ")" * 300,
    "-" * 5000 + "phi",
    "+".join(["phi"] * 500),
    "phi" + "*phi" * 200,
    "a" + "9" * 100000 + "b",  # issue 55: the unknown-name message scanned this in quadratic time
    "10**10000*phi",  # issue 55: raised ValueError in the API, not SymrotError
]

INVALID = [
    "cos(phi)", "sqrt(phi)", "phi**2", "phi**3", "1/phi", "log(phi)", "exp(phi)", "sin(phi) + 1",
    "tan(pi/2 + phi)", "acosh(phi)", "phi**(1/3)", "cbrt(phi)**2", "abs(phi)", "sqrt(phi**2)",
    "x + phi", "phi + y", "sin(phi, 2)", "sin()", "1/0", "phi/0", "(-8)**(1/3)", "0**-1",
    "phi**phi", "phi**sqrt(2)", "phi**pi", "", " ", "phi +", "((phi)", "phi)", "sin", "φ**2",
    "phi*sin(1/phi)", "exp(-1/phi**2)", "phi + phi**2", "sin(phi)*cos(phi)**2 + 1e-30",
    "asin(phi + 2)", "log(-phi**2 - 1)", "sqrt(-1 - phi**2)*phi", "sin(phi)/phi",
]

VALID = [
    "-phi", "phi", "sin(phi)", "asin(phi)", "2*asin(phi/2)", "atanh(phi)",
    "phi/sqrt(1-phi**2)", "log((1+phi)/(1-phi))/2", "1e-20*phi", "2**64*phi", "0x10*phi",
    "sinh(phi)", "phi + phi**3", "-sin(-phi)", "cbrt(6*(phi-sin(phi)))", "phi*(1+phi**2)**32",
]

PATHS = ["/proc", "/dev/null/x", "/etc/passwd/x", "/proc/self/x", "/sys/kernel/x", ""]


def _derive(expression: str, *options: str) -> list[str]:
    return ["derive", expression, *options]


QUICK: list[list[str]] = (
    [_derive(text) for text in INJECTIONS]
    + [["solve", f"mu = {text}"] for text in INJECTIONS[:6]]
    + [[command, text, "--out", command] for command in ("table", "sheet") for text in INJECTIONS[:3]]
    + [["plot", "--add", text, "--out", "plots"] for text in INJECTIONS[:3]]
    + [_derive(text) for text in BOMBS]
    + [["solve", f"p = {text}"] for text in BOMBS[:4]]
    + [["table", text, "--out", "tables"] for text in BOMBS[:2]]
    + [_derive(text) for text in INVALID[:30]]
    + [_derive(text, "--json") for text in VALID[:3]]
    + [_derive("phi", "--emit", "numpy", "--out", path) for path in PATHS[1:4]]
    + [["plot", "--figure", "1", "--format", "png", "--out", path] for path in PATHS[1:4]]
    + [["table", "phi", "--out", PATHS[1]], ["sheet", "phi", "--out", PATHS[0]]]
    + [
        [], ["frobnicate"], ["derive"], ["solve"], ["sheet"], ["--timeout", "-1", "derive", "phi"],
        ["--timeout", "nan", "derive", "phi"], ["--timeout", "inf", "derive", "phi"],
        ["--timeout", "abc", "derive", "phi"], ["derive", "phi", "--terms", "0"],
        ["derive", "phi", "--terms", "99"], ["derive", "phi", "--terms", "abc"],
        ["derive", "phi", "--emit", "fortran"], ["derive", "phi", "--emit", "c", "--name", "a b"],
        ["derive", "phi", "--emit", "numpy", "--name", "../escape"], ["derive", "--bogus", "phi"],
        ["derive", "phi", "extra"], ["plot", "--figure", "9"], ["plot", "--format", "svg"],
        ["plot", "--format", ","], ["table", "--columns", "nope"], ["sheet", "phi", "--name", "../x"],
        ["solve", "mu"], ["solve", "a = b = c"], ["solve", "mu == 1"], ["solve", "x = 1"],
        ["solve", "--m", "0", "mu = 1"], ["solve", "--m", "-3", "mu = 1"], ["solve", "--m", "x", "mu = 1"],
        ["solve", "c = 1"], ["audit", "--only", "no-such-key"],
        ["derive", "nonexistent_m0"], ["derive", "sine_m0"], ["derive", "sine_m99999"],
        ["derive", "cayley_m1001"], ["derive", "\u202ephi"], ["derive", "phi\u200b"],
        ["derive", "２*phi"], ["derive", "phi 🙂"], ["derive", "-phi", "--timeout", "20"],
        ["solve", "mu = 1"],
    ]
)
"""Inputs answered in a few seconds: rejected early, or cheap valid functions."""

EXTRA: list[list[str]] = (
    [["solve", f"mu = {text}"] for text in INJECTIONS[6:]]
    + [[command, text, "--out", command] for command in ("table", "sheet") for text in INJECTIONS[3:12]]
    + [["plot", "--add", text, "--out", "plots"] for text in INJECTIONS[3:12]]
    + [["solve", f"p = {text}"] for text in BOMBS[4:]]
    + [_derive(text) for text in INVALID[30:]]
    + [_derive(text, "--json") for text in VALID[3:]]
    + [["table", "phi", "--out", path] for path in PATHS[2:]]
    + [["sheet", "phi", "--out", path] for path in PATHS[1:]]
    + [["derive", "φ", "--json"], ["--timeout", "5", "derive", "wiener_milenkovic"],
       ["solve", "det_H = const", "--json"], ["solve", "p_prime = p_prime"]]
)
"""More of the same for the long run (``python bench/hostile_cli.py``)."""

HEAVY: list[list[str]] = [
    _derive("tan(" * 31 + "phi" + ")" * 31),
    _derive("sinh(" * 20 + "phi" + ")" * 20),
    _derive("asin(" * 8 + "phi" + ")" * 8),
    ["solve", "mu = exp(-exp(exp(exp(64))))"],
    ["solve", "det_H = exp(exp(exp(p)))"],
    ["table", "asin(phi)", "--out", "tables"],
    ["sheet", "asin(phi)", "--out", "sheets"],
    _derive("1e-20*phi", "--emit", "c", "--out", "code"),
    _derive("phi", "--emit", "c", "--out", "/proc"),
    ["plot", "--add", "asin(phi)", "--figure", "3", "--format", "png", "--out", "plots"],
    *[_derive(text) for text in VALID[3:9]],
]
"""Inputs that run into the budget or do real work (derivation, planning, figures)."""


@dataclass(frozen=True)
class Outcome:
    args: tuple[str, ...]
    status: int
    seconds: float
    stderr: str

    def problems(self, budget: float, margin: float = MARGIN) -> list[str]:
        """What this run did wrong (empty when it behaved)."""
        found = []
        if self.status not in (0, 2):
            found.append(f"exit {self.status}")
        if self.seconds > budget + margin:
            found.append(f"took {self.seconds:.1f} s (budget {budget:g} s)")
        if "Traceback" in self.stderr or "internal error" in self.stderr:
            found.append("traceback or internal error")
        return found


def run_one(args: list[str], budget: float, directory: str) -> Outcome:
    """``python -m symrot --timeout BUDGET *args`` in ``directory``."""
    started = time.monotonic()
    try:
        result = subprocess.run([sys.executable, "-m", "symrot", "--timeout", f"{budget:g}", *args],
                                capture_output=True, text=True, cwd=directory, check=False,
                                timeout=budget + 10 * MARGIN)
        status, stderr = result.returncode, result.stderr
    except subprocess.TimeoutExpired as exc:
        status, stderr = -9, str(exc.stderr or "")
    return Outcome(tuple(args), status, time.monotonic() - started, stderr)


def run_all(corpus: list[list[str]], budget: float, workers: int = 2) -> list[Outcome]:
    """Every input of ``corpus``, ``workers`` at a time, each in its own scratch directory."""
    with tempfile.TemporaryDirectory(prefix="symrot-hostile-") as scratch, \
            ThreadPoolExecutor(max_workers=workers) as pool:
        return list(pool.map(lambda args: run_one(args, budget, scratch), corpus))


def serve() -> None:
    """The preloaded server of :func:`run_all_preloaded`: imports ``symrot.cli`` once, then for
    each request on stdin (one JSON object per line: args, budget, directory, stderr path) forks a
    child that runs the command (:func:`_command_in_child`), waits for it at most the budget plus
    ``10 * MARGIN`` (then kills it: status -9), and answers ``[status, seconds]`` on stdout."""
    import symrot.cli  # noqa: F401 - imported once here, inherited by every child

    for line in sys.stdin:
        request = json.loads(line)
        started = time.monotonic()
        pid = os.fork()
        if pid == 0:
            _command_in_child(request)
        status = _wait_or_kill(pid, request["budget"] + 10 * MARGIN)
        print(json.dumps([status, time.monotonic() - started]), flush=True)


def _command_in_child(request: dict[str, Any]) -> NoReturn:
    """``symrot --timeout BUDGET *args`` in the request's directory as the console script runs it
    (``symrot.cli.main`` reading ``sys.argv``, through its worker process), stdin and stdout on
    /dev/null, stderr into the request's file; ends the process with the command's status."""
    code = 70
    try:
        os.chdir(request["directory"])
        null = os.open(os.devnull, os.O_RDWR)
        err = os.open(request["stderr"], os.O_WRONLY | os.O_CREAT | os.O_TRUNC)
        for target, fd in ((0, null), (1, null), (2, err)):
            os.dup2(fd, target)
        sys.stdin = open(0, encoding="utf-8", closefd=False)  # noqa: SIM115 - the process's own
        sys.stdout = open(1, "w", encoding="utf-8", closefd=False)  # noqa: SIM115
        sys.stderr = open(2, "w", encoding="utf-8", closefd=False)  # noqa: SIM115
        sys.argv = ["symrot", "--timeout", f"{request['budget']:g}", *request["args"]]
        from symrot.cli import main

        code = main()
    except SystemExit as exc:
        code = exc.code if isinstance(exc.code, int) else int(exc.code is not None)
    except BaseException:  # reported like an uncaught exception of the real command
        traceback.print_exc()
        code = 1
    finally:
        try:
            sys.stdout.flush()
            sys.stderr.flush()
        finally:
            os._exit(code)


def _wait_or_kill(pid: int, seconds: float) -> int:
    """The exit status of child ``pid`` as :mod:`subprocess` gives it (−N for signal N), killing
    it after ``seconds``."""
    deadline = time.monotonic() + seconds
    while True:
        done, status = os.waitpid(pid, os.WNOHANG)
        if done:
            return os.waitstatus_to_exitcode(status)
        if time.monotonic() > deadline:
            os.kill(pid, signal.SIGKILL)
            os.waitpid(pid, 0)
            return -9
        time.sleep(0.005)


def run_all_preloaded(corpus: list[list[str]], budget: float, workers: int = 2) -> list[Outcome]:
    """Every input of ``corpus`` like :func:`run_all`, each in a process forked from one of
    ``workers`` servers (:func:`serve`) that have ``symrot.cli`` imported, started with
    ``PYTHONHASHSEED=0`` as the ``symrot`` command re-executes itself."""
    pending: queue.Queue[tuple[int, list[str]]] = queue.Queue()
    for item in enumerate(corpus):
        pending.put(item)
    outcomes: dict[int, Outcome] = {}
    server_code = (f"import sys; sys.path.insert(0, {str(Path(__file__).parent)!r}); "
                   "import hostile_cli; hostile_cli.serve()")
    with tempfile.TemporaryDirectory(prefix="symrot-hostile-") as scratch:
        def drive() -> None:
            with subprocess.Popen([sys.executable, "-c", server_code], stdin=subprocess.PIPE,
                                  stdout=subprocess.PIPE, text=True, cwd=scratch,
                                  env=dict(os.environ, PYTHONHASHSEED="0")) as server:
                assert server.stdin is not None and server.stdout is not None
                while True:
                    try:
                        index, args = pending.get_nowait()
                    except queue.Empty:
                        break
                    stderr_path = Path(scratch) / f"stderr-{index}.txt"
                    server.stdin.write(json.dumps({"args": args, "budget": budget, "directory": scratch,
                                                   "stderr": str(stderr_path)}) + "\n")
                    server.stdin.flush()
                    reply = server.stdout.readline()
                    if not reply:
                        raise RuntimeError(f"the preloaded server ended while running {args!r}")
                    status, seconds = json.loads(reply)
                    stderr = stderr_path.read_text(encoding="utf-8", errors="replace")
                    outcomes[index] = Outcome(tuple(args), status, seconds, stderr)
                server.stdin.close()

        with ThreadPoolExecutor(max_workers=workers) as pool:
            for future in [pool.submit(drive) for _ in range(workers)]:
                future.result()
    return [outcomes[index] for index in range(len(corpus))]


def main(argv: list[str]) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("budget", nargs="?", type=float, default=60.0,
                        help="seconds each input may take (--timeout of every command; default 60)")
    budget: float = parser.parse_args(argv).budget
    started = time.monotonic()
    with tempfile.TemporaryDirectory(prefix="symrot-hostile-plans-") as plans:
        # the plan cache of --emit takes part, in a directory of its own instead of ~/.cache
        os.environ.setdefault("SYMROT_CACHE_DIR", plans)
        outcomes = run_all(QUICK + EXTRA + HEAVY, budget)
    bad = 0
    for outcome in outcomes:
        problems = outcome.problems(budget)
        bad += bool(problems)
        last = (outcome.stderr.strip().splitlines() or [""])[-1][:100]
        print(f"{'FAIL' if problems else 'ok  '} {outcome.status:>3} {outcome.seconds:6.1f} s  "
              f"{' '.join(outcome.args)[:60]!r:64} {last}")
    print(f"{len(outcomes)} inputs, {bad} failed, {time.monotonic() - started:.0f} s")
    return 1 if bad else 0



# OUTPUT (issue 55 items 3 and 5): options refused before any work, links inside --out not followed.

OUTPUT_CASES: list[tuple[str, dict[str, str], list[str], str]] = [
    ("timeout past the maximum", {}, ["--timeout", "1e10", "derive", "phi"], "maximum"),
    ("timeout past the maximum, in-process", {"SYMROT_WORKER": "0"}, ["--timeout", "1e10", "derive", "phi"],
     "maximum"),
    ("timeout 1e300", {}, ["derive", "phi", "--timeout", "1e300"], "maximum"),
    ("name of 250 characters", {}, ["derive", "phi", "--emit", "numpy", "--name", "x" * 250, "--out", "out"],
     "--name"),
    ("name numpy", {}, ["derive", "phi", "--emit", "numpy", "--name", "numpy", "--out", "out"], "shadow"),
    ("name functools", {}, ["derive", "phi", "--emit", "c,numpy", "--name", "functools", "--out", "out"],
     "shadow"),
    ("name __main__", {}, ["derive", "phi", "--emit", "numpy", "--name", "__main__", "--out", "out"],
     "dunder"),
    ("name class", {}, ["derive", "phi", "--emit", "numpy", "--name", "class", "--out", "out"], "keyword"),
    ("out below a file", {}, ["derive", "phi", "--emit", "numpy", "--out", "a_file/sub"], "cannot write"),
    ("out in /proc", {}, ["derive", "phi", "--emit", "numpy", "--out", "/proc/symrot"], "cannot write"),
    ("link to a file outside out", {}, ["derive", "phi", "--emit", "numpy", "--name", "rotation", "--out",
                                        "linked"], "symbolic link"),
    ("link to a directory outside out", {}, ["derive", "phi", "--emit", "c,numpy", "--name", "rotation",
                                             "--out", "linked"], "outside"),
]
"""(what, extra environment, arguments, a word of the one-line error): each must exit 2 with one
error line on stderr (argparse prints the usage above it), no traceback, and leave the files
outside ``--out`` as they were. ``linked`` holds a link ``rotation.py`` to a file outside it and a
link ``c`` to a directory outside it."""


def _output_scratch(directory: Path) -> None:
    (directory / "a_file").write_text("")
    (directory / "outside").mkdir()
    (directory / "outside.py").write_text("old\n")
    (directory / "linked").mkdir()
    (directory / "linked" / "rotation.py").symlink_to(directory / "outside.py")
    (directory / "linked" / "c").symlink_to(directory / "outside")


def run_output_cases(cases: list[tuple[str, dict[str, str], list[str], str]] | None = None) -> int:
    """Run :data:`OUTPUT_CASES` (each in a fresh scratch directory), print one line each; the
    number that misbehaved."""
    bad = 0
    for what, environment, args, word in OUTPUT_CASES if cases is None else cases:
        with tempfile.TemporaryDirectory(prefix="symrot-hostile-output-") as scratch:
            directory = Path(scratch)
            _output_scratch(directory)
            result = subprocess.run([sys.executable, "-m", "symrot", *args], capture_output=True, text=True,
                                    cwd=directory, env={**os.environ, **environment}, check=False,
                                    timeout=10 * MARGIN)
            lines = [line for line in result.stderr.splitlines() if "error:" in line]  # after a usage
            problems = [problem for problem, failed in [
                (f"exit {result.returncode}", result.returncode != 2),
                (f"{len(lines)} error lines", len(lines) != 1),
                ("a traceback", "Traceback" in result.stderr),
                (f"no {word!r} in the error", not any(word in line for line in lines)),
                ("a file outside --out changed", (directory / "outside.py").read_text() != "old\n"
                 or any((directory / "outside").iterdir())),
            ] if failed]
        bad += bool(problems)
        print(f"{'FAIL' if problems else 'ok  '} {result.returncode:>3} {what:40} "
              f"{'; '.join(problems) or (lines or [''])[-1][:80]}")
    print(f"{len(OUTPUT_CASES if cases is None else cases)} output cases, {bad} failed")
    return bad


# --- The plan cache of --emit (issue 55, items 1, 2 and 7): ``python bench/hostile_cli.py --cache`` ---

CACHE_PROBE = ([[0.3, -0.2, 0.5]], 0.95257673)
"""tangent(p)[0, 0, 0] of phi's module at this p: what every emit must print, whatever the cache holds."""


def _emit_phi(out: Path, environment: dict[str, str],
              cwd: Path | None = None) -> tuple[int, float | None, str]:
    """(exit status, tangent at :data:`CACHE_PROBE` of the module written, stderr's last line) of
    ``symrot derive phi --emit numpy --out OUT``."""
    import importlib.util

    command = [sys.executable, "-m", "symrot", "derive", "phi", "--emit", "numpy", "--out", str(out)]
    result = subprocess.run(command, capture_output=True, text=True, timeout=600, check=False, cwd=cwd,
                            env={**os.environ, "SYMROT_NO_CACHE": "", **environment})
    module_path = out / "rotation_vector.py"
    value = None
    if result.returncode == 0 and module_path.is_file():
        spec = importlib.util.spec_from_file_location(f"phi_{abs(hash(str(out)))}", module_path)
        assert spec is not None and spec.loader is not None
        module = importlib.util.module_from_spec(spec)
        spec.loader.exec_module(module)
        value = float(module.tangent(CACHE_PROBE[0])[0, 0, 0])
    return result.returncode, value, (result.stderr.strip().splitlines() or [""])[-1][:100]


def _right(value: float | None) -> bool:
    return value is not None and abs(value - CACHE_PROBE[1]) <= 1e-7 * CACHE_PROBE[1]


_IN_PROCESS_FLIPS = """
import json, os, sys
os.environ.update(SYMROT_CACHE_DIR=sys.argv[1], SYMROT_NO_CACHE="")
from symrot.api import derive
from symrot.cli import plan_cache
plan = plan_cache.evaluation_plan(derive("phi").derivation, "rotation_vector")
path = plan_cache.directory() / plan_cache.entry_name(plan.p, plan.name)
good = plan_cache.entry_bytes(plan, plan_cache.entry_key(plan.p, plan.name))
path.parent.mkdir(mode=0o700, parents=True, exist_ok=True)
counts = {"miss": 0, "same plan": 0, "other plan": 0, "exception": 0}
changes = [good[:i] + bytes([good[i] ^ (1 << i % 8)]) + good[i + 1:] for i in range(len(good))]
changes += [good[:length] for length in range(len(good))]
for content in changes:
    path.write_bytes(content)
    try:
        loaded = plan_cache.load(plan.p, plan.name)
    except Exception:
        counts["exception"] += 1
        continue
    counts["miss" if loaded is None else "same plan" if loaded == plan else "other plan"] += 1
print(json.dumps({"entry bytes": len(good), **counts}))
"""


def run_cache_cases() -> int:
    """The cache cases of issue 55, each printed as one line; 1 if any went wrong."""
    failures = 0

    def report(ok: bool, case: str, detail: str) -> None:
        nonlocal failures
        failures += not ok
        print(f"{'ok  ' if ok else 'FAIL'} {case:48} {detail}")

    with tempfile.TemporaryDirectory(prefix="symrot-hostile-cache-") as scratch_name:
        scratch = Path(scratch_name)
        root = scratch / "user-cache"
        root.mkdir()
        own = [root / f"mine-{index}.pickle" for index in range(300)] + [root / "notes.json"]
        for path in own:
            path.write_text("the user's")
        environment = {"SYMROT_CACHE_DIR": str(root)}
        status, value, last = _emit_phi(scratch / "out0", environment)
        report(status == 0 and _right(value), "first emit (stores phi's plan)",
               f"exit {status}, tangent {value} {last}")
        report(all(path.exists() for path in own), "300 *.pickle of the user's kept",
               f"{sum(map(Path.exists, own))} of {len(own)} left")
        entries = sorted((root / "symrot-plans-v1").glob("symrot-plan-*.json"))
        report(len(entries) == 1, "one entry, in symrot's own subdirectory",
               f"{[p.name[:24] for p in entries]}")
        if entries:
            good = entries[0].read_bytes()
            for run, offset in enumerate((55, 66, 1902, 2254, len(good) // 2, len(good) - 2)):
                offset = min(offset, len(good) - 1)
                corrupted = good[:offset] + bytes([good[offset] ^ 0x10]) + good[offset + 1:]
                entries[0].write_bytes(corrupted)
                status, value, last = _emit_phi(scratch / f"flip{run}", environment)
                # rewritten; not compared with ``good``: a plan computed on a loaded machine (its
                # time limits) may differ from the first and still print a right kernel
                report(status == 0 and _right(value) and entries[0].read_bytes() != corrupted,
                       f"emit over a byte flipped at {offset}", f"exit {status}, tangent {value} {last}")
            before = entries[0].read_bytes()
            entries[0].chmod(0o400)
            (root / "symrot-plans-v1").chmod(0o500)
            try:
                status, value, last = _emit_phi(scratch / "read-only", environment)
            finally:
                (root / "symrot-plans-v1").chmod(0o700)
            report(status == 0 and _right(value) and entries[0].read_bytes() == before,
                   "emit from a read-only cache", f"exit {status}, tangent {value} {last}")
        homeless = scratch / "homeless"
        homeless.mkdir()
        existed = Path("/.cache/symrot").exists()
        no_home = {"HOME": "", "XDG_CACHE_HOME": "", "SYMROT_CACHE_DIR": ""}
        status, value, last = _emit_phi(homeless / "out", no_home, cwd=homeless)
        report(status == 0 and _right(value) and [p.name for p in homeless.iterdir()] == ["out"]
               and (existed or not Path("/.cache/symrot").exists()), "emit with HOME='' (no cache)",
               f"exit {status}, tangent {value} {last}")
        flips = subprocess.run([sys.executable, "-c", _IN_PROCESS_FLIPS, str(scratch / "flips")],
                               capture_output=True, text=True, timeout=600, check=False,
                               env={**os.environ, "PYTHONHASHSEED": "0"})
        counts = json.loads(flips.stdout) if flips.returncode == 0 else {}
        report(bool(counts) and counts["other plan"] == 0 and counts["exception"] == 0,
               "every bit flip and truncation of phi's entry", f"{counts or flips.stderr[-200:]}")
    print(f"plan cache: {failures} failed")
    return 1 if failures else 0


# -- The Python API (issue 55, item 6) ---------------------------------------------------------

API_CASES: list[tuple[str, str]] = [
    ("long unknown name", "'a' + '9' * 200000 + 'b'"),
    ("long digits", "'9' * 200000"),
    ("long blank tail", "'phi' + ' ' * 200000"),
    ("a million letters", "'x' * 10**6"),
    ("huge integer", "sympy.Integer(10)**10000 * PHI"),
    ("huge float", "sympy.Float('1e400') * PHI"),
    ("NaN", "sympy.nan * PHI"),
    ("other symbol", "sympy.Symbol('x') * PHI"),
    ("plain phi symbol", "sympy.Symbol('phi')"),
    ("function outside the grammar", "sympy.Abs(PHI)"),
    ("None", "None"),
    ("bytes", "b'phi'"),
]
"""``symrot.derive`` on each (a Python expression with ``sympy`` and ``PHI`` in scope): every one
must end in a SymrotError within the budget (the long strings had run for minutes, the huge
integer was Python's ValueError)."""


def run_api_case(source: str, budget: float) -> Outcome:
    """``symrot.derive(<source>)`` in a fresh interpreter; exit 2 for a SymrotError, 0 for a
    result, 1 (with a traceback) for anything else; killed after ``budget + 10 * MARGIN``."""
    script = ("import sympy, symrot\nfrom symrot.core.parsing import PHI\n"
              f"try:\n    symrot.derive({source})\n"
              "except symrot.SymrotError as exc:\n    print(exc)\n    raise SystemExit(2)\n")
    started = time.monotonic()
    try:
        result = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True,
                                timeout=budget + 10 * MARGIN, check=False)
        status, stderr = result.returncode, result.stderr
    except subprocess.TimeoutExpired as exc:
        status, stderr = -9, str(exc.stderr or "")
    return Outcome(("derive", source), status, time.monotonic() - started, stderr)


def api_main(budget: float = 60.0) -> int:
    """Every :data:`API_CASES` entry; 1 when one misbehaves (see :meth:`Outcome.problems`)."""
    bad = 0
    for label, source in API_CASES:
        outcome = run_api_case(source, budget)
        problems = outcome.problems(budget)
        if outcome.status == 0:
            problems.append("accepted")
        bad += bool(problems)
        print(f"{'FAIL' if problems else 'ok  '} {outcome.status:>3} {outcome.seconds:6.1f} s  "
              f"{label:30} {', '.join(problems)}")
    print(f"{len(API_CASES)} API inputs, {bad} failed")
    return 1 if bad else 0


if __name__ == "__main__":
    if sys.argv[1:2] == ["--cache"]:
        raise SystemExit(run_cache_cases())
    codes = [main(sys.argv[1:]), run_output_cases(), api_main()]
    raise SystemExit(1 if any(codes) else 0)
