"""Batch speed: 10⁶ rotations through the generated ``rotation_matrix`` against SciPy (issue 4).

Times ``rotation_matrix`` of generated/numpy/rotation_vector.py and cayley_gibbs_rodrigues.py /
wiener_milenkovic.py against ``Rotation.from_rotvec(p).as_matrix()`` and
``Rotation.from_mrp(p).as_matrix()`` on the same random inputs, best of ``--repeat`` runs, and
writes the table to docs/performance.md (section "NumPy batch speed").

Run: ``python bench/batch_speed.py [--count 1000000] [--repeat 5]``.
"""

from __future__ import annotations

import argparse
import importlib.util
import re
import time
from collections.abc import Callable
from pathlib import Path
from types import ModuleType

import numpy as np
from scipy.spatial.transform import Rotation

ROOT = Path(__file__).resolve().parent.parent
SECTION = "## NumPy batch speed"


def load(name: str) -> ModuleType:
    path = ROOT / "generated" / "numpy" / f"{name}.py"
    spec = importlib.util.spec_from_file_location(f"generated_{name}", path)
    assert spec and spec.loader
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def best_time(function: Callable[[], object], repeat: int) -> float:
    times = []
    for _ in range(repeat):
        start = time.perf_counter()
        function()
        times.append(time.perf_counter() - start)
    return min(times)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser()
    parser.add_argument("--count", type=int, default=1_000_000)
    parser.add_argument("--repeat", type=int, default=5)
    parser.add_argument("--out", default=str(ROOT / "docs" / "performance.md"))
    args = parser.parse_args(argv)
    rng = np.random.default_rng(0)
    axes = rng.normal(size=(args.count, 3))
    axes /= np.linalg.norm(axes, axis=1, keepdims=True)
    angles = rng.uniform(0, 3.0, size=(args.count, 1))
    rotvec = axes * angles
    mrp = axes * np.tan(angles / 4)
    rows = []
    scipy_rotvec = best_time(lambda: Rotation.from_rotvec(rotvec).as_matrix(), args.repeat)
    scipy_mrp = best_time(lambda: Rotation.from_mrp(mrp).as_matrix(), args.repeat)
    rows.append(("scipy Rotation.from_rotvec(p).as_matrix()", scipy_rotvec, 1.0))
    rows.append(("scipy Rotation.from_mrp(p).as_matrix()", scipy_mrp, 1.0))
    for name, p, baseline in (("rotation_vector", rotvec, scipy_rotvec),
                              ("wiener_milenkovic", 4 * mrp, scipy_mrp),
                              ("cayley_gibbs_rodrigues", axes * 2 * np.tan(angles / 2), scipy_rotvec)):
        module = load(name)
        elapsed = best_time(lambda module=module, p=p: module.rotation_matrix(p), args.repeat)
        rows.append((f"generated {name}.rotation_matrix(p)", elapsed, elapsed / baseline))
    command = f"python bench/batch_speed.py --count {args.count} --repeat {args.repeat}"
    lines = [SECTION, "", f"`{command}` ({args.count} rotations, float64, best of {args.repeat}; "
             "ratio against from_rotvec, or from_mrp for Wiener-Milenkovic = 4 x MRP).", "",
             "| kernel | seconds | ratio to scipy |", "|---|---|---|"]
    lines += [f"| {label} | {seconds:.4f} | {ratio:.2f} |" for label, seconds, ratio in rows]
    section = "\n".join(lines) + "\n\n"
    print(section)
    out = Path(args.out)
    text = out.read_text(encoding="utf-8") if out.exists() else "# Performance\n\n"
    pattern = re.compile(re.escape(SECTION) + r".*?(?=^## |\Z)", re.S | re.M)
    text = pattern.sub(section, text) if pattern.search(text) else text.rstrip("\n") + "\n\n" + section
    out.parent.mkdir(parents=True, exist_ok=True)
    out.write_text(text, encoding="utf-8")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
