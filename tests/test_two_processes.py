"""symrot.core.two_processes: work split between the process and a forked child gives what the process
alone gives."""

from __future__ import annotations

import os

import sympy as sp

from symrot.core.derivation import TENSOR_NAMES, derive_expression
from symrot.core.parsing import PHI, parse_expression
from symrot.core.two_processes import computed_in_two_processes, simplify_tensors


def test_every_job_is_computed_once_and_half_of_them_in_the_child() -> None:
    jobs = ["a", "bb", "ccc", "dddd", "eeeee"]
    values = computed_in_two_processes(lambda job: (len(job), os.getpid()), jobs, [len(j) for j in jobs])
    assert {job: value[0] for job, value in values.items()} == {job: len(job) for job in jobs}
    here = {job for job, (_, pid) in values.items() if pid == os.getpid()}
    assert here == {"eeeee", "ccc", "a"}  # largest first, alternately: this process takes the first


def test_simplified_tensors_are_equivalent_to_the_sequential_ones() -> None:
    derivation = derive_expression(parse_expression("tan(phi)/2 + tanh(phi)/2"))
    simplify_tensors(derivation)
    for name in TENSOR_NAMES:
        tensor = derivation.tensors[name]
        assert {"simplified", "canonical"} <= tensor.__dict__.keys(), name
        for simplified, raw in zip(tensor.simplified, tensor.coefficients, strict=True):
            difference = (simplified - raw).subs(PHI, sp.Rational(37, 100)).evalf(30)
            assert abs(complex(difference)) < 1e-25, (name, simplified, raw)
