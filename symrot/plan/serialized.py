"""A versioned JSON form of an evaluation plan (:mod:`symrot.plan.ir`) that cannot run code when read.

:func:`encode_plan` turns an :class:`~symrot.plan.ir.EvaluationPlan` into canonical JSON bytes and
:func:`decode_plan` rebuilds exactly the same plan from them: the decoded plan equals the original
(dataclass equality, SymPy's structural equality) and every backend prints it byte for byte the
same. It is the on-disk format of :mod:`symrot.cli.plan_cache`.

Reading is safe whatever the bytes: nothing is ever evaluated, unpickled or parsed by SymPy.
Decoding only calls the constructors of a fixed set of classes:

* the IR's dataclasses (:data:`DATACLASSES`), with exactly their fields;
* Python values: ``None``, bool, int, str, float (exactly, as ``float.hex``, so ±inf and NaN too),
  NumPy's float64/float32 scalars (kept as such), tuples and dicts with string keys;
* SymPy expressions as a table of nodes, each referring only to nodes before it (a DAG: shared
  subexpressions are stored once, and decoding needs no recursion): the IR's symbols by name
  (:data:`SYMBOLS`), ``Integer``, ``Rational`` as p/q in lowest terms, ``Float`` exactly (its mpf
  tuple and precision), ``Add``, ``Mul``, ``Pow`` and the functions of :data:`FUNCTIONS` (built
  with ``evaluate=False``, so that their arguments stay as they were), and the constants of
  :data:`CONSTANTS`.

Anything else (an unknown tag, node or symbol, a reference forward, a field too many or too few,
a non-canonical number) raises :class:`PlanFormatError`. Decoding ends by encoding the result
again and comparing: a payload is accepted only if it is exactly what :func:`encode_plan` writes
for the plan it describes.
"""

from __future__ import annotations

import dataclasses
import json
import math
from typing import Any

import numpy as np
import sympy as sp

from symrot.core.functions import BoundedPower, RealCbrt
from symrot.core.parsing import PHI
from symrot.plan.algebraic import D, S, X
from symrot.plan.ir import (
    Algebraic,
    Branch,
    ClosedAngle,
    Constant,
    EvaluationPlan,
    NewtonAngle,
    PrecisionPlan,
    QuaternionScale,
)
from symrot.plan.newton_start import FarStart
from symrot.plan.quaternion import E0

PAYLOAD_FORMAT = "symrot-plan-ir"
PAYLOAD_VERSION = 1
"""Raised whenever the encoding changes; a payload of another version is refused."""

DATACLASSES: dict[str, type] = {cls.__name__: cls for cls in (
    EvaluationPlan, PrecisionPlan, Constant, Algebraic, Branch, ClosedAngle, NewtonAngle, FarStart,
    QuaternionScale,
)}
"""The IR classes a payload may build, by name."""

SYMBOLS: dict[str, sp.Symbol] = {symbol.name: symbol for symbol in (PHI, S, X, D, E0)}
"""The only symbols of the IR (with their assumptions): φ, s = |p|, x = |p|², d = p_max² − x, e₀."""

FUNCTIONS: dict[str, type[sp.Function]] = {cls.__name__: cls for cls in (
    sp.sin, sp.cos, sp.tan, sp.cot, sp.sec, sp.csc, sp.asin, sp.acos, sp.atan, sp.acot, sp.atan2,
    sp.sinh, sp.cosh, sp.tanh, sp.asinh, sp.acosh, sp.atanh, sp.exp, sp.log, sp.Abs, sp.sign,
    RealCbrt, BoundedPower,
)}
"""Function applications a payload may build, by class name."""

CONSTANTS: dict[str, sp.Expr] = {
    "pi": sp.pi, "E": sp.E, "oo": sp.oo, "-oo": sp.S.NegativeInfinity, "nan": sp.nan, "zoo": sp.zoo,
}

_OPERATIONS: dict[str, type[sp.Expr]] = {"Add": sp.Add, "Mul": sp.Mul, "Pow": sp.Pow}
_NUMPY_SCALARS: dict[str, type[np.floating[Any]]] = {"float64": np.float64, "float32": np.float32}


class PlanFormatError(ValueError):
    """The bytes are not a payload :func:`encode_plan` writes (or hold something it cannot write)."""


def canonical_json(value: Any) -> bytes:
    """The one serialization used for payloads: sorted keys, no spaces, ASCII, no bare NaN."""
    return json.dumps(value, sort_keys=True, separators=(",", ":"), ensure_ascii=True,
                      allow_nan=False).encode("ascii")


class _ExpressionTable:
    """SymPy expressions as a list of nodes; equal nodes (by their encoding) are stored once."""

    def __init__(self) -> None:
        self.nodes: list[list[Any]] = []
        self._index_of_node: dict[str, int] = {}
        self._index_of_object: dict[int, tuple[sp.Basic, int]] = {}

    def add(self, expression: sp.Basic) -> int:
        """The index of ``expression``'s node (children first, so references only point back)."""
        known = self._index_of_object.get(id(expression))
        if known is not None and known[0] is expression:
            return known[1]
        node = self._node(expression)
        key = json.dumps(node, separators=(",", ":"))
        index = self._index_of_node.get(key)
        if index is None:
            index = self._index_of_node[key] = len(self.nodes)
            self.nodes.append(node)
        self._index_of_object[id(expression)] = (expression, index)
        return index

    def _node(self, expression: sp.Basic) -> list[Any]:
        if isinstance(expression, sp.Symbol):
            if SYMBOLS.get(expression.name) != expression:
                raise PlanFormatError(f"not a symbol of the plan IR: {expression!r}")
            return ["Symbol", expression.name]
        if isinstance(expression, sp.Integer):
            return ["Integer", int(expression)]
        if isinstance(expression, sp.Rational):
            return ["Rational", int(expression.p), int(expression.q)]
        if isinstance(expression, sp.Float):
            sign, mantissa, exponent, bits = expression._mpf_
            return ["Float", int(sign), int(mantissa), int(exponent), int(bits), int(expression._prec)]
        for name, constant in CONSTANTS.items():
            if expression is constant:
                return ["Constant", name]
        kind = type(expression)
        if kind in _OPERATIONS.values() or FUNCTIONS.get(kind.__name__) is kind:
            name = kind.__name__
        else:
            raise PlanFormatError(f"no JSON form for a {kind.__name__}: {expression}")
        return [name, *(self.add(argument) for argument in expression.args)]


def _decode_expression_node(node: Any, built: list[sp.Basic]) -> sp.Basic:
    """The expression of one node, whose references index ``built`` (the nodes before it)."""
    if not isinstance(node, list) or not node or not isinstance(node[0], str):
        raise PlanFormatError("an expression node is a list that starts with its kind")
    kind, operands = node[0], node[1:]
    if kind == "Symbol":
        if len(operands) != 1 or not isinstance(operands[0], str) or operands[0] not in SYMBOLS:
            raise PlanFormatError(f"unknown symbol {operands!r}")
        return SYMBOLS[operands[0]]
    if kind == "Constant":
        if len(operands) != 1 or not isinstance(operands[0], str) or operands[0] not in CONSTANTS:
            raise PlanFormatError(f"unknown constant {operands!r}")
        return CONSTANTS[operands[0]]
    if kind in ("Integer", "Rational", "Float"):
        if not all(type(operand) is int for operand in operands):
            raise PlanFormatError(f"{kind} takes integers")
        if kind == "Integer" and len(operands) == 1:
            return sp.Integer(operands[0])
        if kind == "Rational" and len(operands) == 2:
            numerator, denominator = operands
            if denominator < 2 or math.gcd(numerator, denominator) != 1:
                raise PlanFormatError("a Rational is stored in lowest terms with q > 1")
            return sp.Rational(numerator, denominator)
        if kind == "Float" and len(operands) == 5:
            sign, mantissa, exponent, bits, precision = operands
            zero = (sign, mantissa, exponent, bits) == (0, 0, 0, 0)
            normalized = sign in (0, 1) and mantissa % 2 == 1 and bits == mantissa.bit_length()
            if not (zero or normalized) or not 1 <= precision <= 100_000:
                raise PlanFormatError("a Float is zero or a normalized mpf")
            return sp.Float._new((sign, mantissa, exponent, bits), precision)
        raise PlanFormatError(f"{kind} with {len(operands)} operands")
    cls = _OPERATIONS.get(kind) or FUNCTIONS.get(kind)
    if cls is None:
        raise PlanFormatError(f"unknown expression node {kind!r}")
    if not operands or not all(type(reference) is int and 0 <= reference < len(built)
                               for reference in operands):
        raise PlanFormatError(f"{kind} refers to nodes that do not precede it")
    arguments = [built[reference] for reference in operands]
    if kind == "Pow" and len(arguments) != 2:
        raise PlanFormatError("Pow takes two arguments")
    return cls(*arguments, evaluate=False)


def _decode_expressions(nodes: Any) -> list[sp.Basic]:
    if not isinstance(nodes, list):
        raise PlanFormatError("the expression table is a list")
    built: list[sp.Basic] = []
    for node in nodes:
        built.append(_decode_expression_node(node, built))
    return built


def _encode_value(value: Any, table: _ExpressionTable) -> Any:
    """A field's value as tagged JSON (every value is a one-key object, or null)."""
    if value is None:
        return None
    if isinstance(value, bool):
        return {"bool": value}
    if isinstance(value, np.floating):
        name = type(value).__name__
        if _NUMPY_SCALARS.get(name) is not type(value):
            raise PlanFormatError(f"no JSON form for NumPy's {name}")
        return {name: float(value).hex()}
    if isinstance(value, float):
        return {"float": value.hex()}
    if isinstance(value, int):
        return {"int": value}
    if isinstance(value, str):
        return {"str": value}
    if isinstance(value, sp.Basic):
        return {"expr": table.add(value)}
    if isinstance(value, tuple):
        return {"tuple": [_encode_value(item, table) for item in value]}
    if isinstance(value, dict):
        if not all(isinstance(key, str) for key in value):
            raise PlanFormatError("dict keys of the IR are strings")
        return {"dict": [[key, _encode_value(item, table)] for key, item in value.items()]}
    if dataclasses.is_dataclass(value) and DATACLASSES.get(type(value).__name__) is type(value):
        return {"dataclass": [type(value).__name__,
                              {field.name: _encode_value(getattr(value, field.name), table)
                               for field in dataclasses.fields(value)}]}
    raise PlanFormatError(f"no JSON form for a {type(value).__name__}")


def _parse_float(text: Any) -> float:
    if not isinstance(text, str):
        raise PlanFormatError("a float is stored as float.hex")
    return float.fromhex(text)


def _decode_value(tagged: Any, expressions: list[sp.Basic]) -> Any:
    """The inverse of :func:`_encode_value`."""
    if tagged is None:
        return None
    if not isinstance(tagged, dict) or len(tagged) != 1:
        raise PlanFormatError("a value is null or an object with one tag")
    ((tag, content),) = tagged.items()
    if tag == "bool" and type(content) is bool:
        return content
    if tag == "int" and type(content) is int:
        return content
    if tag == "str" and type(content) is str:
        return content
    if tag == "float":
        return _parse_float(content)
    if tag in _NUMPY_SCALARS:
        return _NUMPY_SCALARS[tag](_parse_float(content))
    if tag == "expr" and type(content) is int and 0 <= content < len(expressions):
        return expressions[content]
    if tag == "tuple" and isinstance(content, list):
        return tuple(_decode_value(item, expressions) for item in content)
    if tag == "dict" and isinstance(content, list):
        decoded: dict[str, Any] = {}
        for pair in content:
            if not (isinstance(pair, list) and len(pair) == 2 and isinstance(pair[0], str)
                    and pair[0] not in decoded):
                raise PlanFormatError("a dict is a list of distinct [string key, value] pairs")
            decoded[pair[0]] = _decode_value(pair[1], expressions)
        return decoded
    if tag == "dataclass" and isinstance(content, list) and len(content) == 2:
        name, fields = content
        cls = DATACLASSES.get(name) if isinstance(name, str) else None
        if cls is None or not isinstance(fields, dict):
            raise PlanFormatError(f"unknown IR class {name!r}")
        if set(fields) != {field.name for field in dataclasses.fields(cls)}:
            raise PlanFormatError(f"{name} needs exactly its fields")
        return cls(**{key: _decode_value(item, expressions) for key, item in fields.items()})
    raise PlanFormatError(f"unknown or malformed value tagged {tag!r}")


def encode_plan(plan: EvaluationPlan) -> bytes:
    """The canonical JSON payload of ``plan`` (raises :class:`PlanFormatError` for a plan holding
    something outside the whitelist, which then is simply not stored)."""
    if type(plan) is not EvaluationPlan:
        raise PlanFormatError("only an EvaluationPlan is encoded")
    table = _ExpressionTable()
    root = _encode_value(plan, table)
    return canonical_json({"format": PAYLOAD_FORMAT, "version": PAYLOAD_VERSION,
                           "expressions": table.nodes, "plan": root})


def decode_plan(payload: bytes) -> EvaluationPlan:
    """The plan of a payload of :func:`encode_plan`; :class:`PlanFormatError` (or another
    exception of a constructor, for nonsense that got past the checks) for anything else."""
    document = json.loads(payload.decode("ascii"))
    if not (isinstance(document, dict) and set(document) == {"format", "version", "expressions", "plan"}
            and document["format"] == PAYLOAD_FORMAT and document["version"] == PAYLOAD_VERSION):
        raise PlanFormatError(f"not a {PAYLOAD_FORMAT} payload of version {PAYLOAD_VERSION}")
    plan = _decode_value(document["plan"], _decode_expressions(document["expressions"]))
    if type(plan) is not EvaluationPlan:
        raise PlanFormatError("the payload does not hold an EvaluationPlan")
    if encode_plan(plan) != payload:
        raise PlanFormatError("the payload is not the canonical encoding of the plan it holds")
    return plan
