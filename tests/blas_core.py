"""Which kernel set NumPy's bundled OpenBLAS runs on this CPU (tests/test_reproducible.py asks it in
its own process and in a child started with ``OPENBLAS_CORETYPE``, to see that the variant took effect)."""

from __future__ import annotations

import ctypes
import glob
import os

import numpy

SYMBOLS = ("scipy_openblas_get_corename64_", "scipy_openblas_get_corename",
           "openblas_get_corename64_", "openblas_get_corename")


def openblas_core() -> str | None:
    """OpenBLAS's ``get_corename()`` (e.g. "Haswell"), or None when NumPy bundles no OpenBLAS."""
    pattern = os.path.join(os.path.dirname(numpy.__file__), os.pardir, "numpy.libs", "*openblas*")
    for path in sorted(glob.glob(pattern)):
        library = ctypes.CDLL(path)
        for symbol in SYMBOLS:
            function = getattr(library, symbol, None)
            if function is not None:
                function.restype = ctypes.c_char_p
                name: bytes = function()
                return name.decode()
    return None
