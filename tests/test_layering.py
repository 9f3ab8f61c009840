"""Imports run one way: core → plan → backends → API/CLI, with the audit beside plan and backends.

Every module of ``symrot`` belongs to the layer of its folder (symrot/core, plan, backends, audit,
cli; the few modules at the top are the public face; see docs/architecture.md). The test reads each
module's source with :mod:`ast`, so it sees every import: at the top, inside functions (lazy) and
under ``if TYPE_CHECKING:``. It fails when a module imports from a layer its own layer may not
use, when an import cycle joins modules of different layers and, stricter, on any import cycle.
Imports by name at run time (``importlib.import_module`` in ``symrot.backends.emitter``) are not
seen; they stay within the backends.
"""

from __future__ import annotations

import ast
from pathlib import Path

import symrot

PACKAGE = Path(symrot.__file__).parent

LAYER_OF_FOLDER: dict[str, str] = {
    # the folder of symrot/ a module lives in is its layer; the top of the package is the public face
    "core": "core",
    "plan": "plan",
    "backends": "backends",
    "audit": "audit",
    "cli": "app",
}
TOP_LEVEL = {"__init__", "__main__", "api", "entry", "generate", "kernels_api"}
"""The public face: the only modules directly in symrot/ (issue 56: at most 8)."""
MAY_IMPORT: dict[str, set[str]] = {
    "core": {"core"},
    "plan": {"core", "plan"},
    "backends": {"core", "plan", "backends"},
    "audit": {"core", "audit"},
    "app": {"core", "plan", "backends", "audit", "app"},
}
KNOWN_UPWARD: set[tuple[str, str]] = set()
"""Arrows that run the wrong way and are accepted for now (none)."""


def module_name(path: Path) -> str:
    parts = path.relative_to(PACKAGE.parent).with_suffix("").parts
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


MODULES: dict[str, Path] = {module_name(path): path for path in sorted(PACKAGE.rglob("*.py"))}


def layer(module: str) -> str:
    """The layer of a module: the folder of symrot/ it lives in (app at the top)."""
    parts = module.split(".")
    if len(parts) == 1 or (len(parts) == 2 and parts[1] in TOP_LEVEL):
        return "app"
    if parts[1] not in LAYER_OF_FOLDER:
        raise AssertionError(f"{module} is in no layer's folder: {sorted(LAYER_OF_FOLDER)} or the top")
    return LAYER_OF_FOLDER[parts[1]]


def imports(module: str) -> set[str]:
    """The ``symrot`` modules ``module`` imports anywhere in its source (``from a import b``
    counts as importing ``a.b`` when that is a module, else ``a``)."""
    path = MODULES[module]
    package = module if path.name == "__init__.py" else module.rpartition(".")[0]
    found: set[str] = set()
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.Import):
            found.update(alias.name for alias in node.names)
        elif isinstance(node, ast.ImportFrom):
            base = node.module or ""
            if node.level:  # relative: from . import x, from ..plan import y
                parts = package.split(".")
                base = ".".join([*parts[:len(parts) - node.level + 1], *filter(None, [node.module])])
            for alias in node.names:
                found.add(f"{base}.{alias.name}" if f"{base}.{alias.name}" in MODULES else base)
    return {name for name in found if name in MODULES and name != module}


GRAPH: dict[str, set[str]] = {module: imports(module) for module in MODULES}


def test_every_module_has_a_layer() -> None:
    for module in MODULES:
        assert layer(module) in MAY_IMPORT


def test_the_top_of_the_package_is_only_the_public_face() -> None:
    top = {path.stem for path in PACKAGE.glob("*.py")}
    assert top == TOP_LEVEL and len(top) <= 8
    folders = {path.name for path in PACKAGE.iterdir()
               if path.is_dir() and not path.name.startswith(("_", "."))}
    assert folders == set(LAYER_OF_FOLDER)


def test_no_module_is_too_long_to_read_in_one_sitting() -> None:
    """Issue 56: no module over ~500 lines (600 at most)."""
    long = {module: lines for module, path in MODULES.items()
            if (lines := len(path.read_text(encoding="utf-8").splitlines())) > 600}
    assert not long, long


def test_no_module_imports_a_layer_above_it() -> None:
    upward = sorted((module, target) for module, targets in GRAPH.items() for target in targets
                    if layer(target) not in MAY_IMPORT[layer(module)])
    unexpected = [f"{m} ({layer(m)}) imports {t} ({layer(t)})" for m, t in upward
                  if (m, t) not in KNOWN_UPWARD]
    assert not unexpected, "\n".join(unexpected)
    stale = KNOWN_UPWARD - set(upward)
    assert not stale, f"KNOWN_UPWARD lists arrows that are gone, delete them: {sorted(stale)}"


def strongly_connected(graph: dict[str, set[str]]) -> list[set[str]]:
    """Tarjan's algorithm: the import cycles, as sets of modules."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    components: list[set[str]] = []

    def visit(node: str) -> None:
        index[node] = low[node] = len(index)
        stack.append(node)
        for target in graph[node]:
            if target not in index:
                visit(target)
                low[node] = min(low[node], low[target])
            elif target in stack:
                low[node] = min(low[node], index[target])
        if low[node] == index[node]:
            position = stack.index(node)
            components.append(set(stack[position:]))
            del stack[position:]

    for node in sorted(graph):
        if node not in index:
            visit(node)
    return [c for c in components if len(c) > 1]


CYCLES = strongly_connected({module: {t for t in targets if (module, t) not in KNOWN_UPWARD}
                              for module, targets in GRAPH.items()})


def test_no_import_cycle_spans_two_layers() -> None:
    mixed = [sorted(cycle) for cycle in CYCLES if len({layer(m) for m in cycle}) > 1]
    assert not mixed, f"import cycles across layers: {mixed}"


def test_no_import_cycle() -> None:
    """Stricter than the rule between layers: modules of one layer do not import each other in a
    circle either (shared code goes into a module below both, as c_writer, plan_ir, audit.records)."""
    assert not CYCLES, f"import cycles: {[sorted(cycle) for cycle in CYCLES]}"


def test_bench_has_no_import_cycle() -> None:
    """Issue 56: the drivers of bench/ import shared code below them, never each other in a circle."""
    bench = PACKAGE.parent / "bench"
    local = {path.stem: path for path in bench.glob("*.py")}
    graph: dict[str, set[str]] = {}
    for name, path in local.items():
        found: set[str] = set()
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if isinstance(node, ast.ImportFrom) and node.module and not node.level:
                found.add(node.module.split(".")[0])
            elif isinstance(node, ast.Import):
                found.update(alias.name.split(".")[0] for alias in node.names)
        graph[name] = {target for target in found if target in local and target != name}

    def reaches(start: str, goal: str) -> bool:
        seen, todo = set(), [start]
        while todo:
            node = todo.pop()
            if node == goal:
                return True
            if node not in seen:
                seen.add(node)
                todo.extend(graph[node])
        return False

    circles = sorted(name for name in graph if any(reaches(target, name) for target in graph[name]))
    assert not circles, f"bench/ modules in an import cycle: {circles}"


def test_every_public_name_resolves() -> None:
    """The public face (issue 56: unchanged by the move): every name of ``symrot.__all__`` imports."""
    assert all(getattr(symrot, name) is not None for name in symrot.__all__)
