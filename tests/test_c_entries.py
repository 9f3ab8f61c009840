"""Issue 56: entries that several C functions of a header compute alike but for the names they read
are printed once, as a helper each calls with its own names (symrot/backends/c_entries.py)."""

from __future__ import annotations

import re
from pathlib import Path
from types import SimpleNamespace
from typing import Any

import pytest

from symrot.backends.c_backend import COVERED
from symrot.backends.c_entries import SHORTEST, share_entries

GENERATED = Path(__file__).resolve().parent.parent / "generated" / "c"
WRITER: Any = SimpleNamespace(header="demo", suffix="")


def _let(name: str, value: str) -> dict[str, Any]:
    return {"kind": "let", "type": "double", "name": name, "value": value, "ops": 1}


def _set(name: str, value: str) -> dict[str, Any]:
    return {"kind": "set", "name": name, "value": value, "ops": 0}


def _function(name: str, tensor: str, output: str, rows: int = 9) -> dict[str, Any]:
    """x, the coefficients of ``tensor`` (c_T_1, c_T_2), then entries reading them and p."""
    statements = [_let("x", "p[0]*p[0] + p[1]*p[1] + p[2]*p[2]"),
                  {"kind": "declare", "type": "double", "names": [f"c_{tensor}_1", f"c_{tensor}_2"]},
                  {"kind": "call", "value": f"coefficients(x, &c_{tensor}_1, &c_{tensor}_2)", "ops": 9}]
    statements += [_let(f"out{i}", f"c_{tensor}_2*p[{i % 3}] + c_{tensor}_1*x*p[{i // 3}]")
                   for i in range(rows)]
    statements += [_set(f"{output}[{i}]", f"out{i}") for i in range(rows)]
    return {"c_name": f"symrot_demo_{name}", "summary": name, "equation": "14", "notes": [], "ops": 50,
            "signature": f"void symrot_demo_{name}(const double p[3], double {output}[9])",
            "statements": statements, "batch_signature": None, "output": output}


def test_tails_alike_but_for_names_become_one_helper_called_with_each_callers_names() -> None:
    functions = [_function("rotation_matrix", "R", "R"), _function("root_matrix", "G", "G")]
    shared = share_entries(functions, WRITER)
    assert [f["c_name"] for f in shared] == ["symrot_demo__matrix_entries", "symrot_demo_rotation_matrix",
                                             "symrot_demo_root_matrix"]
    helper = shared[0]
    assert helper["signature"] == ("void symrot_demo__matrix_entries(double c_1, double c_2, double x, "
                                   "const double p[3], double T[9])")
    assert helper["statements"][0]["value"] == "c_2*p[0] + c_1*x*p[0]"
    assert helper["statements"][-1] == _set("T[8]", "out8")
    assert shared[1]["statements"][-1]["value"] == "symrot_demo__matrix_entries(c_R_1, c_R_2, x, p, R)"
    assert shared[2]["statements"][-1]["value"] == "symrot_demo__matrix_entries(c_G_1, c_G_2, x, p, G)"
    assert shared[1]["statements"][:3] == functions[0]["statements"][:3]
    assert helper["ops"] == sum(s["ops"] for s in functions[0]["statements"][3:])


def test_a_tail_no_other_function_shares_or_too_short_or_on_a_local_array_is_kept() -> None:
    alone = _function("tangent", "H", "H")
    alone["statements"][3] = _let("out0", "c_H_1*p[0]")  # another shape than the others
    short = [_function("rotation_matrix", "R", "R", rows=(SHORTEST - 1) // 2),
             _function("root_matrix", "G", "G", rows=(SHORTEST - 1) // 2)]
    local = [_function("rotation_matrix", "R", "R"), _function("root_matrix", "G", "G")]
    for function in local:
        function["statements"][3] = _let("out0", "q[0]")  # q: not a parameter the helper could take
    for functions in ([alone, _function("rotation_matrix", "R", "R")], short, local):
        assert share_entries(functions, WRITER) == functions


def _bodies(text: str, float_part: bool) -> dict[str, list[str]]:
    """Public single-call functions of one precision: name → the lines of their body."""
    found = re.findall(r"^static inline \w+ (symrot_\w+?)\(.*?\)\n{\n(.*?)\n}\n", text, re.S | re.M)
    return {name: body.splitlines() for name, body in found
            if "__" not in name and not name.endswith("_batch") and name.endswith("_f") == float_part}


def _shape(lines: list[str]) -> list[str]:
    """Lines with every identifier but C's replaced by its place of first use."""
    places: dict[str, str] = {}

    def place(match: re.Match[str]) -> str:
        word = match[0]
        if word in ("const", "double", "float", "return", "NAN", "sqrt", "sqrtf"):
            return word
        return places.setdefault(word, f"n{len(places)}")

    return [re.sub(r"(?<![\w.])[A-Za-z_]\w*", place, line) for line in lines]


@pytest.mark.parametrize("name", COVERED)
@pytest.mark.parametrize("float_part", [False, True])
def test_no_two_functions_of_one_precision_end_with_the_same_entries(name: str, float_part: bool) -> None:
    """From the header's text: the last SHORTEST lines of the public single-call functions of one
    precision, with names replaced by places, differ pairwise where those lines hold no call."""
    text = (GENERATED / f"symrot_{name}.h").read_text(encoding="utf-8")
    tails: dict[tuple[str, ...], str] = {}
    for function, lines in _bodies(text, float_part).items():
        tail = lines[-SHORTEST:]
        if len(lines) < SHORTEST or any(re.search(r"\w\(|[{}]", line) for line in tail):
            continue
        key = tuple(_shape(tail))
        assert key not in tails, f"{function} ends as {tails[key]} does"
        tails[key] = function


def test_the_rotation_vector_derivatives_of_r_and_h_and_their_transposes_share_their_entries() -> None:
    """R and H of the rotation vector have the same shape (c0 = 1): d(R a)/dp, d(Rᵀ a)/dp, d(H a)/dp
    and d(Hᵀ a)/dp are one helper, called with c_R_…, c_R_T_… (c1 negated), c_H_…, c_H_T_…."""
    text = (GENERATED / "symrot_rotation_vector.h").read_text(encoding="utf-8")
    for suffix in ("", "_f"):
        helper = f"symrot_rotation_vector__derivative_entries{suffix}"
        calls = re.findall(rf"^    {helper}\((c_\w+?)_1, .*, D\);$", text, re.M)
        assert calls == ["c_R", "c_R_T", "c_H", "c_H_T"], calls


@pytest.mark.parametrize("name", COVERED)
def test_a_transposed_derivative_calls_the_helper_of_the_plain_one(name: str) -> None:
    """d(Tᵀ a)/dp is d(T a)/dp with c1 and c1′ negated: both call one helper, except where c1 or
    c1′ is a nonzero constant (folded into the printed numbers, so Tᵀ's differ from T's)."""
    text = (GENERATED / f"symrot_{name}.h").read_text(encoding="utf-8")
    shared = 0
    for tensor, letter in (("rotation", "R"), ("tangent", "H")):
        for suffix in ("", "_f"):
            pattern = rf"^/\* symrot_{name}_{tensor}_derivative{suffix}:(.*?)\*/\n"
            comment = re.search(pattern, text, re.S | re.M)
            assert comment
            if re.search(rf"^ \* {letter}_1(_x)? = (?!0 )\S+ \(constant\)", comment[1], re.M):
                continue
            called = []
            for function in (f"{tensor}_derivative", f"{tensor}_transpose_derivative"):
                pattern = rf"^static inline void symrot_{name}_{function}{suffix}\(.*?^}}"
                body = re.search(pattern, text, re.S | re.M)
                assert body, function
                called.append(re.findall(r"^    (symrot_\w+__\w+)\(", body[0], re.M)[-1])
            assert called[0] == called[1] and called[0].endswith(f"derivative_entries{suffix}"), called
            shared += 1
    assert shared >= 2, shared  # at least R or H in both precisions


def _batch(output: str, tensor: str, entries: list[str]) -> list[dict[str, Any]]:
    """A ``_batch`` kernel's outer loop whose last loop (the assembly) prints ``entries``."""
    assembly = [{"kind": "let", "type": "const double *const", "name": "pk", "value": "p + 3 * (start + k)"},
                *({"kind": "let", "type": "double", "name": f"p{i}", "value": f"pk[{i}]"} for i in range(3)),
                {"kind": "declare", "type": "double *const", "names": [f"out = {output} + 9 * (start + k)"]},
                *(_set(f"out[{i}]", entry) for i, entry in enumerate(entries))]
    return [{"kind": "declare", "type": "size_t", "names": ["end", "start", "k"]},
            {"kind": "loop", "header": "end = n; end > 0; end = start", "times": 1, "body": [
                {"kind": "comment", "text": f"the passes of {tensor}"},
                {"kind": "loop", "header": "k = m; k-- > 0;", "times": 1, "body": assembly}]}]


def test_a_batch_kernel_whose_entries_are_the_helpers_on_the_lanes_calls_it() -> None:
    functions = [_function("rotation_matrix", "R", "R"), _function("root_matrix", "G", "G")]
    lanes = [f"c_R_2_lanes[k]*p{i % 3} + c_R_1_lanes[k]*x_lanes[k]*p{i // 3}" for i in range(9)]
    functions[0]["batch_statements"] = _batch("R", "R", lanes)
    other = [*lanes[:8], "c_R_2_lanes[k]*p2"]  # one entry another shape: the kernel keeps its own
    functions[1]["batch_statements"] = _batch("G", "G", other)
    shared = share_entries(functions, WRITER)
    calling = shared[1]["batch_statements"][-1]["body"][-1]["body"]
    assert [s["kind"] for s in calling] == ["let", "call"] and calling[0]["name"] == "pk"
    assert calling[1]["value"] == ("symrot_demo__matrix_entries(c_R_1_lanes[k], c_R_2_lanes[k], x_lanes[k], "
                                   "pk, R + 9 * (start + k))")
    assert shared[2]["batch_statements"] == functions[1]["batch_statements"]
