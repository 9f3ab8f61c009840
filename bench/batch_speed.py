"""NumPy speed: the generated modules against SciPy's ``Rotation`` from n = 1 to 10⁷ (issue 21).

Question answered: how long does the generated NumPy module take, against the closest public SciPy
call, for n rotations at once?  Pairs (symrot kernel | SciPy peer, same inputs):

- rotation_vector ``rotation_matrix`` | ``Rotation.from_rotvec(p).as_matrix()``
- wiener_milenkovic ``rotation_matrix`` | ``Rotation.from_mrp(p / 4).as_matrix()`` (WM = 4 × MRP)
- cayley_gibbs_rodrigues ``rotation_matrix`` | ``Rotation.from_quat([p / 2, 1]).as_matrix()``
  (SciPy has no Gibbs vector; the quaternion (g, 1) with g = p/2 is the closest path, its
  construction counted)
- rotation_vector ``tangent`` and ``tangent_inverse`` | ``from_rotvec(p).as_matrix()`` (SciPy has
  no tangent tensor; the same input-to-3×3 call is the closest operation)
- rotation_vector ``compose`` | ``(from_rotvec(p2) * from_rotvec(p1)).as_rotvec()``

Inputs: angles uniform in [0, 3) on random axes.  Each repetition times the symrot call and the peer
call back to back (the order alternating) in thread CPU time, so both see the same machine state;
the ratio of a repetition is peer time / symrot time (> 1: symrot faster).  Reported: the minimum
and the median of these paired ratios and the median times.  Writes the section "NumPy speed" of
docs/performance.md with the command that produced it.

Run: ``python bench/batch_speed.py [--sizes 1,10,1000,...] [--dtypes float64,float32]``.
"""

from __future__ import annotations

import argparse
import importlib.util
import re
import statistics
import time
from collections.abc import Callable
from pathlib import Path
from types import ModuleType

import numpy as np
from machine import description  # bench/, next to this script
from scipy.spatial.transform import Rotation

ROOT = Path(__file__).resolve().parent.parent
SECTION = "## NumPy speed"
SIZES = (1, 10, 1_000, 10_000, 100_000, 1_000_000, 10_000_000)


def load(name: str) -> ModuleType:
    path = ROOT / "generated" / "numpy" / f"{name}.py"
    spec = importlib.util.spec_from_file_location(f"generated_{name}", path)
    assert spec and spec.loader
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def cpu_time(function: Callable[[], object], loops: int) -> float:
    """Thread CPU seconds per call, over ``loops`` calls."""
    start = time.thread_time()
    for _ in range(loops):
        function()
    return (time.thread_time() - start) / loops


def paired(ours: Callable[[], object], peer: Callable[[], object], n: int,
           repeat: int) -> tuple[float, float, float, float]:
    """(min ratio, median ratio, median symrot s, median peer s); ratio = peer / symrot."""
    loops = max(1, min(2000, 200_000 // n))
    ours(), peer()  # warm up
    ratios, mine, theirs = [], [], []
    for r in range(repeat):
        if r % 2:
            b = cpu_time(peer, loops)
            a = cpu_time(ours, loops)
        else:
            a = cpu_time(ours, loops)
            b = cpu_time(peer, loops)
        ratios.append(b / a)
        mine.append(a)
        theirs.append(b)
    return min(ratios), statistics.median(ratios), statistics.median(mine), statistics.median(theirs)


def cases(n: int, dtype: type, rng: np.random.Generator) -> list[tuple[str, Callable[[], object],
                                                                      Callable[[], object]]]:
    axes = rng.normal(size=(n, 3))
    axes /= np.linalg.norm(axes, axis=1, keepdims=True)
    angles = rng.uniform(0.0, 3.0, size=(n, 1))
    rv = (axes * angles).astype(dtype)
    wm = (4.0 * axes * np.tan(angles / 4)).astype(dtype)
    cgr = (2.0 * axes * np.tan(angles / 2)).astype(dtype)
    rv2 = np.roll(rv, 1, axis=0)
    rotvec, wiener = load("rotation_vector"), load("wiener_milenkovic")
    cayley = load("cayley_gibbs_rodrigues")
    one = np.ones((n, 1), dtype=dtype)
    return [
        ("rotation_vector rotation_matrix | from_rotvec().as_matrix()",
         lambda: rotvec.rotation_matrix(rv), lambda: Rotation.from_rotvec(rv).as_matrix()),
        ("wiener_milenkovic rotation_matrix | from_mrp(p/4).as_matrix()",
         lambda: wiener.rotation_matrix(wm), lambda: Rotation.from_mrp(wm / 4).as_matrix()),
        ("cayley_gibbs_rodrigues rotation_matrix | from_quat([p/2, 1]).as_matrix()",
         lambda: cayley.rotation_matrix(cgr),
         lambda: Rotation.from_quat(np.concatenate([cgr / 2, one], axis=1)).as_matrix()),
        ("rotation_vector tangent | from_rotvec().as_matrix()",
         lambda: rotvec.tangent(rv), lambda: Rotation.from_rotvec(rv).as_matrix()),
        ("rotation_vector tangent_inverse | from_rotvec().as_matrix()",
         lambda: rotvec.tangent_inverse(rv), lambda: Rotation.from_rotvec(rv).as_matrix()),
        ("rotation_vector compose | (from_rotvec(p2) * from_rotvec(p1)).as_rotvec()",
         lambda: rotvec.compose(rv, rv2),
         lambda: (Rotation.from_rotvec(rv2) * Rotation.from_rotvec(rv)).as_rotvec()),
    ]


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser()
    parser.add_argument("--sizes", default=",".join(map(str, SIZES)))
    parser.add_argument("--dtypes", default="float64,float32")
    parser.add_argument("--repeat", type=int, default=7, help="paired repetitions (3 at n >= 10^6)")
    parser.add_argument("--only", default="", help="substring of the case names to run")
    parser.add_argument("--out", default=str(ROOT / "docs" / "performance.md"))
    parser.add_argument("--no-write", action="store_true")
    args = parser.parse_args(argv)
    sizes = [int(s) for s in args.sizes.split(",")]
    rows = []
    for dtype_name in args.dtypes.split(","):
        dtype = getattr(np, dtype_name)
        for n in sizes:
            rng = np.random.default_rng(n)
            for label, ours, peer in cases(n, dtype, rng):
                if args.only not in label:
                    continue
                repeat = args.repeat if n < 1_000_000 else 3
                low, mid, mine, theirs = paired(ours, peer, n, repeat)
                rows.append((label, dtype_name, n, mine, theirs, low, mid))
                print(f"{label:75s} {dtype_name} n={n:>8d} symrot {mine * 1e6:12.1f} us "
                      f"peer {theirs * 1e6:12.1f} us ratio min {low:.2f} median {mid:.2f}", flush=True)
    command = "python bench/batch_speed.py" + (f" --sizes {args.sizes}" if sizes != list(SIZES) else "") \
        + (f" --dtypes {args.dtypes}" if args.dtypes != "float64,float32" else "") \
        + (f" --repeat {args.repeat}" if args.repeat != 7 else "") \
        + (f" --only '{args.only}'" if args.only else "")
    lines = [SECTION, "", f"`{command}` ({description()}, shared): thread CPU time, {args.repeat} "
             "interleaved paired repetitions (3 at n ≥ 10⁶); ratio = SciPy time / symrot time "
             "(> 1: symrot faster), minimum and median of the paired ratios; angles uniform in [0, 3) "
             "on random axes. SciPy computes in float64 for float32 input too.", "",
             "| symrot kernel \\| SciPy peer | dtype | n | symrot µs | SciPy µs | ratio min | ratio median |",
             "| --- | --- | ---: | ---: | ---: | ---: | ---: |"]
    lines += [f"| {label.replace('|', chr(92) + '|')} | {dtype} | {n} | {mine * 1e6:.1f} | "
              f"{theirs * 1e6:.1f} | {low:.2f} | {mid:.2f} |"
              for label, dtype, n, mine, theirs, low, mid in rows]
    section = "\n".join(lines) + "\n\n"
    print(section)
    if args.no_write:
        return 0
    out = Path(args.out)
    text = out.read_text(encoding="utf-8") if out.exists() else "# Performance\n\n"
    pattern = re.compile(r"^## NumPy (batch )?speed.*?(?=^## |\Z)", re.S | re.M)
    text = pattern.sub(lambda _: section, text) if pattern.search(text) \
        else text.rstrip("\n") + "\n\n" + section
    out.parent.mkdir(parents=True, exist_ok=True)
    out.write_text(text, encoding="utf-8")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
