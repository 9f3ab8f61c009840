"""``pip install .`` (not editable) gives a working command with the templates inside the wheel."""

from __future__ import annotations

import os
import subprocess
import sys
import venv
import zipfile
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent


@pytest.fixture(scope="module")
def wheel(tmp_path_factory: pytest.TempPathFactory) -> Path:
    out = tmp_path_factory.mktemp("wheel")
    subprocess.run([sys.executable, "-m", "pip", "wheel", "--no-deps", "--no-build-isolation",
                    "-q", "-w", str(out), str(ROOT)], check=True, capture_output=True,
                   timeout=300)
    (built,) = out.glob("symrot-*.whl")
    return built


def test_wheel_ships_the_templates(wheel: Path) -> None:
    names = zipfile.ZipFile(wheel).namelist()
    templates = {Path(root).name for root in (ROOT / "templates").rglob("*.j2")}
    shipped = {Path(n).name for n in names if n.startswith("symrot/templates/")}
    assert "symrot/templates/__init__.py" in names
    assert templates <= shipped


def test_fresh_venv_install_gives_symrot_and_python_m(wheel: Path, tmp_path: Path) -> None:
    # System site packages provide the pinned dependencies offline; pip still resolves them
    # against the wheel's metadata, and symrot itself comes only from the wheel.
    env_dir = tmp_path / "venv"
    venv.create(env_dir, system_site_packages=True, with_pip=True)
    python = env_dir / "bin" / "python"
    clean_env = {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}
    subprocess.run([str(python), "-m", "pip", "install", "-q", "--no-index", "--ignore-installed",
                    "--no-deps", str(wheel)], check=True, capture_output=True, timeout=300,
                   env=clean_env)
    subprocess.run([str(python), "-m", "pip", "check"], check=True, capture_output=True,
                   timeout=120, env=clean_env)
    where = subprocess.run([str(python), "-c", "import symrot, sys; print(symrot.__file__)"],
                           capture_output=True, text=True, check=True, cwd=tmp_path, env=clean_env)
    assert str(env_dir) in where.stdout
    for command in ([str(env_dir / "bin" / "symrot")], [str(python), "-m", "symrot"]):
        result = subprocess.run([*command, "derive", "wiener_milenkovic"], capture_output=True,
                                text=True, timeout=60, cwd=tmp_path, env=clean_env, check=False)
        assert result.returncode == 0, result.stderr
        assert "cos(phi/4)**2" in result.stdout
    templates = subprocess.run(
        [str(python), "-c", "from importlib.resources import files; "
         "print(files('symrot.templates').joinpath('__init__.py').is_file())"],
        capture_output=True, text=True, check=True, cwd=tmp_path, env=clean_env)
    assert templates.stdout.strip() == "True"
