"""Issue 57: generated kernels from Python in one call, ``symrot.kernels`` and ``symrot.emit``."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import symrot
from symrot import kernels_api
from symrot.core.errors import SymrotError

GENERATED = Path(__file__).resolve().parent.parent / "generated"


@pytest.fixture
def cache(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    """A cache folder of this test only, and no module kept from an earlier test."""
    monkeypatch.setenv("SYMROT_CACHE_DIR", str(tmp_path / "cache"))
    monkeypatch.delenv("SYMROT_NO_CACHE", raising=False)
    monkeypatch.setattr(kernels_api, "_LOADED", {})
    return tmp_path / "cache" / kernels_api.SUBDIRECTORY


def _no_child(*args: object, **kwargs: object) -> None:
    raise AssertionError("a child process was started")


def test_kernels_is_the_command_lines_module_and_a_second_call_is_free(
        cache: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    module = symrot.kernels("wiener_milenkovic")
    assert module.backend == "numpy"
    (kept,) = cache.glob("*/wiener_milenkovic.py")
    assert kept.read_bytes() == (GENERATED / "numpy" / "wiener_milenkovic.py").read_bytes()
    p = np.array([[0.3, -1.2, 2.0], [1e-9, 0.0, 0.0]])
    expected = np.array([[1.0, 0, 0], [0, 1, 0], [0, 0, 1]])  # p = 0: the identity
    assert np.array_equal(module.rotation_matrix(np.zeros(3)), expected)
    assert module.rotation_matrix(p).shape == (2, 3, 3)
    monkeypatch.setattr(subprocess, "run", _no_child)
    assert symrot.kernels("wiener_milenkovic") is module


def test_a_new_process_imports_the_kept_module_without_a_child(cache: Path) -> None:
    symrot.kernels("rotation_vector")
    script = ("import subprocess, symrot\n"
              "def refuse(*a, **k): raise SystemExit('a child process was started')\n"
              "subprocess.run = refuse\n"
              "m = symrot.kernels('rotation_vector')\n"
              "print(m.backend, m.angle([0.0, 0.0, 0.5]))\n")
    environment = {**os.environ, "SYMROT_CACHE_DIR": str(cache.parent)}
    result = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, timeout=120,
                            env=environment, check=False)
    assert result.returncode == 0, result.stderr
    assert result.stdout.split() == ["numpy", "0.5"]


@pytest.mark.parametrize("damage", ["edit", "truncate", "checksum", "group-writable"])
def test_a_kept_module_that_does_not_check_is_made_again(cache: Path, damage: str) -> None:
    symrot.kernels("rotation_vector")
    (kept,) = cache.glob("*/rotation_vector.py")
    good = kept.read_bytes()
    if damage == "edit":
        kept.write_bytes(good.replace(b"def rotation_matrix", b"def rotation_matrix_", 1))
    elif damage == "truncate":
        kept.write_bytes(good[: len(good) // 2])
    elif damage == "checksum":
        (kept.parent / "rotation_vector.py.sha256").write_text("0" * 64 + "\n")
    else:
        kept.chmod(0o664)
    kernels_api._LOADED.clear()
    module = symrot.kernels("rotation_vector")
    assert kept.read_bytes() == good
    assert np.allclose(module.rotation_matrix([0.0, 0.0, np.pi / 2]), [[0, -1, 0], [1, 0, 0], [0, 0, 1]])


def test_bad_input_raises_one_line(cache: Path) -> None:
    with pytest.raises(SymrotError, match="choose from numpy, jax, torch"):
        symrot.kernels("rotation_vector", backend="fortran")
    for expression in ("__import__('os').system('true')", "sin(phi", "phi**2"):
        with pytest.raises(SymrotError) as error:
            symrot.kernels(expression)
        assert "\n" not in str(error.value) and "Traceback" not in str(error.value)
    assert not list(cache.glob("*/*.py"))
    with pytest.raises(SymrotError, match="--name"):
        symrot.kernels("rotation_vector", name="numpy")


def test_emit_writes_the_files_of_several_backends_all_or_none(tmp_path: Path) -> None:
    written = symrot.emit("4*tan(phi/4)", ["c", "numpy"], tmp_path / "out", name="wm")
    paths = sorted(p.relative_to(tmp_path / "out").as_posix() for p in written)
    assert paths == ["c/symrot_wm.h", "numpy/wm.py"]
    assert all(p.is_file() for p in written)
    (tmp_path / "kept").mkdir()
    (tmp_path / "kept" / "wm.py").write_text("mine")
    with pytest.raises(SymrotError):
        symrot.emit("4*tan(phi/4) + ", "numpy", tmp_path / "kept", name="wm")
    assert (tmp_path / "kept" / "wm.py").read_text() == "mine"
