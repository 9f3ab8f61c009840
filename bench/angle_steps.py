"""Accuracy of a NumPy module's ``angle`` for eq 35 (det H = 1) against tests/reference.py.

Used to size the Newton iteration (issue 61, mutation ``plan-newton-steps-dropped``): pass the
generated module and modules regenerated with fewer steps; prints, per precision, the worst error
in ulps divided by max(1, κ) over |φ| from 1e-3 to 6 and 2π − 0.3 … 2π − 1e-7.

Run: ``python bench/angle_steps.py generated/numpy/det_h_one.py [OTHER.py ...]``.
"""

from __future__ import annotations

import argparse
import importlib.util
import sys
from pathlib import Path

import mpmath
import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from tests.reference import GeneratingFunction  # noqa: E402


def load(path: str, index: int) -> object:
    spec = importlib.util.spec_from_file_location(f"angle_steps_{index}", path)
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def main(paths: list[str]) -> None:
    mpmath.mp.dps = 50
    function = GeneratingFunction("cbrt(6*(phi-sin(phi)))", phi_max_text="2*pi")
    modules = [load(path, i) for i, path in enumerate(paths)]
    angles = np.concatenate([np.geomspace(1e-3, 6, 400), 2 * np.pi - np.geomspace(1e-7, 0.3, 400)])
    for dtype in (np.float64, np.float32):
        worst = [0.0] * len(modules)
        for phi in angles:
            p = np.array([float(function.value(mpmath.mpf(phi))), 0, 0], dtype=dtype)
            s = mpmath.mpf(float(p[0]))
            reference = function.inverse(s, mpmath.mpf(phi))
            slope = function.dp(reference)
            if slope == 0:  # rounded onto the fold at 2π
                continue
            kappa = float(abs(s / (slope * reference)))
            for i, module in enumerate(modules):
                got = float(np.asarray(module.angle(p)).ravel()[0])  # type: ignore[attr-defined]
                ulp = float(abs(got - reference)) / float(np.spacing(dtype(abs(float(reference)))))
                worst[i] = max(worst[i], ulp / max(1.0, kappa))
        for path, value in zip(paths, worst, strict=True):
            print(f"{np.dtype(dtype).name}  {value:10.3g}  {path}")


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("modules", nargs="+", help="generated NumPy modules of eq 35 (det_h_one)")
    main(parser.parse_args().modules)
