"""Symbolic work split between this process and a forked child (:mod:`symrot.core.forked`), for the
derivation summary and the plan on a machine with two cores.

Each step starts the child from the state the process has at that point and divides a fixed list
of independent jobs between them by a fixed rule, so that what each process computes, and the
forms it finds (SymPy's caches carry state from one job to the next), are the same on every run
and every machine with ``fork``.

- :func:`simplify_tensors`: the simplified and canonical forms of the five tensors (eqs 14, 22,
  26, 81, 83); H⁻¹ and K, the costliest, in the child.
- :func:`computed_in_two_processes`: a list of calls of one function, alternately assigned
  (largest first) to the process and the child; the values come back in a dict.
"""

from __future__ import annotations

from collections.abc import Callable, Hashable, Sequence
from typing import Any, TypeVar

from symrot.core.derivation import TENSOR_NAMES, Derivation
from symrot.core.forked import first_here_others_in_children, in_child

CHILD_TENSORS = ("H_inverse", "K")
"""Tensors simplified in the child: the two costliest (for tan(φ/3) + 8 tan(3φ/4)/9, 2.6 and 1.8 s
of the 8.1 s for all five)."""

K = TypeVar("K", bound=Hashable)
V = TypeVar("V")


def _is_simplified(derivation: Derivation, name: str) -> bool:
    return {"simplified", "canonical"} <= derivation.tensors[name].__dict__.keys()


def simplify_tensors(derivation: Derivation, beside: Callable[[], object] | None = None) -> None:
    """Fill the ``simplified`` and ``canonical`` forms of every tensor of ``derivation``: those of
    :data:`CHILD_TENSORS` in a forked child while this process computes the others and then calls
    ``beside`` (e.g. the validity analysis). Tensors already simplified are left as they are."""
    in_child_names = [n for n in CHILD_TENSORS if not _is_simplified(derivation, n)]

    def child_forms() -> dict[str, tuple[Any, Any]]:
        return {name: (derivation.tensors[name].simplified, derivation.tensors[name].canonical)
                for name in in_child_names}

    with in_child(child_forms) as wait:
        for name in TENSOR_NAMES:
            if name not in CHILD_TENSORS:
                derivation.tensors[name].simplified  # noqa: B018 (fills the cached property)
                derivation.tensors[name].canonical  # noqa: B018
        if beside is not None:
            beside()
        forms = wait()
    for name, (simplified, canonical) in forms.items():
        derivation.tensors[name].__dict__.update(simplified=simplified, canonical=canonical)


def computed_in_two_processes(function: Callable[[K], V], jobs: Sequence[K],
                              sizes: Sequence[int]) -> dict[K, V]:
    """``{job: function(job)}``: the jobs sorted by decreasing size (ties in list order) go
    alternately to this process (the first) and to a forked child."""
    order = sorted(range(len(jobs)), key=lambda i: -sizes[i])
    mine = [jobs[i] for i in order[0::2]]
    theirs = [jobs[i] for i in order[1::2]]
    if not theirs:
        return {job: function(job) for job in mine}
    here, there = first_here_others_in_children([lambda: {job: function(job) for job in mine},
                                                 lambda: {job: function(job) for job in theirs}])
    return {**here, **there}
