"""A new user's first hour (issue 15): the built **wheel**, installed non-editable into a virtual
environment that has only symrot's runtime dependencies, runs every subcommand from an empty
directory, and the README's C and NumPy examples work against what it emits."""

from __future__ import annotations

import json
import os
import re
import shutil
import subprocess
import sys
import tomllib
import venv
import zipfile
from pathlib import Path

import pytest
from filelock import FileLock

ROOT = Path(__file__).resolve().parent.parent
README = (ROOT / "README.md").read_text(encoding="utf-8")


def _shared_dir(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A directory every pytest-xdist worker of this run sees (the parent of the workers' base
    temporary directories), so that the wheel and its environment are built once per run, not once
    per worker that runs one of these tests (about 30 s each)."""
    base = tmp_path_factory.getbasetemp()
    return base.parent if os.environ.get("PYTEST_XDIST_WORKER") else base


@pytest.fixture(scope="module")
def wheel(tmp_path_factory: pytest.TempPathFactory) -> Path:
    out = _shared_dir(tmp_path_factory) / "symrot_wheel"
    with FileLock(str(out) + ".lock"):
        if not list(out.glob("symrot-*.whl")):
            out.mkdir(exist_ok=True)
            subprocess.run([sys.executable, "-m", "pip", "wheel", "--no-deps", "--no-build-isolation",
                            "-q", "-w", str(out), str(ROOT)], check=True, capture_output=True,
                           timeout=300)
    (built,) = out.glob("symrot-*.whl")
    return built


def test_wheel_ships_every_package_and_the_templates(wheel: Path) -> None:
    names = set(zipfile.ZipFile(wheel).namelist())
    sources = {str(p.relative_to(ROOT)) for p in (ROOT / "symrot").rglob("*.py")}
    assert sources <= names, f"missing from the wheel: {sorted(sources - names)}"
    templates = {str(p.relative_to(ROOT)) for p in (ROOT / "symrot" / "backends" / "templates").rglob("*.j2")}
    assert templates and templates <= names
    assert any(n.endswith(".dist-info/licenses/LICENSE") or n.endswith(".dist-info/LICENSE") for n in names)


def _runtime_requirements() -> list[str]:
    return list(tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]["dependencies"])


@pytest.fixture(scope="module")
def runtime_env(wheel: Path, tmp_path_factory: pytest.TempPathFactory) -> dict[str, Path]:
    """A venv with the wheel and its runtime dependencies only (no system site packages, no dev
    extras); pip resolves the dependencies from the wheel's metadata (pip's cache makes it quick).
    Built once per run and shared by the xdist workers (:func:`_shared_dir`); ``ready`` marks a
    complete environment, so a worker never uses one another worker is still installing."""
    root = _shared_dir(tmp_path_factory) / "symrot_runtime"
    env_dir, ready = root / "venv", root / "ready"
    with FileLock(str(root) + ".lock"):
        if not ready.exists():
            shutil.rmtree(root, ignore_errors=True)  # a build that failed half-way
            root.mkdir()
            venv.create(env_dir, system_site_packages=False, with_pip=True)
            result = subprocess.run([str(env_dir / "bin" / "python"), "-m", "pip", "install", "-q",
                                     "--disable-pip-version-check", str(wheel)], capture_output=True,
                                    text=True, timeout=900, env=_clean_env(), check=False)
            assert result.returncode == 0, result.stderr[-3000:]
            ready.touch()
    return {"python": env_dir / "bin" / "python", "symrot": env_dir / "bin" / "symrot", "root": env_dir}


def _clean_env() -> dict[str, str]:
    return {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "VIRTUAL_ENV")}


def _run(command: list[str], cwd: Path, timeout: float = 180,
         extra: dict[str, str] | None = None) -> subprocess.CompletedProcess[str]:
    return subprocess.run(command, capture_output=True, text=True, timeout=timeout, cwd=cwd,
                          env={**_clean_env(), **(extra or {})}, check=False)


def test_runtime_env_has_only_the_runtime_dependencies(runtime_env: dict[str, Path], tmp_path: Path) -> None:
    python = str(runtime_env["python"])
    assert _run([python, "-m", "pip", "check"], tmp_path).returncode == 0
    where = _run([python, "-c", "import symrot; print(symrot.__file__)"], tmp_path)
    assert str(runtime_env["root"]) in where.stdout  # from the wheel, not the source tree
    for dev_only in ("pytest", "hypothesis", "scipy"):
        assert _run([python, "-c", f"import {dev_only}"], tmp_path).returncode != 0
    names = {re.split(r"[<>=!~ \[]", r)[0].lower() for r in _runtime_requirements()}
    assert {"sympy", "numpy", "mpmath", "jinja2", "matplotlib", "tqdm"} <= names


SUBCOMMANDS = [
    ["--version"],
    [],
    ["derive", "wiener_milenkovic"],
    ["derive", "cbrt(6*(phi-sin(phi)))", "--json"],
    ["derive", "tan(phi/4)", "--normalize"],
    ["derive", "rotation_vector", "--emit", "c", "--out", "include"],
    ["derive", "rotation_vector", "--emit", "numpy", "--out", "kernels"],
    ["solve", "det_H = const"],
    ["table", "--out", "paper"],
    ["sheet", "cayley_gibbs_rodrigues", "--standalone", "--out", "paper"],
    ["plot", "--figure", "3", "--format", "png", "--out", "figures"],
    ["audit", "--only", "14,22"],
]


PYTHON_M_CHECKED = ([], ["--version"], ["derive", "wiener_milenkovic"])


@pytest.mark.slow
def test_every_subcommand_runs_from_an_empty_directory(runtime_env: dict[str, Path], tmp_path: Path) -> None:
    for arguments in SUBCOMMANDS:
        for command in ([str(runtime_env["symrot"])], [str(runtime_env["python"]), "-m", "symrot"]):
            if command[0].endswith("python") and arguments not in PYTHON_M_CHECKED:
                continue  # python -m symrot is the same entry point: checked on three cheap commands
            result = _run([*command, *arguments], tmp_path)
            assert result.returncode == 0, (arguments, result.stderr[-2000:])
            assert "Traceback" not in result.stderr
            if arguments == []:
                assert "usage: symrot" in result.stdout and "derive" in result.stdout
            if "--json" in arguments:
                json.loads(result.stdout, parse_constant=_reject_non_finite)
    assert (tmp_path / "include" / "symrot_rotation_vector.h").is_file()
    assert (tmp_path / "kernels" / "rotation_vector.py").is_file()
    assert (tmp_path / "paper" / "table.tex").is_file()
    assert (tmp_path / "figures" / "figure3.png").is_file()


def _reject_non_finite(constant: str) -> None:
    raise AssertionError(f"non-standard JSON constant {constant}")


def _readme_block(language: str, containing: str) -> str:
    blocks = re.findall(rf"```{language}\n(.*?)```", README, re.S)
    match = [block for block in blocks if containing in block]
    assert match, f"README has no {language} example with {containing!r}"
    return match[0]


@pytest.mark.slow
def test_readme_c_and_python_examples_work(runtime_env: dict[str, Path], tmp_path: Path) -> None:
    symrot = str(runtime_env["symrot"])
    assert _run([symrot, "derive", "wiener_milenkovic", "--emit", "c", "--out", "include"],
                tmp_path).returncode == 0
    assert _run([symrot, "derive", "wiener_milenkovic", "--emit", "numpy", "--out", "kernels"],
                tmp_path).returncode == 0
    compile_line = next(line for line in README.splitlines() if line.startswith("cc -std=c99"))
    c_example = _readme_block("c", "symrot_wiener_milenkovic_rotation_matrix")
    (tmp_path / "example.c").write_text(c_example, encoding="utf-8")
    compiler = shutil.which("cc") or shutil.which("gcc")
    assert compiler, "a C compiler is needed (make setup installs gcc)"
    built = subprocess.run(compile_line.split("&&")[0], shell=True, cwd=tmp_path, capture_output=True,
                           text=True, timeout=120, check=False)
    assert built.returncode == 0, built.stderr
    ran = _run([str(tmp_path / "example")], tmp_path)
    assert ran.returncode == 0 and "phi = 0.37308011578559" in ran.stdout
    python_example = _readme_block("python", "symrot.kernels(")  # the wheel's symrot, run elsewhere
    (tmp_path / "example.py").write_text(python_example, encoding="utf-8")
    python_run = _run([str(runtime_env["python"]), "example.py"], tmp_path,
                      extra={"SYMROT_CACHE_DIR": str(tmp_path / "cache"), "SYMROT_NO_CACHE": ""})
    assert python_run.returncode == 0, python_run.stderr
    assert python_run.stdout.startswith("numpy [0.37308012 0.        ]"), python_run.stdout
    assert list((tmp_path / "cache" / "symrot-kernels-v1").glob("*/wiener_milenkovic.py"))
