"""generated/numpy/ is current: rerunning the producer changes nothing."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent


def test_generated_numpy_modules_are_current() -> None:
    check = subprocess.run([sys.executable, "-m", "symrot.generate", "--check", "--only", "numpy/",
                            str(ROOT / "generated")], capture_output=True, text=True, cwd=ROOT)
    assert check.returncode == 0, f"{check.stdout}\n{check.stderr}\nFix: make generate"
