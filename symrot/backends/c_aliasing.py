"""In-place calls of the generated C functions: any output may be the same array as any input.

A single call writes its outputs only after it has read every input: where a function ends with
the stores of its entries (``R[0] = …; …; R[8] = …;``) and those entries still read an input
array, :func:`stored_last` turns them into locals ``out0 …`` and stores the locals at the end, so
``rotation_matrix(buf, buf)``, ``to_quaternion(buf, buf)`` or ``angular_acceleration(p, pdot,
pddot, pdot)`` give the bits of separate buffers. The other functions already read their inputs
into locals (quaternions, the tensors of ``compose_jacobians``) or by value before writing.
Early NaN returns write only after every read. The ``_batch`` kernels
(:mod:`symrot.backends.c_batch`) run their blocks and vectors backward, so that with the output
and p at the same base pointer (output stride 9 ≥ 3) no vector's entries overwrite a p not yet
read. Partial overlaps other than identical base pointers are not supported (the header's
comment block and docs/guide/c.md say so).
"""

from __future__ import annotations

import re
from typing import Any

Statement = dict[str, Any]

PARAMETER = re.compile(r"(const )?(?:double|float) (\w+)\[\d+\]")
ENTRY = re.compile(r"^(\w+)\[(\d+)\]$")
READ = re.compile(r"\b(\w+)(?:\[(\d+)\])?")


def parameters(signature: str) -> tuple[list[str], list[str]]:
    """The input (``const``) and output array parameters of a C signature."""
    found = PARAMETER.findall(signature)
    return [name for const, name in found if const], [name for const, name in found if not const]


def clobbers(tail: list[Statement], inputs: list[str]) -> bool:
    """Whether a store of ``tail`` reads an input entry that an earlier store overwrites when the
    output is the input's array (entry i of both at the same address), or passes an input whole."""
    written: set[str] = set()
    for statement in tail:
        for name, index in READ.findall(statement["value"]):
            if name in inputs and (not index or index in written):
                return True
        written.add(statement["name"].split("[")[1].rstrip("]"))
    return False


def stored_last(function: dict[str, Any]) -> dict[str, Any]:
    """``function`` with its trailing stores of output entries computed into locals first, where
    a store could overwrite an input entry that a later one reads (otherwise unchanged). A function
    printed whole from ``templates/c/shared.h.j2`` (a ``source``) is written to read first."""
    if "source" in function:
        return function
    inputs, outputs = parameters(function["signature"])
    statements: list[Statement] = function["statements"]
    start = len(statements)
    while start > 0 and statements[start - 1]["kind"] == "set" and (
            (match := ENTRY.match(statements[start - 1]["name"])) and match[1] in outputs):
        start -= 1
    tail = statements[start:]
    if not clobbers(tail, inputs):
        return function
    entry = re.compile(r"\b(?:" + "|".join(outputs) + r")\[\d+\]")
    local: dict[str, str] = {}  # an entry stored earlier in the tail is read from its local
    lets: list[Statement] = []
    for s in tail:
        value = entry.sub(lambda m: local.get(m[0], m[0]), s["value"])
        local[s["name"]] = f"out{len(local)}"
        lets.append({"kind": "let", "type": _type(function["signature"]), "name": local[s["name"]],
                     "value": value, "ops": s.get("ops", 0)})
    stores = [{"kind": "set", "name": s["name"], "value": local[s["name"]], "ops": 0} for s in tail]
    comment = {"kind": "comment", "text": "stored last: an output may be the same array as an input"}
    return {**function, "statements": [*statements[:start], *lets, comment, *stores]}


def _type(signature: str) -> str:
    return "float" if re.search(r"\bfloat \w+\[", signature) else "double"


__all__ = ["parameters", "stored_last"]
