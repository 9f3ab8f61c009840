"""The generated NumPy kernels used blockwise on a Dask array (issue 21, large-data path).

A generated module's functions map (..., 3) to (..., 3, 3), (..., 3) or (...) block by block with no
state across lanes, so ``dask.array.map_blocks`` runs them on arrays larger than memory or on a
cluster; here on a small chunked array with the local synchronous scheduler, compared bit for bit
with the same function on the whole NumPy array (the recipe of docs/guide/numpy.md, "Large data: Dask").
"""

from __future__ import annotations

import importlib.util
from pathlib import Path
from types import ModuleType

import numpy as np
import pytest

da = pytest.importorskip("dask.array")
dask = pytest.importorskip("dask")

GENERATED = Path(__file__).resolve().parent.parent / "generated" / "numpy"


def load(name: str) -> ModuleType:
    spec = importlib.util.spec_from_file_location(f"symrot_dask_{name}", GENERATED / f"{name}.py")
    assert spec and spec.loader
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


@pytest.mark.parametrize("dtype", [np.float64, np.float32])
@pytest.mark.parametrize("name", ["rotation_vector", "wiener_milenkovic", "linear"])
def test_map_blocks_matches_numpy(name: str, dtype: type) -> None:
    module = load(name)
    rng = np.random.default_rng(21)
    axes = rng.normal(size=(1000, 3))
    axes /= np.linalg.norm(axes, axis=1, keepdims=True)
    p = (axes * rng.uniform(0.0, 0.9 * min(module.P_MAX, 6.0), size=(1000, 1))).astype(dtype)
    p[::97] = 0.0  # the series branch in some chunks
    p[5] = np.nan  # outside the range: NaN in its chunk only
    lazy = da.from_array(p, chunks=(128, 3))
    with dask.config.set(scheduler="synchronous"):
        matrices = da.map_blocks(module.rotation_matrix, lazy, dtype=lazy.dtype,
                                 new_axis=2, chunks=(*lazy.chunks, (3,))).compute()
        angles = da.map_blocks(module.angle, lazy, dtype=lazy.dtype, drop_axis=1).compute()
        composed = da.map_blocks(module.compose, lazy, lazy[::-1].rechunk(lazy.chunks),
                                 dtype=lazy.dtype).compute()
    assert matrices.dtype == dtype and matrices.shape == (1000, 3, 3)
    np.testing.assert_array_equal(matrices, module.rotation_matrix(p))
    np.testing.assert_array_equal(angles, module.angle(p))
    np.testing.assert_array_equal(composed, module.compose(p, p[::-1]))
    assert np.isnan(matrices[5]).all() and np.isfinite(np.delete(matrices, 5, axis=0)).all()
