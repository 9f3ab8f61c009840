"""One helper for a coefficient block that several functions of a header compute alike.

The functions of one plan in one precision often need the same coefficients: ``tangent`` and
``omega`` (H), ``tangent_derivative`` and ``tangent_transpose_derivative`` (H and its slopes),
``rotation_matrix`` and the operations… :meth:`~symrot.backends.c_writer.FunctionWriter.coefficients`
marks its statements; where two or more functions hold the same marked block (the same text, of
at least :data:`SHORTEST` lines), the
block becomes one ``static inline`` helper ``symrot_NAME__coefficients_…(x[, d], c_… outputs)``
and each function declares the coefficients and calls it. The helper runs the very statements the
functions ran, in the same order, on the same values (x, and d of the sine family), so results are
bit-identical; its ``ops`` are counted into each caller as before.
"""

from __future__ import annotations

import re
from typing import Any

from symrot.backends.c_statements import PlanWriter, Statement, ops_of

Function = dict[str, Any]
UNMARKED = ("block", "computed")
SHORTEST = 8
"""Lines a block must print to be shared: a shorter one is cheaper to repeat than to call."""


def _worth(lines: int, uses: int, outputs: int) -> bool:
    """Whether sharing a block of ``lines`` used ``uses`` times prints fewer lines: the helper adds
    its comment, signature, braces and one store an output, each caller a declaration and a call."""
    return uses >= 2 and lines >= SHORTEST and uses * lines > lines + 6 + outputs + 2 * uses


def printed_lines(statements: list[Statement]) -> int:
    """Lines ``templates/c/statements.j2`` prints for ``statements``."""
    total = 0
    for statement in statements:
        if statement["kind"] == "if":
            total += 2 + printed_lines(statement["then"]) + (1 + printed_lines(statement["otherwise"])
                                                      if statement["otherwise"] else 0)
        elif statement["kind"] == "loop":
            total += 2 + printed_lines(statement["body"])
        else:
            total += 1
    return total


def _block(statements: list[Statement]) -> tuple[int, int] | None:
    """Start and end of the marked coefficient statements of a function body, if any."""
    marked = [i for i, statement in enumerate(statements) if statement.get("block") == "coefficients"]
    if not marked:
        return None
    assert marked == list(range(marked[0], marked[-1] + 1)), "one contiguous coefficient block"
    return marked[0], marked[-1] + 1


def _unmarked(statements: list[Statement]) -> list[Statement]:
    return [{k: v for k, v in statement.items() if k not in UNMARKED} for statement in statements]


def share_coefficients(functions: list[Function],
                       writer: PlanWriter) -> tuple[list[Function], list[Function]]:
    """``functions`` with every coefficient block that two or more of them compute alike replaced by
    a call, and the helpers (in order of first use; they go before the first caller)."""
    blocks: dict[str, list[Statement]] = {}
    uses: dict[str, int] = {}
    for function in functions:
        span = _block(function.get("statements", []))
        if span is not None:
            block = _unmarked(function["statements"][span[0]:span[1]])
            key = repr(block)
            blocks.setdefault(key, block)
            uses[key] = uses.get(key, 0) + 1
    helpers: dict[str, Function] = {}
    names: set[str] = set()
    shared: list[Function] = []
    for function in functions:
        span = _block(function.get("statements", []))
        if span is None:
            shared.append(function)
            continue
        statements = function["statements"]
        block = _unmarked(statements[span[0]:span[1]])
        key = repr(block)
        computed: list[str] = statements[span[0]]["computed"]
        text = repr(block)
        worth = _worth(printed_lines(block), uses[key], len(computed))
        if not computed or not worth or re.search(r"\bp\[", text):
            shared.append({**function, "statements": [*statements[:span[0]], *block, *statements[span[1]:]]})
            continue
        if key not in helpers:
            helpers[key] = _helper(writer, block, computed, names)
        helper = helpers[key]
        complement = ", d" if helper["takes_d"] else ""
        outputs = ", ".join(f"&{name}" for name in computed)
        call: list[Statement] = [
            {"kind": "declare", "type": writer.ctype, "names": computed},
            {"kind": "call", "value": f"{helper['c_name']}(x{complement}, {outputs})",
             "ops": helper["ops"]},
        ]
        shared.append({**function, "statements": [*statements[:span[0]], *call, *statements[span[1]:]]})
    return shared, [{k: v for k, v in helper.items() if k != "takes_d"} for helper in helpers.values()]


def _helper(writer: PlanWriter, block: list[Statement], computed: list[str], names: set[str]) -> Function:
    t = writer.ctype
    base = f"symrot_{writer.header}__coefficients_{'_'.join(name[2:] for name in computed)}"
    name, k = f"{base}{writer.suffix}", 1
    while name in names:  # the same coefficients computed differently (another function's plan)
        k += 1
        name = f"{base}_{k}{writer.suffix}"
    names.add(name)
    takes_d = re.search(r"\bd\b", repr(block)) is not None and writer.plan.complement is not None
    parameters = [f"{t} x", *([f"{t} d"] if takes_d else []), *(f"{t} *{c}_out" for c in computed)]
    lets = {s["name"] for s in block if s["kind"] == "let"}
    # a coefficient the block leaves in a const local (Algebraic) or a declared one (Branch)
    stores = [{"kind": "set", "name": f"*{c}_out", "value": c, "ops": 0} for c in computed]
    assert all(c in lets or any(c in s.get("names", []) for s in block) for c in computed)
    statements = [*block, *stores]
    return {"c_name": name, "summary": f"internal: the coefficients {', '.join(c[2:] for c in computed)} "
            "of x, shared by the functions that need them", "equation": "11",
            "notes": ["The same statements in every caller: computed once here, called where needed."],
            "ops": ops_of(statements), "signature": f"void {name}({', '.join(parameters)})",
            "statements": statements, "batch_signature": None, "output": None, "takes_d": takes_d}


__all__ = ["printed_lines", "share_coefficients"]
