"""Bounded simplification: ranking never fails, whatever the size of the numbers."""

from __future__ import annotations

import sympy as sp

from symrot.parsing import PHI
from symrot.simplify import complexity, simplest


def test_numbers_beyond_the_str_digit_limit_are_ranked_and_simplified() -> None:
    big = sp.Integer(10) ** 5000
    assert complexity(big * PHI)[2] > 5000
    assert simplest(big * sp.sin(PHI) ** 2 / (1 - sp.cos(PHI) ** 2)) == big
