"""Output files survive a full disk, signals and links; bad options end before any work (issue 55).

Every output is written atomically (:mod:`symrot.core.atomic`); an emit of several backends replaces
all of its files or none; SIGINT (130) and SIGTERM (143) leave no temporary file or scratch
directory; SIGKILL leaves the previous files whole and temporary files that the next run removes.
A time limit here only catches a hang.
"""

from __future__ import annotations

import errno
import os
import signal
import subprocess
import sys
import textwrap
import time
from pathlib import Path
from typing import Any

import pytest

import symrot.cli.derive as derive_command
from symrot.cli import MAX_TIMEOUT, main
from symrot.cli.output import write_file, write_files
from symrot.core import atomic
from symrot.core.errors import SymrotError

FAST = "cayley_gibbs_rodrigues"
"""A parameterization whose plan takes about a second."""
HANG = 240.0
"""Seconds after which a subprocess counts as hung (not a speed bound)."""
OLD = "old = 'whole'\n" * 1000


@pytest.fixture(autouse=True)
def shell_sigint() -> Any:
    """Each test starts with SIGINT as a shell gives it: Python's default handler, not blocked (another
    test in the same pytest-xdist worker may leave it otherwise; the children inherit both)."""
    handler = signal.signal(signal.SIGINT, signal.default_int_handler)
    mask = signal.pthread_sigmask(signal.SIG_UNBLOCK, [signal.SIGINT])
    yield
    signal.pthread_sigmask(signal.SIG_SETMASK, mask)
    signal.signal(signal.SIGINT, handler)


def leftovers(directory: Path) -> list[str]:
    """Temporary files of symrot in ``directory`` (recursively)."""
    return sorted(str(p) for p in directory.rglob("*") if p.name.endswith((atomic.PARTIAL, atomic.BACKUP)))


def full_disk(monkeypatch: pytest.MonkeyPatch, free: int) -> None:
    """Every write through ``os.write`` or ``Path.write_text/bytes`` stops with ENOSPC after
    ``free`` bytes (what a nearly full disk does)."""
    left = [free]

    def write(descriptor: int, data: Any) -> int:
        if left[0] <= 0:
            raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))
        count = min(len(data), left[0])
        left[0] -= count
        return real_write(descriptor, bytes(data[:count]))

    def write_text(self: Path, text: str, *args: Any, **kwargs: Any) -> int:
        return write_bytes(self, text.encode("utf-8"))

    def write_bytes(self: Path, data: bytes) -> int:
        with open(self, "wb") as stream:
            stream.write(data[:left[0]])
        raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))

    real_write = os.write
    monkeypatch.setattr(os, "write", write)
    monkeypatch.setattr(Path, "write_text", write_text)
    monkeypatch.setattr(Path, "write_bytes", write_bytes)


def test_a_full_disk_leaves_the_previous_file_whole(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    target = tmp_path / "rotation.py"
    target.write_text(OLD)
    full_disk(monkeypatch, 4096)
    with pytest.raises(SymrotError, match="No space left on device"):
        write_file(tmp_path, "rotation.py", "new = 1\n" * 10_000, announce=False)
    monkeypatch.undo()
    assert target.read_text() == OLD
    assert leftovers(tmp_path) == []


def test_several_files_are_replaced_all_or_none(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """A failure in the second rename (or, before atomic writes, the second write) restores the
    first file and removes the backups and staged files."""
    first, second = tmp_path / "c" / "a.h", tmp_path / "numpy" / "a.py"
    for path in (first, second):
        path.parent.mkdir()
        path.write_text(OLD)
    calls = [0]
    real_replace, real_write_text = os.replace, Path.write_text

    def failing(real: Any) -> Any:
        def call(*args: Any, **kwargs: Any) -> Any:
            calls[0] += 1
            if calls[0] == 2:
                raise OSError(errno.EIO, os.strerror(errno.EIO))
            return real(*args, **kwargs)
        return call

    monkeypatch.setattr(os, "replace", failing(real_replace))
    monkeypatch.setattr(Path, "write_text", failing(real_write_text))
    with pytest.raises(SymrotError, match="Input/output error"):
        write_files(tmp_path, [(first, "new"), (second, "new")], announce=False)
    monkeypatch.undo()
    assert first.read_text() == OLD and second.read_text() == OLD
    assert leftovers(tmp_path) == []


def test_a_new_file_is_removed_again_when_a_later_rename_fails(tmp_path: Path,
                                                               monkeypatch: pytest.MonkeyPatch) -> None:
    calls = [0]
    real_replace = os.replace

    def replace(*args: Any) -> None:
        calls[0] += 1
        if calls[0] == 2:
            raise OSError(errno.EIO, "injected")
        real_replace(*args)

    monkeypatch.setattr(os, "replace", replace)
    with pytest.raises(SymrotError):
        write_files(tmp_path, [(tmp_path / "a", "new"), (tmp_path / "b", "new")], announce=False)
    assert sorted(p.name for p in tmp_path.iterdir()) == []


def test_sigint_during_the_renames_waits_until_all_are_done(tmp_path: Path,
                                                            monkeypatch: pytest.MonkeyPatch) -> None:
    first, second = tmp_path / "a", tmp_path / "b"
    first.write_text(OLD)
    second.write_text(OLD)
    real_replace = os.replace

    def replace(*args: Any) -> None:
        real_replace(*args)
        if os.path.basename(args[1]) == "a":
            os.kill(os.getpid(), signal.SIGINT)
            time.sleep(0.05)

    monkeypatch.setattr(os, "replace", replace)
    with pytest.raises(KeyboardInterrupt):
        write_files(tmp_path, [(first, "new"), (second, "new")], announce=False)
    assert first.read_text() == "new" and second.read_text() == "new"
    assert leftovers(tmp_path) == []


def test_a_link_inside_out_is_not_followed(tmp_path: Path) -> None:
    outside = tmp_path / "outside.py"
    outside.write_text(OLD)
    out = tmp_path / "out"
    out.mkdir()
    (out / "rotation.py").symlink_to(outside)
    with pytest.raises(SymrotError, match="symbolic link"):
        write_file(out, "rotation.py", "new", announce=False)
    (tmp_path / "elsewhere").mkdir()
    (out / "numpy").symlink_to(tmp_path / "elsewhere")
    with pytest.raises(SymrotError, match="outside"):
        write_files(out, [(out / "numpy" / "rotation.py", "new")], announce=False)
    assert outside.read_text() == OLD and list((tmp_path / "elsewhere").iterdir()) == []


def test_out_itself_may_be_a_link(tmp_path: Path) -> None:
    (tmp_path / "real").mkdir()
    (tmp_path / "link").symlink_to(tmp_path / "real")
    write_files(tmp_path / "link", [(tmp_path / "link" / "c" / "a.h", "new")], announce=False)
    assert (tmp_path / "real" / "c" / "a.h").read_text() == "new"


def test_an_emit_through_a_link_exits_two_and_changes_nothing_outside(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    outside = tmp_path / "outside.py"
    outside.write_text(OLD)
    out = tmp_path / "out"
    out.mkdir()
    (out / f"{FAST}.py").symlink_to(outside)
    assert main(["derive", FAST, "--emit", "numpy", "--out", str(out)]) == 2
    assert "symbolic link" in capsys.readouterr().err
    assert outside.read_text() == OLD


def test_an_emit_of_several_backends_keeps_the_old_files_when_the_second_rename_fails(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]) -> None:
    header, module = tmp_path / "c" / f"symrot_{FAST}.h", tmp_path / "numpy" / f"{FAST}.py"
    for path in (header, module):
        path.parent.mkdir()
        path.write_text(OLD)
    calls = [0]
    real_replace, real_write_text = os.replace, Path.write_text

    def replace(*args: Any, **kwargs: Any) -> Any:
        if str(tmp_path) in str(args[-1]):
            calls[0] += 1
            if calls[0] == 2:
                raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))
        return real_replace(*args, **kwargs)

    def write_text(self: Path, *args: Any, **kwargs: Any) -> Any:  # the writes before atomic ones
        if str(tmp_path) in str(self):
            calls[0] += 1
            if calls[0] == 2:
                raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))
        return real_write_text(self, *args, **kwargs)

    monkeypatch.setattr(os, "replace", replace)
    monkeypatch.setattr(Path, "write_text", write_text)
    assert main(["derive", FAST, "--emit", "c,numpy", "--out", str(tmp_path)]) == 2
    monkeypatch.undo()
    assert "No space left" in capsys.readouterr().err
    assert header.read_text() == OLD and module.read_text() == OLD
    assert leftovers(tmp_path) == []


CHILD = textwrap.dedent("""
    import os, sys, time
    from pathlib import Path
    ready = Path(sys.argv[1])

    def stuck(*args, **kwargs):  # a write that hangs half-way (a slow disk)
        ready.write_bytes(b"")
        time.sleep(600)

    if sys.argv[2] == "emit":
        real_write_text = Path.write_text
        def write_text(self, *args, **kwargs):  # before atomic writes: truncated, then stuck
            if str(self).startswith(sys.argv[3]):
                open(self, "w").close()
                stuck()
            return real_write_text(self, *args, **kwargs)
        Path.write_text = write_text
        real_fsync = os.fsync
        def fsync(descriptor):
            where = os.readlink(f"/proc/self/fd/{descriptor}")
            if where.startswith(sys.argv[3]) and ".symrot-probe" not in where:
                stuck()
            real_fsync(descriptor)
        os.fsync = fsync
        from symrot.cli import main
        sys.exit(main(["derive", "%s", "--emit", "c,numpy", "--out", sys.argv[3]]))
    else:
        os.fsync = stuck
        from symrot.cli.output import write_file
        write_file(Path(sys.argv[3]), "a.py", "new", announce=False)
""" % FAST)


def stop_while_writing(tmp_path: Path, mode: str, number: int, group: bool = False,
                       worker: str = "1") -> tuple[int, Path]:
    """Run :data:`CHILD`, send ``number`` once it hangs in a write; (its exit status, out)."""
    out, scratch, ready = tmp_path / "out", tmp_path / "tmp", tmp_path / "ready"
    out.mkdir()
    scratch.mkdir()
    for path in (out / "c" / f"symrot_{FAST}.h", out / "numpy" / f"{FAST}.py", out / "a.py"):
        path.parent.mkdir(exist_ok=True)
        path.write_text(OLD)
    environment = {**os.environ, "TMPDIR": str(scratch), "SYMROT_WORKER": worker, "PYTHONPATH":
                   str(Path(__file__).resolve().parents[1])}
    child = subprocess.Popen([sys.executable, "-c", CHILD, str(ready), mode, str(out)],
                             env=environment, start_new_session=True)
    try:
        deadline = time.monotonic() + HANG
        while not ready.exists() and child.poll() is None and time.monotonic() < deadline:
            time.sleep(0.05)
        assert ready.exists(), "the child never reached its write"
        if group:
            os.killpg(child.pid, number)
        else:
            child.send_signal(number)
        status = child.wait(timeout=HANG)
    finally:
        if child.poll() is None:
            os.killpg(child.pid, signal.SIGKILL)
            child.wait()
    assert list(scratch.iterdir()) == [], "a scratch directory was left"
    return status, out


@pytest.mark.parametrize(("number", "status", "group", "worker"), [
    (signal.SIGTERM, 143, False, "1"), (signal.SIGINT, 130, True, "1"), (signal.SIGTERM, 143, False, "0")])
def test_a_signal_during_an_emit_leaves_the_old_files_and_nothing_else(
        tmp_path: Path, number: int, status: int, group: bool, worker: str) -> None:
    code, out = stop_while_writing(tmp_path, "emit", number, group, worker)
    assert code == status
    assert (out / "c" / f"symrot_{FAST}.h").read_text() == OLD
    assert (out / "numpy" / f"{FAST}.py").read_text() == OLD
    assert leftovers(out) == []


def test_sigkill_during_a_write_leaves_the_old_file_and_the_next_run_cleans_up(tmp_path: Path) -> None:
    code, out = stop_while_writing(tmp_path, "write", signal.SIGKILL)
    assert code == -signal.SIGKILL
    assert (out / "a.py").read_text() == OLD
    assert len(leftovers(out)) == 1
    write_file(out, "a.py", "new", announce=False)
    assert (out / "a.py").read_text() == "new" and leftovers(out) == []


def test_a_killed_emit_leaves_no_scratch_directory_for_long(tmp_path: Path,
                                                            monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("TMPDIR", str(tmp_path))
    monkeypatch.setattr("tempfile.tempdir", None)
    dead = subprocess.run([sys.executable, "-c", "import os; print(os.getpid())"], capture_output=True,
                          text=True, check=True).stdout.strip()
    stale, live = tmp_path / f"symrot-emit-{dead}-abc", tmp_path / f"symrot-emit-{os.getpid()}-abc"
    stale.mkdir()
    live.mkdir()
    derive_command.remove_stale_scratch()
    assert not stale.exists() and live.exists()


@pytest.mark.parametrize("seconds", ["1e10", str(MAX_TIMEOUT * 2), "1e300"])
@pytest.mark.parametrize("worker", ["0", "1"])
def test_a_timeout_past_the_maximum_is_a_usage_error(seconds: str, worker: str,
                                                     monkeypatch: pytest.MonkeyPatch,
                                                     capsys: pytest.CaptureFixture[str]) -> None:
    monkeypatch.setenv("SYMROT_WORKER", worker)
    with pytest.raises(SystemExit) as stopped:
        main(["--timeout", seconds, "derive", "phi"])
    assert stopped.value.code == 2
    assert "maximum" in capsys.readouterr().err


def test_the_maximum_timeout_is_accepted(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["--timeout", f"{MAX_TIMEOUT:g}", "derive", "phi", "--json"]) == 0


@pytest.mark.parametrize("name", [
    "x" * 250, "a" * 65, "numpy", "functools", "math", "os", "sympy", "torch", "jax", "symrot",
    "__main__", "__init__", "class", "None", "a b", "../escape"])
def test_a_bad_name_is_refused_before_any_work(name: str, tmp_path: Path, monkeypatch: pytest.MonkeyPatch,
                                               capsys: pytest.CaptureFixture[str]) -> None:
    monkeypatch.setattr(derive_command, "derive", lambda *a, **k: pytest.fail("derived anyway"))
    assert main(["derive", "phi", "--emit", "numpy", "--name", name, "--out", str(tmp_path)]) == 2
    error = capsys.readouterr().err.strip()
    assert len(error.splitlines()) == 1 and "--name" in error and len(error) < 200
    assert list(tmp_path.iterdir()) == []


def test_a_name_of_64_characters_is_accepted() -> None:
    derive_command.check_name("a" * 64)
    derive_command.check_name("my_rotation")


@pytest.mark.parametrize("where", ["file", "file/sub", "/proc/symrot"])
def test_an_unwritable_out_is_refused_before_any_work(where: str, tmp_path: Path,
                                                      monkeypatch: pytest.MonkeyPatch,
                                                      capsys: pytest.CaptureFixture[str]) -> None:
    (tmp_path / "file").write_text("")
    monkeypatch.setattr(derive_command, "derive", lambda *a, **k: pytest.fail("derived anyway"))
    out = where if where.startswith("/") else str(tmp_path / where)
    assert main(["derive", "phi", "--emit", "numpy", "--out", out]) == 2
    error = capsys.readouterr().err.strip()
    assert len(error.splitlines()) == 1 and "cannot write" in error


@pytest.mark.skipif(os.geteuid() == 0, reason="root may write into a read-only directory")
def test_a_read_only_out_is_refused_before_any_work(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    (tmp_path / "ro").mkdir(mode=0o500)
    monkeypatch.setattr(derive_command, "derive", lambda *a, **k: pytest.fail("derived anyway"))
    assert main(["derive", "phi", "--emit", "numpy", "--out", str(tmp_path / "ro" / "new")]) == 2


def test_the_output_cases_of_the_hostile_bench(capsys: pytest.CaptureFixture[str]) -> None:
    """``bench/hostile_cli.py``'s OUTPUT section: every case exits 2 with one error line, through
    ``python -m symrot`` (the worker process included)."""
    sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "bench"))
    import hostile_cli

    bad = hostile_cli.run_output_cases()
    assert bad == 0, capsys.readouterr().out


def test_no_directory_is_created_through_a_link_out_of_out(tmp_path: Path) -> None:
    (tmp_path / "elsewhere").mkdir()
    out = tmp_path / "out"
    out.mkdir()
    (out / "numpy").symlink_to(tmp_path / "elsewhere")
    with pytest.raises(SymrotError, match="outside"):
        write_files(out, [(out / "numpy" / "deeper" / "rotation.py", "new")], announce=False)
    assert list((tmp_path / "elsewhere").iterdir()) == []


def test_a_new_out_is_created(tmp_path: Path) -> None:
    write_files(tmp_path / "new" / "out", [(tmp_path / "new" / "out" / "c" / "a.h", "new")], announce=False)
    assert (tmp_path / "new" / "out" / "c" / "a.h").read_text() == "new"
