"""The long version of tests/test_c_sanitizer_fuzz.py (issue 17): every header under generated/c,
gcc and clang with -O0 -fsanitize=address,undefined -fno-sanitize-recover=all, on many more fuzz
inputs (tests/c_fuzz.py). Prints one line per compiler: inputs, outputs, ±inf count, statuses,
status/output disagreements; exits 1 on any sanitizer report, ±inf or disagreement.

Run: ``python bench/c_sanitizer_fuzz.py [--vectors 5000] [--quaternions 2000] [--matrices 1000]``.
"""

from __future__ import annotations

import argparse
import shutil
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from tests import c_fuzz  # noqa: E402


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--vectors", type=int, default=5000)
    parser.add_argument("--quaternions", type=int, default=2000)
    parser.add_argument("--matrices", type=int, default=1000)
    parser.add_argument("--seed", type=int, default=2026)
    args = parser.parse_args(argv)
    headers = sorted(path.stem.removeprefix("symrot_") for path in (ROOT / "generated" / "c").glob("*.h"))
    p = c_fuzz.vectors(args.vectors, args.seed)
    e = c_fuzz.quaternions(args.quaternions, args.seed)
    r = c_fuzz.matrices(args.matrices, args.seed)
    failed = False
    for compiler in ("clang", "gcc"):
        if shutil.which(compiler) is None:
            print(f"{compiler}: not installed")
            continue
        with tempfile.TemporaryDirectory() as tmp:
            work = Path(tmp)
            start = time.perf_counter()
            binary = c_fuzz.build(compiler, headers, ROOT / "generated" / "c", work)
            built = time.perf_counter() - start
            try:
                outputs = c_fuzz.run(binary, p, e, r, work)
            except AssertionError as report:
                print(f"{compiler}: SANITIZER REPORT\n{report}")
                failed = True
                continue
            statuses, values, disagree = c_fuzz.statuses_and_values(headers, len(p), len(e), len(r), outputs)
            infinite = int(np.isinf(values).sum())
            failed |= bool(infinite or disagree)
            print(f"{compiler}: {len(headers)} headers, {len(p)} vectors, {len(e)} quaternions, {len(r)} "
                  f"matrices, both precisions: {outputs.size} outputs, no sanitizer report, "
                  f"{infinite} +-inf, "
                  f"statuses 0/1: {int((statuses == 0).sum())}/{int((statuses == 1).sum())}, "
                  f"disagreements: {disagree or 0} (build {built:.0f} s, run "
                  f"{time.perf_counter() - start - built:.0f} s)", flush=True)
    return 1 if failed else 0


if __name__ == "__main__":
    raise SystemExit(main())
