"""``symrot derive EXPR --emit A,B,…``: several backends from one evaluation plan."""

from __future__ import annotations

from pathlib import Path

import pytest

from tests.helpers import files
from tests.helpers import run_symrot as run_cli

FAST = "cayley_gibbs_rodrigues"
"""A parameterization whose plan takes about a second."""


def test_several_backends_share_one_plan_and_write_into_their_own_directories(tmp_path: Path) -> None:
    result = run_cli("derive", FAST, "--emit", "numpy,jax,c,numpy", "--out", str(tmp_path / "all"))
    assert result.returncode == 0, result.stderr
    assert set(files(tmp_path / "all")) == {f"numpy/{FAST}.py", f"jax/{FAST}.py", f"c/symrot_{FAST}.h"}
    single = run_cli("derive", FAST, "--emit", "jax", "--out", str(tmp_path / "one"))
    assert single.returncode == 0, single.stderr
    assert files(tmp_path / "one")[f"{FAST}.py"] == files(tmp_path / "all")[f"jax/{FAST}.py"]


def test_all_is_every_backend(tmp_path: Path) -> None:
    result = run_cli("derive", FAST, "--emit", "all", "--out", str(tmp_path))
    assert result.returncode == 0, result.stderr
    assert set(files(tmp_path)) == {f"numpy/{FAST}.py", f"jax/{FAST}.py", f"torch/{FAST}.py",
                                    f"c/symrot_{FAST}.h"}


@pytest.mark.parametrize("emit", ["numpy,", "numpy,fortran", ",", "numpy, ", "all,numpy"])
def test_a_bad_backend_list_is_one_line_and_writes_nothing(tmp_path: Path, emit: str) -> None:
    result = run_cli("derive", FAST, "--emit", emit, "--out", str(tmp_path / "out"))
    assert result.returncode == 2
    assert len(result.stderr.strip().splitlines()) == 1 and "Traceback" not in result.stderr
    assert not (tmp_path / "out").exists()
