"""CLI conventions of well-liked Python tools (issue 15): --version, help without arguments, strict
JSON, did-you-mean, the κ that --normalize divides out, progress only on a terminal."""

from __future__ import annotations

import fcntl
import json
import os
import pty
import select
import struct
import subprocess
import sys
import termios
import time
from pathlib import Path

import pytest

from symrot import __version__
from symrot.cli.strict_json import dumps, strict


def run_cli(*args: str, timeout: float = 120) -> subprocess.CompletedProcess[str]:
    return subprocess.run([sys.executable, "-m", "symrot", *args], capture_output=True, text=True,
                          timeout=timeout, check=False)


def test_version() -> None:
    result = run_cli("--version")
    assert result.returncode == 0 and result.stdout.strip() == f"symrot {__version__}"


def test_no_arguments_prints_the_help_and_exits_zero() -> None:
    result = run_cli()
    assert result.returncode == 0
    assert result.stdout.startswith("usage: symrot")
    assert "derive" in result.stdout and "audit" in result.stdout
    assert run_cli("--help").stdout == result.stdout


def test_misuse_is_exit_two() -> None:
    assert run_cli("no-such-command").returncode == 2
    assert run_cli("derive").returncode == 2


def _no_non_finite(constant: str) -> None:
    raise AssertionError(f"{constant} is not JSON")


def test_json_is_strict_for_an_unbounded_p() -> None:
    result = run_cli("derive", "cayley_gibbs_rodrigues", "--json")
    assert result.returncode == 0, result.stderr
    data = json.loads(result.stdout, parse_constant=_no_non_finite)
    assert data["validity"]["p_max_float"] == "inf"


def test_generated_derivations_are_strict_json() -> None:
    """One derivation per generated NumPy module (an empty or missing folder fails), each strict JSON."""
    generated = Path(__file__).resolve().parent.parent / "generated"
    paths = sorted((generated / "derivations").glob("*.json"))
    assert [p.stem for p in paths] == sorted(p.stem for p in (generated / "numpy").glob("*.py"))
    assert len(paths) >= 7
    for path in paths:
        data = json.loads(path.read_text(encoding="utf-8"), parse_constant=_no_non_finite)
        assert isinstance(data, dict) and data, path.name


def test_strict_json_replaces_every_non_finite_number() -> None:
    data = {"a": [float("inf"), -float("inf"), float("nan"), 1.5], "b": (2, {"c": float("inf")})}
    assert strict(data) == {"a": ["inf", "-inf", None, 1.5], "b": [2, {"c": "inf"}]}
    assert "Infinity" not in dumps(data) and "NaN" not in dumps(data)


@pytest.mark.parametrize(("typo", "suggestion"), [("wiener_milenkovich", "wiener_milenkovic"),
                                                  ("rotation_vectr", "rotation_vector"),
                                                  ("sine_4", "sine_m4"), ("tangentm3", "tangent_m3")])
def test_registry_typos_get_a_suggestion_and_the_list(typo: str, suggestion: str) -> None:
    result = run_cli("derive", typo)
    assert result.returncode == 2
    line = result.stderr.strip()
    assert f"did you mean {suggestion}" in line and "registry names:" in line and "det_h_one" in line


@pytest.mark.parametrize(("expression", "suggestion"), [("sinn(phi)", "sin"), ("2*ph", "phi"),
                                                        ("phi + atna(phi)", "atan")])
def test_expression_typos_get_a_suggestion(expression: str, suggestion: str) -> None:
    result = run_cli("derive", expression)
    assert result.returncode == 2 and f"did you mean {suggestion}?" in result.stderr


def test_normalize_reports_the_kappa_it_divided_out() -> None:
    text = run_cli("derive", "tan(phi/4)", "--normalize").stdout
    assert "kappa 1/4 of the input" in text
    data = json.loads(run_cli("derive", "tan(phi/4)", "--normalize", "--json").stdout)
    assert data["kappa"] == "1" and data["original_kappa"] == "1/4" and data["normalized"] is True


def test_progress_is_silent_when_stderr_is_not_a_terminal(tmp_path: Path) -> None:
    result = run_cli("derive", "wiener_milenkovic", "--emit", "numpy", "--out", str(tmp_path))
    assert result.returncode == 0 and result.stderr == ""


def _run_on_a_terminal(*args: str, timeout: float = 120) -> tuple[int, str]:
    """Run symrot with stderr (and stdout) on a pseudo-terminal; return (exit status, output)."""
    leader, follower = pty.openpty()
    fcntl.ioctl(follower, termios.TIOCSWINSZ, struct.pack("HHHH", 24, 100, 0, 0))  # a 100x24 terminal
    process = subprocess.Popen([sys.executable, "-m", "symrot", *args], stdout=follower, stderr=follower,
                               stdin=subprocess.DEVNULL, close_fds=True)
    os.close(follower)
    chunks = []
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        ready, _, _ = select.select([leader], [], [], 0.2)
        if ready:
            try:
                data = os.read(leader, 65536)
            except OSError:  # the child closed the terminal
                break
            if not data:
                break
            chunks.append(data)
        elif process.poll() is not None:
            break
    os.close(leader)
    return process.wait(timeout=10), b"".join(chunks).decode("utf-8", "replace")


def test_progress_is_drawn_on_a_terminal_and_quiet_silences_it(tmp_path: Path) -> None:
    status, output = _run_on_a_terminal("derive", "cayley_gibbs_rodrigues", "--emit", "c",
                                        "--out", str(tmp_path))
    assert status == 0 and "symrot: --emit c" in output and "evaluation plan" in output
    status, output = _run_on_a_terminal("--quiet", "derive", "cayley_gibbs_rodrigues", "--emit", "c",
                                        "--out", str(tmp_path))
    assert status == 0 and "symrot: --emit" not in output and "symrot_cayley_gibbs_rodrigues.h" in output


BENCH = Path(__file__).resolve().parent.parent / "bench"
BENCH_DRIVERS = sorted(path.name for path in BENCH.glob("*.py")
                       if "__main__" in path.read_text(encoding="utf-8"))


@pytest.mark.parametrize("driver", BENCH_DRIVERS)
def test_every_bench_driver_answers_help_without_running(driver: str) -> None:
    """``python bench/X.py --help`` prints a usage and exits 0 at once: before, two drivers ran their
    benchmark (c_derivative_speed.py) or ended in a traceback (hostile_cli.py took "--help" for its
    budget). accuracy_operations.py is part of accuracy.py and says so."""
    result = subprocess.run([sys.executable, str(BENCH / driver), "--help"], capture_output=True, text=True,
                            timeout=120, check=False)
    assert result.returncode == 0, result.stderr[-2000:]
    assert "Traceback" not in result.stderr
    assert result.stdout.startswith("usage: ") or "accuracy.py" in result.stdout, result.stdout[:500]


def test_the_bench_drivers_are_found() -> None:
    """The parametrization above is not empty: a moved bench/ or a changed guard would skip it all."""
    assert len(BENCH_DRIVERS) >= 10 and "accuracy.py" in BENCH_DRIVERS, BENCH_DRIVERS
