"""The plan cache of ``symrot derive --emit`` (symrot/cli/plan_cache.py).

A plan read back from disk must print exactly the files a computed plan prints; anything unusable
in the cache directory (corrupt, truncated, of another version, written by someone else, for another
p) must be ignored, never loaded and never an error; nothing in it but symrot's own entries is ever
removed. tests/conftest.py turns the cache off for every other test.
"""

from __future__ import annotations

import dataclasses
import importlib.util
import os
import pickle
import random
import stat
from dataclasses import replace
from pathlib import Path
from typing import Any

import numpy as np
import pytest
import sympy as sp

from symrot.api import derive
from symrot.backends.numpy_backend import module_source
from symrot.cli import plan_cache
from symrot.entry import SEED
from symrot.plan.builder import evaluation_plan
from symrot.plan.ir import EvaluationPlan, NewtonAngle
from symrot.plan.serialized import PlanFormatError, decode_plan, encode_plan
from tests.helpers import files
from tests.helpers import run_symrot as run_cli

FAST = "cayley_gibbs_rodrigues"
"""A parameterization whose plan takes about a second."""
ROUND_TRIPS = ("rotation_vector", "euler_rodrigues", "linear", "wiener_milenkovic", "det_h_one", "sine_m4")
"""Closed angles with branches, complements d (euler_rodrigues, linear, sine_m4), BoundedPower
(wiener_milenkovic), a Newton angle with its far start and 50-digit p_max² (det_h_one)."""


@pytest.fixture
def cache(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    folder = tmp_path / "plans-root" / plan_cache.SUBDIRECTORY
    monkeypatch.setenv(plan_cache.DIRECTORY_VARIABLE, str(folder.parent))
    monkeypatch.delenv(plan_cache.DISABLE_VARIABLE, raising=False)
    # the commands' seed, which the cache requires (this process hashes with another: its plans go
    # only into this temporary directory)
    monkeypatch.setenv("PYTHONHASHSEED", SEED)
    return folder


def entries(folder: Path) -> list[Path]:
    return sorted(path for path in folder.iterdir() if plan_cache.ENTRY_PATTERN.fullmatch(path.name))


def write_entry(folder: Path, plan: EvaluationPlan, content: bytes | None = None) -> Path:
    """``content`` (else the entry of ``plan``) at the place of ``plan``'s entry, private."""
    folder.mkdir(mode=0o700, parents=True, exist_ok=True)
    entry = folder / plan_cache.entry_name(plan.p, plan.name)
    entry.write_bytes(content if content is not None
                      else plan_cache.entry_bytes(plan, plan_cache.entry_key(plan.p, plan.name)))
    entry.chmod(0o600)
    return entry


def same_types(a: Any, b: Any) -> bool:
    """``a`` and ``b`` have the same Python types all the way down (what equality does not see:
    1 == 1.0, float == numpy.float64)."""
    if type(a) is not type(b):
        return False
    if dataclasses.is_dataclass(a):
        return all(same_types(getattr(a, f.name), getattr(b, f.name)) for f in dataclasses.fields(a))
    if isinstance(a, dict):
        return list(a) == list(b) and all(same_types(a[k], b[k]) for k in a)
    if isinstance(a, tuple):
        return len(a) == len(b) and all(map(same_types, a, b))
    if isinstance(a, sp.Basic):
        return sp.srepr(a) == sp.srepr(b)
    return True


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
            assert [path.name for path in (tmp_path / "plans").iterdir()] == [plan_cache.SUBDIRECTORY]
            assert len(entries(tmp_path / "plans" / plan_cache.SUBDIRECTORY)) == 1
    assert set(outputs[0]) == {"numpy/cached.py", "c/symrot_cached.h"}
    assert outputs[1] == outputs[0]
    assert outputs[2] == outputs[0]


def test_the_second_request_reads_the_plan_from_disk(cache: Path) -> None:
    derivation = derive(FAST).derivation
    plan, from_disk = plan_cache.cached_plan(derivation, "first")
    assert not from_disk and len(entries(cache)) == 1 == len(list(cache.iterdir()))
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


@pytest.mark.parametrize("name", ROUND_TRIPS)
def test_a_decoded_plan_equals_the_plan_and_prints_the_same_module(name: str) -> None:
    plan = evaluation_plan(derive(name).derivation, name)
    payload = encode_plan(plan)
    decoded = decode_plan(payload)
    assert decoded == plan and same_types(decoded, plan)
    assert module_source(decoded) == module_source(plan)
    assert encode_plan(decoded) == payload
    assert set(decoded.precisions) == {"float64", "float32"}
    if name == "det_h_one":
        assert all(isinstance(precision.angle, NewtonAngle) for precision in plan.precisions.values())
    if name == "euler_rodrigues":
        assert plan.complement is not None


class Marker:
    """Unpickling this creates a directory: proof that a pickle was loaded."""

    def __init__(self, path: str) -> None:
        self.path = path

    def __reduce__(self) -> tuple[object, tuple[str]]:
        return (os.mkdir, (self.path,))


def test_a_pickle_in_an_entry_is_never_loaded(cache: Path, tmp_path: Path) -> None:
    plan = evaluation_plan(derive(FAST).derivation, "pickled")
    marker = tmp_path / "loaded"
    write_entry(cache, plan, pickle.dumps(Marker(str(marker))))
    assert plan_cache.load(plan.p, "pickled") is None
    assert not marker.exists()
    with pytest.raises(ValueError):
        decode_plan(pickle.dumps(plan))


@pytest.mark.skipif(not hasattr(os, "getuid"), reason="POSIX permissions")
@pytest.mark.parametrize("writable", ["file", "directory"])
def test_a_file_that_others_may_write_is_never_loaded(cache: Path, writable: str) -> None:
    plan = evaluation_plan(derive(FAST).derivation, "foreign")
    entry = write_entry(cache, plan)
    (entry if writable == "file" else cache).chmod(0o666 if writable == "file" else 0o777)
    assert plan_cache.load(plan.p, "foreign") is None
    entry.chmod(0o600)
    cache.chmod(0o700)
    assert plan_cache.load(plan.p, "foreign") == plan


def test_truncated_skewed_and_mismatched_entries_are_computed_again(cache: Path) -> None:
    derivation = derive(FAST).derivation
    plan = evaluation_plan(derivation, "mended")
    key = plan_cache.entry_key(plan.p, "mended")
    good = plan_cache.entry_bytes(plan, key)
    lengths = sorted({*range(0, len(good), 37), *range(len(good) - 64, len(good))})
    for length in lengths:
        write_entry(cache, plan, good[:length])
        assert plan_cache.load(plan.p, "mended") is None, length
    another_p = replace(plan, p=sp.Symbol("phi", real=True) * 2)
    header, _, payload = good.partition(b"\n")
    skewed_header = header.replace(b'"version":1', b'"version":2')
    skewed_payload = payload.replace(b'"version":1', b'"version":2')
    skewed = [plan_cache.entry_bytes(another_p, key),  # another p's plan under this key
              plan_cache.entry_bytes(plan, "0" * 64),  # the entry of another key
              skewed_header + b"\n" + payload,  # another entry version
              plan_cache.canonical_json({**plan_cache.json.loads(header), "sha256":
                                         plan_cache.hashlib.sha256(skewed_payload[:-1]).hexdigest()})
              + b"\n" + skewed_payload]  # another payload version, with its right checksum
    for content in skewed:
        write_entry(cache, plan, content)
        assert plan_cache.load(plan.p, "mended") is None
    again, from_disk = plan_cache.cached_plan(derivation, "mended")
    assert not from_disk and again == plan
    assert (cache / plan_cache.entry_name(plan.p, "mended")).read_bytes() == good  # written anew
    assert plan_cache.load(plan.p, "mended") == plan
    with pytest.raises(PlanFormatError):
        decode_plan(skewed_payload[:-1])


def test_every_single_bit_flip_of_an_entry_is_a_miss(cache: Path) -> None:
    """A bit flipped at every offset of a small entry, and 2000 sampled single-bit flips plus 500
    random byte values (seed 55) in a Newton plan's: each is a miss or the same plan, never another
    plan or an error."""
    outcomes = {"miss": 0, "same plan": 0}
    plans = [evaluation_plan(derive(FAST).derivation, "flipped"),
             evaluation_plan(derive("det_h_one").derivation, "flipped")]
    generator = random.Random(55)
    for index, plan in enumerate(plans):
        good = plan_cache.entry_bytes(plan, plan_cache.entry_key(plan.p, plan.name))
        if index == 0:
            changes = [(offset, good[offset] ^ (1 << offset % 8)) for offset in range(len(good))]
        else:
            changes = []
            while len(changes) < 2000:  # single-bit flips, then 500 random byte values
                offset, bit = generator.randrange(len(good)), generator.randrange(8)
                changes.append((offset, good[offset] ^ (1 << bit)))
            while len(changes) < 2500:
                offset, value = generator.randrange(len(good)), generator.randrange(256)
                if value != good[offset]:
                    changes.append((offset, value))
        for offset, value in changes:
            write_entry(cache, plan, good[:offset] + bytes([value]) + good[offset + 1:])
            loaded = plan_cache.load(plan.p, plan.name)
            assert loaded is None or loaded == plan, (plan.name, offset, value)
            outcomes["miss" if loaded is None else "same plan"] += 1
    assert outcomes["miss"] > 2000
    assert sum(outcomes.values()) == len(plan_cache.entry_bytes(plans[0], "0" * 64)) + 2500


def test_pruning_removes_only_symrots_entries(cache: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """The user's own files (300 *.pickle, other JSON, names that only resemble entries) stay, in
    $SYMROT_CACHE_DIR and in symrot's subdirectory; only the oldest entries beyond KEPT go."""
    plan = evaluation_plan(derive(FAST).derivation, "kept")
    root = cache.parent
    cache.mkdir(mode=0o700, parents=True)
    own = [root / f"user-{index}.pickle" for index in range(300)]
    own += [cache / name for name in ("user.pickle", "notes.json", f"symrot-plan-{'A' * 64}.json",
                                      f"symrot-plan-{'0' * 63}.json", f"symrot-plan-{'0' * 64}.json.bak",
                                      f"x-symrot-plan-{'0' * 64}.json", f"{'0' * 64}.pickle")]
    for index, path in enumerate(own):
        path.write_text("the user's")
        os.utime(path, (1000 + index, 1000 + index))
    lookalike_directory = cache / f"symrot-plan-{'1' * 64}.json"
    lookalike_directory.mkdir()
    before = plan_cache.entry_name(plan.p, "kept")
    monkeypatch.setattr(plan_cache, "code_digest", lambda: "another version of symrot")
    assert plan_cache.entry_name(plan.p, "kept") != before
    monkeypatch.setattr(plan_cache, "KEPT", 2)
    for index, name in enumerate(("a", "b", "c")):
        plan_cache.store(replace(plan, name=name))
        entry = cache / plan_cache.entry_name(plan.p, name)
        os.utime(entry, (1_000_000 + index, 1_000_000 + index))
    kept = {path.name for path in entries(cache) if path.is_file()}
    assert kept == {plan_cache.entry_name(plan.p, "b"), plan_cache.entry_name(plan.p, "c")}
    assert all(path.read_text() == "the user's" for path in own)
    assert lookalike_directory.is_dir()
    assert not list(cache.glob(plan_cache.TEMPORARY_PREFIX + "*"))  # no temporary file left behind


def test_a_read_only_cache_is_read_and_not_written(cache: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    derivation = derive(FAST).derivation
    plan = evaluation_plan(derivation, "read-only")
    entry = write_entry(cache, plan)

    def refuse(*_: object, **__: object) -> None:
        raise PermissionError("read-only file system")

    monkeypatch.setattr(plan_cache.os, "utime", refuse)  # what a read-only mount answers
    assert plan_cache.cached_plan(derivation, "read-only") == (plan, True)
    entry.chmod(0o400)
    cache.chmod(0o500)
    try:
        assert plan_cache.load(plan.p, "read-only") == plan
        if hasattr(os, "getuid") and os.getuid() == 0:  # root may write anyway: as if it could not
            monkeypatch.setattr(plan_cache.os, "access", lambda *_: False)
        plan_cache.store(replace(plan, name="another"))
        assert [path.name for path in cache.iterdir()] == [entry.name]
    finally:
        cache.chmod(0o700)
    assert stat.S_IMODE(entry.stat().st_mode) == 0o400


@pytest.mark.parametrize("home", [None, "", "relative", "/"])
def test_without_a_home_there_is_no_cache(cache: Path, monkeypatch: pytest.MonkeyPatch, home: str | None,
                                          tmp_path: Path) -> None:
    monkeypatch.delenv(plan_cache.DIRECTORY_VARIABLE)
    monkeypatch.setenv("XDG_CACHE_HOME", "relative/cache")  # ignored, as the XDG specification says
    monkeypatch.chdir(tmp_path)
    if home is None:
        monkeypatch.delenv("HOME", raising=False)
    else:
        monkeypatch.setenv("HOME", home)
    assert plan_cache.directory() is None
    derivation = derive(FAST).derivation
    assert plan_cache.cached_plan(derivation, "homeless") == (evaluation_plan(derivation, "homeless"), False)
    assert list(tmp_path.iterdir()) == []
    monkeypatch.setenv("HOME", str(tmp_path))
    assert plan_cache.directory() == tmp_path / ".cache" / "symrot" / plan_cache.SUBDIRECTORY
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "xdg"))
    assert plan_cache.directory() == tmp_path / "xdg" / "symrot" / plan_cache.SUBDIRECTORY


def test_a_corrupted_entry_of_phi_prints_the_right_kernel(tmp_path: Path) -> None:
    """The issue's case: one byte of phi's entry changed; the next emit plans again, exit 0."""
    environment = {plan_cache.DIRECTORY_VARIABLE: str(tmp_path / "plans"), plan_cache.DISABLE_VARIABLE: ""}
    folder = tmp_path / "plans" / plan_cache.SUBDIRECTORY
    for run in range(3):
        out = tmp_path / f"out{run}"
        result = run_cli("derive", "phi", "--emit", "numpy", "--out", str(out), environment=environment)
        assert result.returncode == 0, result.stderr
        spec = importlib.util.spec_from_file_location(f"phi_{run}", out / "rotation_vector.py")
        assert spec is not None and spec.loader is not None
        module = importlib.util.module_from_spec(spec)
        spec.loader.exec_module(module)
        assert np.isclose(module.tangent([[0.3, -0.2, 0.5]])[0, 0, 0], 0.95257673, rtol=1e-7, atol=0)
        (entry,) = entries(folder)
        if run == 0:
            good = entry.read_bytes()
        assert entry.read_bytes() == good  # computed again and rewritten after each corruption
        offset = len(good) * (run + 1) // 4  # in the payload
        entry.write_bytes(good[:offset] + bytes([good[offset] ^ 0x10]) + good[offset + 1:])


def test_a_plan_that_cannot_be_written_is_not_an_error(cache: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    plan = evaluation_plan(derive(FAST).derivation, "unwritable")
    assert plan_cache.load(plan.p, "unwritable") is None
    with pytest.raises(PlanFormatError):
        encode_plan(replace(plan, p=sp.Symbol("y")))  # not a symbol of the IR
    plan_cache.store(replace(plan, p=sp.Symbol("y")))

    def refuse(*_: object, **__: object) -> None:
        raise OSError(28, "No space left on device")

    monkeypatch.setattr(plan_cache.os, "fsync", refuse)
    plan_cache.store(plan)
    assert not list(cache.glob("*"))  # neither an entry nor a temporary file


def test_a_cache_directory_that_cannot_exist_only_costs_the_plan(tmp_path: Path) -> None:
    blocked = tmp_path / "file"
    blocked.write_text("not a directory")
    result = run_cli("derive", FAST, "--emit", "numpy", "--out", str(tmp_path / "out"),
                     environment={plan_cache.DIRECTORY_VARIABLE: str(blocked / "plans"),
                                  plan_cache.DISABLE_VARIABLE: ""})
    assert result.returncode == 0, result.stderr
    assert (tmp_path / "out" / f"{FAST}.py").is_file()
