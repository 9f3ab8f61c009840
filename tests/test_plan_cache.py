"""The plan cache of ``symrot derive --emit`` (symrot/cli/plan_cache.py).

A plan read back from disk must print exactly the files a computed plan prints; anything unusable
in the cache directory (corrupt, written by someone else, for another p) must be ignored, never
loaded and never an error. tests/conftest.py turns the cache off for every other test.
"""

from __future__ import annotations

import os
import pickle
from dataclasses import replace
from pathlib import Path

import pytest
import sympy as sp

from symrot.api import derive
from symrot.cli import plan_cache
from symrot.entry import SEED
from symrot.plan import evaluation_plan
from tests.helpers import files
from tests.helpers import run_symrot as run_cli

FAST = "cayley_gibbs_rodrigues"
"""A parameterization whose plan takes about a second."""


@pytest.fixture
def cache(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    folder = tmp_path / "plans"
    monkeypatch.setenv(plan_cache.DIRECTORY_VARIABLE, str(folder))
    monkeypatch.delenv(plan_cache.DISABLE_VARIABLE, raising=False)
    # the commands' seed, which the cache requires (this process hashes with another: its plans go
    # only into this temporary directory)
    monkeypatch.setenv("PYTHONHASHSEED", SEED)
    return folder


def test_the_cache_requires_the_seed_the_commands_run_with() -> None:
    assert plan_cache.COMMANDS_HASH_SEED == SEED


def test_a_plan_read_back_prints_the_same_files_as_a_computed_one(tmp_path: Path) -> None:
    """Three CLI runs of --emit numpy,c: the first computes and stores the plan, the second reads it
    (its files must equal the first's), the third computes it with --no-cache (the same again)."""
    environment = {plan_cache.DIRECTORY_VARIABLE: str(tmp_path / "plans"), plan_cache.DISABLE_VARIABLE: ""}
    outputs = []
    for run, extra in enumerate(([], [], ["--no-cache"])):
        out = tmp_path / f"out{run}"
        result = run_cli("derive", "rotation_vector", "--emit", "numpy,c", "--name", "cached",
                         "--out", str(out), *extra, environment=environment)
        assert result.returncode == 0, result.stderr
        outputs.append(files(out))
        if run == 0:
            assert len(list((tmp_path / "plans").glob("*.pickle"))) == 1
    assert set(outputs[0]) == {"numpy/cached.py", "c/symrot_cached.h"}
    assert outputs[1] == outputs[0]
    assert outputs[2] == outputs[0]


def test_the_second_request_reads_the_plan_from_disk(cache: Path) -> None:
    derivation = derive(FAST).derivation
    plan, from_disk = plan_cache.cached_plan(derivation, "first")
    assert not from_disk and len(list(cache.glob("*.pickle"))) == 1
    again, from_disk = plan_cache.cached_plan(derivation, "first")
    assert from_disk and again == plan
    if hasattr(os, "getuid"):
        assert cache.stat().st_mode & 0o777 == 0o700


@pytest.mark.parametrize("variable, value", [(plan_cache.DISABLE_VARIABLE, "1"), ("PYTHONHASHSEED", "7")])
def test_the_cache_is_off_when_asked_or_with_another_hash_seed(cache: Path, monkeypatch: pytest.MonkeyPatch,
                                                               variable: str, value: str) -> None:
    plan = evaluation_plan(derive(FAST).derivation, "off")
    monkeypatch.setenv(variable, value)
    plan_cache.store(plan)
    assert not cache.exists()
    assert plan_cache.cached_plan(derive(FAST).derivation, "off") == (plan, False)
    assert not cache.exists()


class Marker:
    """Unpickling this creates a directory: proof that a pickle was loaded."""

    def __init__(self, path: str) -> None:
        self.path = path

    def __reduce__(self) -> tuple[object, tuple[str]]:
        return (os.mkdir, (self.path,))


@pytest.mark.skipif(not hasattr(os, "getuid"), reason="POSIX permissions")
@pytest.mark.parametrize("writable", ["file", "directory"])
def test_a_file_that_others_may_write_is_never_loaded(cache: Path, tmp_path: Path, writable: str) -> None:
    p = derive(FAST).derivation.p
    cache.mkdir(mode=0o700)
    entry = cache / plan_cache.entry_name(p, "foreign")
    marker = tmp_path / "loaded"
    entry.write_bytes(pickle.dumps(Marker(str(marker))))
    entry.chmod(0o600)
    (entry if writable == "file" else cache).chmod(0o666 if writable == "file" else 0o777)
    assert plan_cache.load(p, "foreign") is None
    assert not marker.exists()
    entry.chmod(0o600)
    cache.chmod(0o700)
    assert plan_cache.load(p, "foreign") is None  # private now, so loaded: not a plan, ignored
    assert marker.exists()


def test_corrupt_and_mismatched_entries_are_computed_again(cache: Path) -> None:
    derivation = derive(FAST).derivation
    plan = evaluation_plan(derivation, "mended")
    cache.mkdir(mode=0o700)
    entry = cache / plan_cache.entry_name(plan.p, "mended")
    entry.write_bytes(pickle.dumps(plan)[:100])  # truncated
    entry.chmod(0o600)
    assert plan_cache.load(plan.p, "mended") is None
    entry.write_bytes(pickle.dumps(replace(plan, p=sp.Symbol("phi") * 2)))  # another p's plan
    assert plan_cache.load(plan.p, "mended") is None
    again, from_disk = plan_cache.cached_plan(derivation, "mended")
    assert not from_disk and again == plan
    assert plan_cache.load(plan.p, "mended") == plan  # the entry was written anew


def test_other_code_uses_other_entries_and_the_oldest_go(cache: Path,
                                                          monkeypatch: pytest.MonkeyPatch) -> None:
    plan = evaluation_plan(derive(FAST).derivation, "kept")
    before = plan_cache.entry_name(plan.p, "kept")
    monkeypatch.setattr(plan_cache, "code_digest", lambda: "another version of symrot")
    assert plan_cache.entry_name(plan.p, "kept") != before
    monkeypatch.setattr(plan_cache, "KEPT", 2)
    for index, name in enumerate(("a", "b", "c")):
        plan_cache.store(replace(plan, name=name))
        entry = cache / plan_cache.entry_name(plan.p, name)
        os.utime(entry, (1_000_000 + index, 1_000_000 + index))
    kept = {path.name for path in cache.glob("*.pickle")}
    assert kept == {plan_cache.entry_name(plan.p, "b"), plan_cache.entry_name(plan.p, "c")}
    assert not list(cache.glob(".plan-*"))  # no temporary file left behind


def test_a_read_only_cache_directory_only_costs_the_plan(tmp_path: Path) -> None:
    blocked = tmp_path / "file"
    blocked.write_text("not a directory")
    result = run_cli("derive", FAST, "--emit", "numpy", "--out", str(tmp_path / "out"),
                     environment={plan_cache.DIRECTORY_VARIABLE: str(blocked / "plans"),
                                  plan_cache.DISABLE_VARIABLE: ""})
    assert result.returncode == 0, result.stderr
    assert (tmp_path / "out" / f"{FAST}.py").is_file()


def test_a_plan_that_cannot_be_written_is_not_an_error(cache: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    plan = evaluation_plan(derive(FAST).derivation, "unwritable")

    def refuse(*_: object, **__: object) -> None:
        raise pickle.PicklingError("cannot pickle this")

    monkeypatch.setattr(plan_cache.pickle, "dump", refuse)
    plan_cache.store(plan)
    assert not list(cache.glob("*"))  # neither an entry nor a temporary file
