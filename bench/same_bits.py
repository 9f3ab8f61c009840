"""Do two trees of generated Python modules compute the same bits? (a check for refactorings)

Loads every module of ``KIND`` (numpy, jax, torch) from ``OLD/KIND/`` and ``NEW/KIND/`` and calls
each public function of both on the same inputs: per precision (float64, float32), a sweep of
magnitudes from 0 and 1e-300 to the edge of the validity range and past it (inf, NaN), as one
vector, five, the whole sweep, and the sweep tiled to 5,200 vectors (the NumPy module's blocked
path); it counts the calls whose results differ in a bit, dtype or shape (or in the error raised).
JAX runs with jax_enable_x64. It prints one line per difference and the count, and exits 1 on any.

Run: ``python bench/same_bits.py OLD_GENERATED NEW_GENERATED [--kinds numpy,jax,torch]``, e.g. with
OLD from ``git archive HEAD~1 generated | tar -x -C /tmp/old``.
"""

from __future__ import annotations

import argparse
import importlib.util
import inspect
import sys
import warnings
from collections.abc import Callable
from pathlib import Path
from types import ModuleType
from typing import Any

import numpy as np

SLICES = (slice(0, 1), slice(0, 5), slice(None), "tiled")


def load(path: Path, name: str) -> ModuleType:
    spec = importlib.util.spec_from_file_location(name, path)
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def inputs(module: ModuleType, dtype: type) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    rng = np.random.default_rng(7)
    edge = float(module.P_MAX) if np.isfinite(module.P_MAX) else 50.0
    sizes = np.concatenate([[0.0, 1e-300, 1e-30, 1e-8, 1e-3], np.linspace(0.01, 1.2, 40) * edge,
                            edge * (1 - np.logspace(-12, -1, 10)),
                            [edge, edge * (1 + 1e-15), 1e10, np.inf, np.nan]])
    axis = rng.normal(size=(len(sizes), 3))
    axis /= np.linalg.norm(axis, axis=1)[:, None]
    p = (axis * sizes[:, None]).astype(dtype)
    return p, rng.normal(size=p.shape).astype(dtype), rng.normal(size=p.shape).astype(dtype)


def outputs(module: ModuleType, convert: Callable[[np.ndarray], Any],
            vectors: tuple[np.ndarray, np.ndarray, np.ndarray]) -> dict[tuple[str, str], Any]:
    p, a, b = vectors
    results: dict[tuple[str, str], Any] = {}
    for name in sorted(dir(module)):
        function = getattr(module, name)
        if name.startswith("_") or not callable(function) or function.__module__ != module.__name__:
            continue
        arguments = {1: (p,), 2: (p, a), 3: (p, a, b)}[len(inspect.signature(function).parameters)]
        if name == "from_quaternion":
            arguments = (np.concatenate([a[:, :1], a], axis=1),)
        elif name == "from_rotation_matrix":
            arguments = (np.broadcast_to(np.eye(3, dtype=p.dtype), (len(p), 3, 3)).copy(),)
        for chosen in SLICES:
            parts = [np.tile(x, (80,) + (1,) * (x.ndim - 1)) if chosen == "tiled" else x[chosen]
                     for x in arguments]
            try:
                value = function(*map(convert, parts))
            except Exception as error:  # the error is part of the result compared
                results[(name, str(chosen))] = repr(error)
                continue
            values = value if isinstance(value, tuple) else (value,)
            results[(name, str(chosen))] = tuple(
                np.asarray(v.detach() if hasattr(v, "detach") else v) for v in values)
    return results


def same(x: Any, y: Any) -> bool:
    if isinstance(x, str) or isinstance(y, str):
        return x == y
    return len(x) == len(y) and all(u.dtype == v.dtype and u.shape == v.shape
                                    and u.tobytes() == v.tobytes() for u, v in zip(x, y, strict=True))


def converter(kind: str) -> Callable[[np.ndarray], Any]:
    if kind == "numpy":
        return lambda value: value
    if kind == "torch":
        import torch
        return torch.as_tensor
    import jax
    jax.config.update("jax_enable_x64", True)
    return jax.numpy.asarray


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("old", type=Path, help="the generated/ folder before")
    parser.add_argument("new", type=Path, help="the generated/ folder after")
    parser.add_argument("--kinds", default="numpy,jax,torch", help="comma-separated: numpy, jax, torch")
    args = parser.parse_args(argv)
    calls = differences = 0
    for kind in args.kinds.split(","):
        convert = converter(kind)
        for path in sorted((args.new / kind).glob("*.py")):
            old = load(args.old / kind / path.name, f"old_{kind}_{path.stem}")
            new = load(path, f"new_{kind}_{path.stem}")
            for dtype in (np.float64, np.float32):
                vectors = inputs(new, dtype)
                with warnings.catch_warnings():
                    warnings.simplefilter("ignore")
                    before, after = outputs(old, convert, vectors), outputs(new, convert, vectors)
                for key in sorted(before.keys() | after.keys()):
                    calls += 1
                    if key not in before or key not in after or not same(before[key], after[key]):
                        differences += 1
                        print(f"differs: {kind} {path.stem} {np.dtype(dtype).name} {key[0]} {key[1]}")
    print(f"{calls - differences} of {calls} calls give the same bits")
    return 1 if differences else 0


if __name__ == "__main__":
    sys.exit(main())
