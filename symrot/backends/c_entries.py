"""One helper for the entries that several functions of a header compute alike but for names.

After its coefficients, a function of a header ends with the same kind of statements: the entries
of T = c0 I + c1 (p×) + c2 (p×)² for ``rotation_matrix``, ``tangent``, ``root_matrix`` …, those of
∂(T a)/∂p for the five derivatives (:mod:`symrot.backends.c_derivatives`), those of T v for
``pdot`` and ``omega``. Where two or more functions of one precision end with statements that
differ only in the names of what they read (``c_R_1`` or ``c_H_1``; ``R`` or ``H``), that tail
becomes one ``static inline`` helper ``symrot_NAME__<shape>(coefficients…, arrays…)``, and each
function calls it with its own names. The helper runs the very statements the functions ran, in the
same order, on the same values, so results are bit-identical (at ``-ffp-contract=off``, and
wherever the compiler treats an inlined call like its body); its ``ops`` are counted into each
caller as before. A tail keeps the in-place guarantee of :mod:`symrot.backends.c_aliasing`: it
reads every input before it stores.
"""

from __future__ import annotations

import re
from typing import Any

from symrot.backends.c_shared import printed_lines
from symrot.backends.c_statements import PlanWriter, Statement, ops_of

Function = dict[str, Any]
SHORTEST = 12
"""Lines a tail must print to be shared: a shorter one is cheaper to repeat than to call."""
IDENTIFIER = re.compile(r"(?<![\w.])([A-Za-z_]\w*)(\s*[\[(])?")
ARRAY_PARAMETER = re.compile(r"(const )?(double|float) (\w+)\[(\d+)\]")
COEFFICIENT = re.compile(r"c_\w+?_((?:\d|across)(?:_x)?)")
"""A coefficient or its slope of any tensor (R, H, H_inverse, R_T …): c_R_1, c_H_inverse_across, c_R_T_2_x."""
MACRO = re.compile(r"[A-Z][A-Z0-9_]+")
KEYWORDS = frozenset({"double", "float", "int", "const", "return", "if", "else", "for", "size_t"})
SHAPE_LABELS: dict[tuple[tuple[str, int], ...], str] = {(("p", 3), ("T", 9)): "tensor_entries"}
"""Names of helpers whose callers share no last word (rotation_matrix, tangent, root_matrix)."""


def _tail_start(statements: list[Statement]) -> int:
    """Where the entries begin: the longest run of top-level ``let``/``set``/``comment``
    statements at the end that defines no coefficient (``c_…``, the plan's values, and ``t`` =
    c0 − c2 x, the diagonal term that an across form has as a coefficient of its own)."""
    start = len(statements)
    while start > 0:
        statement = statements[start - 1]
        if statement["kind"] not in ("let", "set", "comment"):
            break
        name = statement.get("name", "")
        if name.startswith("c_") or name == "t":
            break
        start -= 1
    return start


def _reads(text: str) -> list[tuple[str, bool]]:
    """Identifiers ``text`` reads, in order, each with whether it is indexed (an array); calls,
    keywords and macros (upper case) left out."""
    found = []
    for name, after in IDENTIFIER.findall(text):
        indexed = (after or "").strip() == "["
        if name in KEYWORDS or (MACRO.fullmatch(name) and not indexed) or (after or "").strip() == "(":
            continue
        found.append((name, indexed))
    return found


def _free(tail: list[Statement]) -> tuple[list[str], list[str]] | None:
    """The scalars and the arrays ``tail`` reads or writes but does not define, in order of first
    use; None where a name is used both ways."""
    defined: set[str] = set()
    scalars: list[str] = []
    arrays: list[str] = []
    for statement in tail:
        if statement["kind"] == "comment":
            continue
        target = statement["name"]
        for name, indexed in [*_reads(statement["value"]), *(_reads(target) if "[" in target else [])]:
            if name in defined:
                continue
            chosen = arrays if indexed else scalars
            if name not in chosen:
                chosen.append(name)
        if statement["kind"] == "let":
            defined.add(target)
    if set(scalars) & set(arrays):
        return None
    return scalars, arrays


def _rename(tail: list[Statement], names: dict[str, str]) -> list[Statement]:
    def sub(text: str) -> str:
        return IDENTIFIER.sub(lambda m: names.get(m[1], m[1]) + (m[2] or ""), text)

    renamed = []
    for statement in tail:
        changed = dict(statement)
        if statement["kind"] != "comment":
            changed["value"] = sub(statement["value"])
            changed["name"] = sub(statement["name"]) if "[" in statement["name"] else statement["name"]
        renamed.append(changed)
    return renamed


def _canonical(function: Function) -> tuple[str, list[str], list[str], list[tuple[bool, str, int]]] | None:
    """The key of a function's tail (its statements with every free name replaced by its place),
    the free scalars, the free arrays, and each array's (const, type, size) from the signature."""
    statements = function.get("statements")
    if not statements:
        return None
    start = _tail_start(statements)
    tail = statements[start:]
    if printed_lines(tail) < SHORTEST or not any(s["kind"] == "set" and "[" in s["name"] for s in tail):
        return None
    free = _free(tail)
    if free is None:
        return None
    scalars, arrays = free
    parameters = {name: (bool(const), ctype, int(size))
                  for const, ctype, name, size in ARRAY_PARAMETER.findall(function["signature"])}
    if any(name not in parameters for name in arrays):
        return None  # a local array: not a parameter the helper could take
    arrays = [name for name in parameters if name in arrays]  # in the order of the signature
    places = {**{name: f"k{i}" for i, name in enumerate(scalars)},
              **{name: f"v{i}" for i, name in enumerate(arrays)}}
    key = repr([(parameters[name]) for name in arrays]) + repr(_rename(tail, places))
    return key, scalars, arrays, [parameters[name] for name in arrays]


def _common_name(names: list[str], taken: set[str], fallback: str, scalar: bool = True) -> str:
    """One parameter name for what the callers call ``names``: theirs where they agree, else what
    they share at the start and end (``c_R_1_x``, ``c_H_T_1_x`` → ``c_1_x``), else the first that
    names no tensor's coefficient (``t`` for ``t`` and ``c_H_across``), else ``fallback``."""
    coefficients = {match[1] if (match := COEFFICIENT.fullmatch(name)) else "" for name in names}
    if len(set(names)) == 1:
        name = names[0]
    elif len(coefficients) == 1 and "" not in coefficients:  # c_R_1_x, c_R_T_1_x, c_H_1_x
        name = f"c_{coefficients.pop()}"
    else:
        prefix = names[0]
        suffix = names[0]
        for other in names[1:]:
            while not other.startswith(prefix):
                prefix = prefix[:-1]
            while not other.endswith(suffix):
                suffix = suffix[1:]
        name = re.sub(r"_+", "_", prefix + suffix).strip("_")
        if (prefix.startswith("c_") and not name.startswith("c_")) or not name:
            name = next((n for n in names if scalar and not n.startswith("c_")), "")
    if not re.fullmatch(r"[A-Za-z_]\w*", name) or name in taken or name in KEYWORDS:
        name = fallback
    return name


def share_entries(functions: list[Function], writer: PlanWriter) -> list[Function]:
    """``functions`` (one precision, in header order) with every tail that two or more of them end
    with alike replaced by a call, each helper placed before its first caller."""
    found = {id(f): _canonical(f) for f in functions}
    groups: dict[str, list[Function]] = {}
    for function in functions:
        canonical = found[id(function)]
        if canonical is not None:
            groups.setdefault(canonical[0], []).append(function)
    placed: dict[str, Function] = {}
    labels: dict[str, int] = {}
    result: list[Function] = []
    for function in functions:
        canonical = found[id(function)]
        if canonical is None or len(groups[canonical[0]]) < 2:
            result.append(function)
            continue
        key, scalars, arrays, _ = canonical
        if key not in placed:
            placed[key] = _helper(groups[key], found, labels, writer)
            result.append({k: v for k, v in placed[key].items() if k != "order"})
        helper = placed[key]
        statements = function["statements"]
        arguments = [*(scalars[i] for i in helper["order"]), *arrays]
        call = {"kind": "call", "value": f"{helper['c_name']}({', '.join(arguments)})", "ops": helper["ops"]}
        changed = {**function, "statements": [*statements[:_tail_start(statements)], call]}
        if function.get("batch_statements"):
            changed["batch_statements"] = _batch_calling(function["batch_statements"], helper,
                                                         [scalars[i] for i in helper["order"]])
        result.append(changed)
    return result


def _entries_of(helper: Function) -> list[str] | None:
    """The expression of each output entry of a tensor helper (``T[i]``, in order), or None where
    its body computes anything else first."""
    lets = {s["name"]: s["value"] for s in helper["statements"] if s["kind"] == "let"}
    stores = [s for s in helper["statements"] if s["kind"] == "set"]
    if len(stores) != 9 or any(s["name"] != f"T[{i}]" for i, s in enumerate(stores)):
        return None
    values = [lets.get(s["value"], s["value"]) for s in stores]
    if len(lets) != sum(s["value"] in lets for s in stores):
        return None  # a let that is not an entry (a subexpression)
    return values


def _batch_calling(batch: list[Statement], helper: Function, scalars: list[str]) -> list[Statement]:
    """A ``_batch`` kernel whose assembly loop calls the tensor helper of its single call, where the
    entries it prints are the helper's on the lanes (``c_R_1`` → ``c_R_1_lanes[k]``, ``p[0]`` →
    ``p0``): the same operations on the same values. Otherwise the kernel as it was. The helper
    reads p before it writes T, so vector k = 0 of an in-place call (out at pk) stays right."""
    entries = _entries_of(helper)
    outer = batch[-1]
    assembly = outer["body"][-1] if outer["kind"] == "loop" else None
    if entries is None or assembly is None or assembly["kind"] != "loop":
        return batch
    body = assembly["body"]
    lets = {s["name"] for s in body if s["kind"] == "let"}
    arguments = [name if name in lets else "x_lanes[k]" if name == "x" else f"{name}_lanes[k]"
                 for name in scalars]
    parameters = re.findall(r"\w+ (\w+)(?:\[\d+\])?(?:, |\)$)", helper["signature"])
    places = dict(zip(parameters, [*arguments, "pk", "out"], strict=True))
    places.update({f"p[{i}]": f"p{i}" for i in range(3)})
    pattern = re.compile(r"p\[\d\]|(?<![\w.])[A-Za-z_]\w*")
    printed = [pattern.sub(lambda m: places.get(m[0], m[0]), entry) for entry in entries]
    sets = [s for s in body if s["kind"] == "set"]
    if [s["value"] for s in sets] != printed:
        return batch
    declared = next(s for s in body if s["kind"] == "declare")
    output = declared["names"][0].split(" = ")[1]
    kept = [s for s in body if s["kind"] == "let" and s["name"] not in ("p0", "p1", "p2")]
    call = {"kind": "call", "value": f"{helper['c_name']}({', '.join([*arguments, 'pk', output])})",
            "ops": helper["ops"]}
    new_assembly = {**assembly, "body": [*kept, call]}
    return [*batch[:-1], {**outer, "body": [*outer["body"][:-1], new_assembly]}]


def _helper(callers: list[Function], found: dict[int, Any], labels: dict[str, int],
            writer: PlanWriter) -> Function:
    first = callers[0]
    _, scalars, arrays, kinds = found[id(first)]
    prefix, suffix = f"symrot_{writer.header}", writer.suffix
    ctype = kinds[0][1]
    statements = first["statements"][_tail_start(first["statements"]):]
    tail_locals = {s["name"] for s in statements if s["kind"] == "let"}
    taken = set(tail_locals)
    names: dict[str, str] = {}
    for i, scalar in enumerate(scalars):
        names[scalar] = _common_name([found[id(c)][1][i] for c in callers], taken, f"k{i}")
        taken.add(names[scalar])
    for i, array in enumerate(arrays):
        names[array] = _common_name([found[id(c)][2][i] for c in callers], taken,
                                    "T" if not kinds[i][0] else f"v{i}", scalar=False)
        taken.add(names[array])
    shape = tuple((names[a], size) for a, (_, _, size) in zip(arrays, kinds, strict=True))
    label = _common_words([c["c_name"][len(prefix) + 1:len(c["c_name"]) - len(suffix)] for c in callers])
    label = f"{label}_entries" if label else SHAPE_LABELS.get(shape, "entries")
    labels[label] = labels.get(label, 0) + 1
    numbered = label if labels[label] == 1 else f"{label}_{labels[label]}"
    name = f"{prefix}__{numbered}{suffix}"
    order = sorted(range(len(scalars)), key=lambda i: _natural(names[scalars[i]]))
    parameters = [f"{ctype} {names[scalars[i]]}" for i in order]
    parameters += [f"{'const ' if const else ''}{t} {names[a]}[{size}]"
                   for a, (const, t, size) in zip(arrays, kinds, strict=True)]
    body = _rename(statements, names)
    short = [c["c_name"][len(prefix) + 1:len(c["c_name"]) - len(suffix)] for c in callers]
    return {"c_name": name, "summary": f"internal: the entries that {', '.join(short)} compute alike "
            "from their own coefficients", "equation": first["equation"],
            "notes": ["The same statements in every caller but for the names they read: printed once "
                      "here, called with each caller's names."],
            "ops": ops_of(body), "signature": f"void {name}({', '.join(parameters)})",
            "statements": body, "batch_signature": None, "output": None, "order": order}


def _common_words(names: list[str]) -> str:
    """The words all ``names`` start and end with: ``rotation_derivative`` for
    ``rotation_derivative`` and ``rotation_transpose_derivative``, ``matrix`` for
    ``rotation_matrix`` and ``root_matrix``, ``derivative`` for ``rotation_derivative`` and
    ``tangent_derivative``."""
    split = [name.split("_") for name in names]
    shortest = min(len(words) for words in split)
    first = 0
    while first < shortest and len({words[first] for words in split}) == 1:
        first += 1
    last = 0
    while last < shortest - first and len({words[-1 - last] for words in split}) == 1:
        last += 1
    return "_".join([*split[0][:first], *(split[0][len(split[0]) - last:] if last else [])])


def _natural(name: str) -> list[Any]:
    """``c_1 < c_1_x < c_2 < c_10 < x``: numbers compared as numbers."""
    return [int(part) if part.isdigit() else part for part in re.split(r"(\d+)", name)]


__all__ = ["share_entries"]
