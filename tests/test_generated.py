"""generated/ is current: rerunning the producers changes nothing (``make generate`` is the fix).

The check is split into the producers' own units of work (one per parameterization for the NumPy,
JAX, PyTorch and C outputs, which share its plan; one per other producer), each in a fresh
``python -m symrot.generate --check`` process (it fixes the hash seed as ``make generate`` does), so
that pytest-xdist spreads them over the workers. A stale file fails with its diff and the fix command.
"""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

from symrot import generate
from symrot.entry import SEED

ROOT = Path(__file__).resolve().parent.parent
GENERATED = ROOT / "generated"
SELECTED = [prefix for prefix, _ in generate.producers()]
OTHERS = ",".join(prefix for prefix in SELECTED if prefix not in generate.PER_NAME)
UNITS = [*(["--name", task[1]] for task in generate.tasks(SELECTED) if task[0] == "names"),
         ["--only", OTHERS]]
"""One unit per parameterization; the other producers in one (they share their derivations)."""


@pytest.mark.parametrize("unit", UNITS, ids=lambda unit: unit[1] if unit[0] == "--name" else "others")
def test_generated_files_are_current(unit: list[str]) -> None:
    environment = {**os.environ, "PYTHONHASHSEED": SEED}  # the seed it would re-execute itself with
    check = subprocess.run([sys.executable, "-m", "symrot.generate", "--check", "--jobs", "1", *unit,
                            str(GENERATED)], capture_output=True, text=True, cwd=ROOT, timeout=600,
                           env=environment, check=False)
    assert check.returncode == 0, f"{check.stdout}\n{check.stderr}\nFix: make generate"


def test_every_per_name_file_belongs_to_a_parameterization() -> None:
    assert generate.stale_names(GENERATED) == [], "Fix: make generate (it deletes them)"


def test_the_units_cover_every_producer_and_name() -> None:
    names = {unit[1] for unit in UNITS if unit[0] == "--name"}
    assert names == {*generate.names_of("c/"), *generate.names_of("numpy/")}
    (others,) = (unit[1] for unit in UNITS if unit[0] == "--only")
    assert set(generate.selected_prefixes(others)) == set(SELECTED) - set(generate.PER_NAME)


def test_a_stale_file_fails_the_check_with_its_diff(tmp_path: Path) -> None:
    copy = tmp_path / "generated"
    (copy / "numpy").mkdir(parents=True)
    for name in ("rotation_vector.py", "linear.py"):
        (copy / "numpy" / name).write_bytes((GENERATED / "numpy" / name).read_bytes())
    (copy / "numpy" / "removed_entry.py").write_text("stale\n", encoding="utf-8")
    stale = copy / "numpy" / "rotation_vector.py"
    text = stale.read_text(encoding="utf-8")
    stale.write_text(text.replace("P_MAX = ", "P_MAX = 1 + ", 1), encoding="utf-8")
    assert generate.stale_names(copy) == ["numpy/removed_entry.py"]
    current = {"numpy/rotation_vector.py": text}
    diffs = generate.check(copy, current, ["numpy/"], "rotation_vector")  # linear.py: not this name's
    assert len(diffs) == 1 and "-P_MAX = 1 + " in diffs[0] and "+P_MAX = " in diffs[0]
    # without a name, linear.py (not in ``current``) and the stale file differ too
    assert len(generate.check(copy, current, ["numpy/"])) == 3
