"""Generated C under AddressSanitizer and UndefinedBehaviorSanitizer on the domain fuzz (issue 17).

The inputs of the NumPy domain fuzz (components from 0 and the smallest subnormal to 1.7e308, inf,
NaN, both signs; float rounds them to its subnormals and inf), quaternions and matrices (rotations,
perturbed rotations, the non-rotations of issue 17) through every single call, batch kernel and
operation (to/from_quaternion, from_rotation_matrix, compose, rescale) of five headers covering
every plan kind, both precisions, in a clang -O0 -fsanitize=address,undefined build that aborts on
the first report (tests/c_fuzz.py). Outputs are finite or NaN, statuses 0 (finite result) or 1
(NaN result). The long version (every header, gcc and clang, more inputs): bench/c_sanitizer_fuzz.py.
"""

from __future__ import annotations

import shutil
from pathlib import Path

import numpy as np
import pytest

from . import c_fuzz

ROOT = Path(__file__).resolve().parent.parent
HEADERS = ["rotation_vector", "euler_rodrigues", "cayley_gibbs_rodrigues", "wiener_milenkovic", "det_h_one"]
"""Sin/cos kernel, sine-family fold (complement), unbounded p, tangent family, Newton angle."""


@pytest.mark.skipif(shutil.which("clang") is None, reason="clang is not installed")
def test_headers_run_clean_under_asan_and_ubsan_on_the_domain_fuzz(tmp_path: Path) -> None:
    p, e, r = c_fuzz.vectors(120, seed=17), c_fuzz.quaternions(60, seed=17), c_fuzz.matrices(30, seed=17)
    binary = c_fuzz.build("clang", HEADERS, ROOT / "generated" / "c", tmp_path)
    outputs = c_fuzz.run(binary, p, e, r, tmp_path)  # raises with the sanitizer's report
    statuses, values, disagree = c_fuzz.statuses_and_values(HEADERS, len(p), len(e), len(r), outputs)
    assert not np.isinf(values).any(), "an output is +-inf"
    assert not disagree, disagree
    assert set(np.unique(statuses)) <= {0.0, 1.0}
    assert {0.0, 1.0} <= set(np.unique(statuses)), "the fuzz must reach both statuses"
