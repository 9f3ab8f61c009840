"""Issue 56: C text with one source. The functions that are the same in every header come from
templates/c/shared.h.j2, and a coefficient block that several functions of one header compute alike
is printed once, as a helper (symrot/backends/c_shared.py)."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from symrot.backends.c_backend import COVERED

GENERATED = Path(__file__).resolve().parent.parent / "generated" / "c"
SHARED = ("from_rotation_matrix", "rescale", "compose_jacobians", "rescale_jacobian")


def _function(text: str, name: str) -> str:
    match = re.search(rf"^/\* {re.escape(name)}:.*?^}}\n", text, re.S | re.M)
    assert match, name
    return match[0]


@pytest.mark.parametrize("function", SHARED)
@pytest.mark.parametrize("suffix", ["", "_f"])
def test_shared_functions_are_one_text_in_every_header(function: str, suffix: str) -> None:
    texts = set()
    for name in COVERED:
        text = (GENERATED / f"symrot_{name}.h").read_text(encoding="utf-8")
        source = _function(text, f"symrot_{name}_{function}{suffix}")
        texts.add(source.replace(f"symrot_{name}", "symrot_NAME"))
    assert len(texts) == 1


@pytest.mark.parametrize("name", COVERED)
def test_no_coefficient_block_is_printed_twice_in_a_header(name: str) -> None:
    """Every ``if (x < ...) { c_... = <Horner> ...`` block of 30 lines or more stands once in a header
    (issue 56's threshold; a shorter one may stand twice inside blocks that differ otherwise)."""
    text = (GENERATED / f"symrot_{name}.h").read_text(encoding="utf-8")
    pattern = re.compile(r"^( +)(?:double|float) c_\w+(?:, c_\w+)*;\n\1if \(x < .*?\n\1}\n", re.S | re.M)
    blocks = [match[0] for match in pattern.finditer(text)]
    repeated = {block for block in blocks if blocks.count(block) > 1 and block.count("\n") >= 30}
    assert not repeated, [block.splitlines()[0] for block in repeated]
