"""In-place calls of the generated C functions (issue 55, item 4).

The header promises that any output array may be the same array as any input array, and that a
``_batch`` kernel's output may start at the address of its p. For every function the header
exports (read from the header text, so that a new function cannot escape), in double and float, for
three parameterizations (Wiener-Milenkovic: closed angle, |phi| < 2 pi; rotation vector: unbounded;
eq 35, det H = 1: Newton angle, fold complement), every output array aliasing every input array
must give the bits of separate buffers, for small, moderate and large (|phi| > pi) rotations;
batch kernels in place with n = 7 (7 vectors of 3 numbers in the buffer of 63).
"""

from __future__ import annotations

import ctypes
import re
import subprocess
from dataclasses import dataclass

import numpy as np
import pytest

from . import c_harness
from .test_c_backend import GENERATED

HEADERS = ("wiener_milenkovic", "rotation_vector", "det_h_one")
FLAGS = (*c_harness.STRICT_C, "-O2", "-fPIC", "-shared")
DTYPE = {"double": np.float64, "float": np.float32}
EXPORTED = re.compile(r"^static inline (\w+) (symrot_\w+)\(([^)]*)\)$", re.MULTILINE)
ARRAY = re.compile(r"^(const )?(double|float) (\w+)\[(\d+)\]$")
POINTER = re.compile(r"^(const )?(double|float) \*(\w+)$")
BATCH_N = 7


@dataclass(frozen=True)
class Argument:
    name: str
    size: int
    """Numbers per call (per vector for a _batch kernel)."""
    output: bool


@dataclass(frozen=True)
class Function:
    header: str
    name: str
    returns: str
    precision: str
    arguments: tuple[Argument, ...]
    batch: bool

    @property
    def short(self) -> str:
        return self.name.removeprefix(f"symrot_{self.header}_")


def exported(header: str) -> list[Function]:
    """The public functions of generated/c/symrot_HEADER.h (not the internal ``symrot_NAME__*``)."""
    text = (GENERATED / f"symrot_{header}.h").read_text(encoding="utf-8")
    functions = []
    for returns, name, parameters in EXPORTED.findall(text):
        if name.startswith(f"symrot_{header}__"):
            continue
        batch = name.endswith("_batch")
        arguments = []
        for parameter in parameters.split(", "):
            if parameter == "size_t n":
                assert batch, name
                continue
            if batch:
                match = POINTER.match(parameter)
                assert match, f"{name}: unexpected parameter {parameter!r}"
                const, precision, argument = match.groups()
                size = 3 if const else 9  # p[3k..3k+2] into OUT[9k..9k+8]
            else:
                match = ARRAY.match(parameter)
                assert match, f"{name}: unexpected parameter {parameter!r}"
                const, precision, argument, size_text = match.groups()
                size = int(size_text)
            arguments.append(Argument(argument, size, not const))
        functions.append(Function(header, name, returns, precision, tuple(arguments), batch))
    return functions


FUNCTIONS = [f for header in HEADERS for f in exported(header)]


def alias_pairs(function: Function) -> list[tuple[str, str]]:
    """(output, input) of every output array over every input array."""
    outputs = [a.name for a in function.arguments if a.output]
    inputs = [a.name for a in function.arguments if not a.output]
    return [(o, i) for o in outputs for i in inputs]


CASES = [(f, pair) for f in FUNCTIONS for pair in alias_pairs(f)]


def wrapper(function: Function) -> str:
    """``double w_NAME(void *const *a, size_t n)``: the function on the buffers a[i], its return
    value as double (0 for void)."""
    t = function.precision
    args = [f"({'' if a.output else 'const '}{t} *)a[{i}]" for i, a in enumerate(function.arguments)]
    if function.batch:
        args.insert(0, "n")
    call = f"{function.name}({', '.join(args)})"
    body = f"{call}; return 0;" if function.returns == "void" else f"return (double){call};"
    return (f"double w_{function.name}(void *const *a, size_t n);\n"
            f"double w_{function.name}(void *const *a, size_t n) {{ (void)n; {body} }}\n")


@pytest.fixture(scope="module")
def library(tmp_path_factory: pytest.TempPathFactory) -> ctypes.CDLL:
    if c_harness.missing_compilers():
        pytest.skip("needs gcc")
    directory = tmp_path_factory.mktemp("aliasing")
    source = directory / "aliasing.c"
    source.write_text("#include <stddef.h>\n" + "".join(f'#include "symrot_{h}.h"\n' for h in HEADERS)
                      + "".join(wrapper(f) for f in FUNCTIONS), encoding="utf-8")
    target = directory / "aliasing.so"
    subprocess.run(["gcc", *FLAGS, "-I", str(GENERATED), str(source), "-o", str(target), "-lm"],
                   check=True, capture_output=True, text=True)
    lib = ctypes.CDLL(str(target))
    for f in FUNCTIONS:
        getattr(lib, f"w_{f.name}").restype = ctypes.c_double
        getattr(lib, f"w_{f.name}").argtypes = [ctypes.POINTER(ctypes.c_void_p), ctypes.c_size_t]
    return lib


ROTATIONS = {"small": 1e-3, "moderate": 0.6, "large": 4.5}
"""|p| of the parameter vectors: polynomial branches, closed forms, |phi| > pi (rescale's other
branch; p(pi) = 4 for Wiener-Milenkovic, pi for the rotation vector)."""
LARGE = {"det_h_one": 3.0}
"""|p| of the large rotation where 4.5 is out of range (eq 35: p(pi) = 2.66, p_max = 3.35)."""


def rotations(header: str) -> dict[str, float]:
    return {**ROTATIONS, "large": LARGE.get(header, ROTATIONS["large"])}
DIRECTIONS = np.array([[0.48, -0.6, 0.64], [-0.36, 0.8, 0.48], [0.6, 0.0, -0.8]])
QUATERNION = np.array([0.5, -0.5, 0.7, 0.1]) / np.linalg.norm([0.5, -0.5, 0.7, 0.1])
VECTORS = {"a": [0.7, -1.3, 0.4], "omega": [0.3, 1.1, -0.9], "pdot": [-0.8, 0.25, 1.5],
           "pddot": [0.45, -0.65, 0.2]}


def call(lib: ctypes.CDLL, function: Function, buffers: list[np.ndarray], n: int = 1) -> float:
    pointers = (ctypes.c_void_p * len(buffers))(*(b.ctypes.data for b in buffers))
    return float(getattr(lib, f"w_{function.name}")(pointers, n))


def inputs(lib: ctypes.CDLL, function: Function, size: float) -> dict[str, np.ndarray]:
    """Values for the input arrays by name: parameter vectors of norm ``size``, a quaternion, the
    rotation matrix of p1, rates and a fixed vector."""
    dtype = DTYPE[function.precision]
    values: dict[str, np.ndarray] = {}
    for index, argument in enumerate(a for a in function.arguments if not a.output):
        if function.batch:
            scales = size * (1 - 0.05 * np.arange(BATCH_N))
            value = (scales[:, None] * DIRECTIONS[np.arange(BATCH_N) % 3]).ravel()
        elif argument.name in ("p", "p1", "p2"):
            value = size * DIRECTIONS[index % 3]
        elif argument.name == "e":
            value = QUATERNION
        elif argument.name == "R":
            rotation = next(f for f in FUNCTIONS if f.header == function.header and not f.batch
                            and f.short.removesuffix("_f") == "rotation_matrix"
                            and f.precision == function.precision)
            value = np.zeros(9, dtype)
            call(lib, rotation, [(size * DIRECTIONS[0]).astype(dtype), value])
        else:
            assert argument.name in VECTORS, f"{function.name}: no test values for input {argument.name}"
            value = np.array(VECTORS[argument.name])
        assert value.size == argument.size * (BATCH_N if function.batch else 1), (function.name, argument)
        values[argument.name] = np.array(value, dtype)
    return values


def run(lib: ctypes.CDLL, function: Function, given: dict[str, np.ndarray],
        alias: tuple[str, str] | None) -> tuple[float, dict[str, np.ndarray]]:
    """The return value and the outputs, from separate buffers or with output alias[0] in the
    buffer of input alias[1] (the input copied there first, room for the output)."""
    n = BATCH_N if function.batch else 1
    dtype = DTYPE[function.precision]
    buffers: dict[str, np.ndarray] = {}
    for argument in function.arguments:
        if argument.output:
            buffers[argument.name] = np.full(argument.size * n, -7.25, dtype)
        else:
            buffers[argument.name] = given[argument.name].copy()
    if alias is not None:
        output, source = alias
        length = max(buffers[output].size, buffers[source].size)
        shared = np.full(length, -7.25, dtype)
        shared[:given[source].size] = given[source]
        buffers[output] = buffers[source] = shared
    status = call(lib, function, [buffers[a.name] for a in function.arguments], n)
    sizes = {a.name: a.size * n for a in function.arguments if a.output}
    return status, {name: buffers[name][:size].copy() for name, size in sizes.items()}


def bits(value: np.ndarray) -> list[int]:
    return value.view(np.uint64 if value.dtype == np.float64 else np.uint32).tolist()


@pytest.mark.parametrize(("function", "pair"), CASES,
                         ids=[f"{f.header}-{f.short}-{o}={i}" for f, (o, i) in CASES])
def test_an_output_in_the_array_of_an_input_gives_the_same_bits(
        library: ctypes.CDLL, function: Function, pair: tuple[str, str]) -> None:
    for label, size in rotations(function.header).items():
        given = inputs(library, function, size)
        expected_status, expected = run(library, function, given, None)
        status, outputs = run(library, function, given, pair)
        assert np.isnan(expected_status) or status == expected_status, label
        output = pair[0]
        assert np.all(np.isfinite(expected[output])), (label, expected[output])  # inside the range
        assert bits(outputs[output]) == bits(expected[output]), (label, outputs[output], expected[output])
        for name, value in expected.items():  # the other outputs of compose_jacobians
            assert bits(outputs[name]) == bits(value), (label, name)


def test_every_exported_function_is_enumerated() -> None:
    """Every public C function of the headers, both precisions, is parsed; each with an output
    array has alias cases, and the others return a scalar of one p (angle, tangent_det)."""
    for header in HEADERS:
        text = (GENERATED / f"symrot_{header}.h").read_text(encoding="utf-8")
        public = {name for name in re.findall(r"^static inline \w+ (symrot_\w+)\(", text, re.MULTILINE)
                  if not name.startswith(f"symrot_{header}__")}
        functions = [f for f in FUNCTIONS if f.header == header]
        assert {f.name for f in functions} == public
        assert 2 * sum(f.precision == "float" for f in functions) == len(functions)
        for function in functions:
            if not alias_pairs(function):
                assert function.returns in ("double", "float") and len(function.arguments) == 1, function.name
        assert "In place: any output array may be the same array as any input array" in text


def test_the_functions_are_right_on_separate_buffers(library: ctypes.CDLL) -> None:
    """The reference of the aliasing cases is a sane value: R(p) is a rotation, finite."""
    for function in FUNCTIONS:
        if function.short.removesuffix("_f") == "rotation_matrix" and not function.batch:
            for size in rotations(function.header).values():
                _, outputs = run(library, function, inputs(library, function, size), None)
                R = outputs["R"].astype(np.float64).reshape(3, 3)
                tolerance = 1e-12 if function.precision == "double" else 1e-5
                assert np.allclose(R @ R.T, np.eye(3), atol=tolerance), (function.name, size)

