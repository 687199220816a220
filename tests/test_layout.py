"""The package's module graph has no import cycles (issue 12: the old model -> plate ->
assembly -> plate -> model cycle was held together by a function-local import). The graph
is read from the sources: every import between the package's own modules, function-local
ones included (a deferred import is still a dependency); `from . import name` of a name
that is no module is an import of the package itself. The compiled extension
`ancfdrv._kernel` (no .py file; it imports nothing of the package) is a leaf that only
the thin binding `ancfdrv.kernel` imports."""
from __future__ import annotations

import ast
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1] / "python"
EXTENSION = "ancfdrv._kernel"


def module_graph() -> dict[str, set[str]]:
    files = {}
    for path in (ROOT / "ancfdrv").rglob("*.py"):
        parts = path.relative_to(ROOT).with_suffix("").parts
        name = ".".join(parts[:-1] if parts[-1] == "__init__" else parts)
        files[name] = path
    modules = set(files) | {EXTENSION}
    graph: dict[str, set[str]] = {name: set() for name in modules}
    for name, path in files.items():
        package = name if path.name == "__init__.py" else name.rpartition(".")[0]
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, ast.ImportFrom):
                base = package.split(".")[:len(package.split(".")) - node.level + 1] \
                    if node.level else []
                target = ".".join(base + ([node.module] if node.module else []))
                for alias in node.names:
                    full = f"{target}.{alias.name}"
                    if full in modules:
                        graph[name].add(full)
                    elif target in modules:
                        graph[name].add(target)
            elif isinstance(node, ast.Import):
                graph[name] |= {a.name for a in node.names if a.name in modules}
    return graph


def cycles(graph: dict[str, set[str]]) -> list[list[str]]:
    found, state = [], {}

    def visit(node: str, path: list[str]) -> None:
        state[node] = "open"
        for nxt in sorted(graph[node]):
            if state.get(nxt) == "open":
                found.append(path[path.index(nxt):] + [nxt])
            elif nxt not in state:
                visit(nxt, path + [nxt])
        state[node] = "done"

    for node in sorted(graph):
        if node not in state:
            visit(node, [node])
    return found


def test_graph_is_read():
    graph = module_graph()
    assert "ancfdrv.system.assembly" in graph["ancfdrv.system"] or \
        "ancfdrv.system.system" in graph["ancfdrv.system"]
    assert "ancfdrv.system.model" in graph["ancfdrv.system.assembly"]


def test_no_import_cycles():
    assert cycles(module_graph()) == []


def test_only_the_binding_imports_the_compiled_kernel():
    graph = module_graph()
    assert {name for name, targets in graph.items() if EXTENSION in targets} == {"ancfdrv.kernel"}


def test_no_module_imports_the_package_itself():
    """A layer imports only below itself: nothing inside the package imports `ancfdrv`
    (its __init__ re-exports the system API and so sits above everything)."""
    graph = module_graph()
    assert {name for name, targets in graph.items() if "ancfdrv" in targets} == set()


def test_cycle_detection_finds_a_cycle():
    assert cycles({"a": {"b"}, "b": {"c"}, "c": {"a"}}) == [["a", "b", "c", "a"]]
