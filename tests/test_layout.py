"""The package's module graph has no import cycles (issue 12: the old model -> plate ->
assembly -> plate -> model cycle was held together by a function-local import). The graph
is read from the sources: every import between the package's own modules, function-local
ones included (a deferred import is still a dependency); `from . import name` of a name
that is no module is an import of the package itself. The compiled extension
`ancfdrv._kernel` (no .py file; it imports nothing of the package) is a leaf that only
the thin binding `ancfdrv.kernel` imports.

Issue 25: the same graph read at package level (a subpackage is one node, a top-level
module another) must follow one order of layers, each importing only layers below it, so
no arrow runs back up and no two packages import each other, function-local imports
included. The reader and checker of scenes (`io`) is a leaf over `errors`."""
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
    # a function-local import is read too (results/hdf5.py imports xdmf inside functions)
    assert "ancfdrv.results.xdmf" in graph["ancfdrv.results.hdf5"]


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


#: the package's layers, bottom first (SPEC section 9; the order read off the imports):
#: a node may import only nodes of a lower layer (or itself). A subpackage is one node;
#: a top-level module another; `ancfdrv` is the package's __init__ (the public API).
LAYERS = [
    {"records"},                    # dataclasses made without compiled source
    {"_version", "errors", "_kernel", "history", "reference", "_lazy", "csr", "gauss",
     "_build_info"},
    {"codes", "interrupt"},
    {"kernel"},                     # the typed binding over the compiled kernel
    {"io"},                         # schema, namelist reader, validation, safe writes
    {"sweep_keys"},
    {"plots"},                      # reads result files with h5py alone
    {"animate"},                    # ancf animate: frames from a result file, drawn by plots
    {"system"},                     # bodies, joints, loads, drives, assembly, Model
    {"solvers"},                    # static, dynamic, modal, buckling
    {"results"},                    # HDF5, XDMF, locks, output paths, the result object
    {"builders"},                   # templates and the general namelist form: Scene -> System
    {"runner", "preview"},          # one scene start to finish; ancf show
    {"analyses", "sweep_exec",      # System.static/simulate/modes/buckling; sweep workers;
     "simulation"},                 # ancfdrv.simulate: a scene run kept in memory
    {"sweep", "scenedoc"},
    {"cli"},
    {"ancfdrv"},
]


def node_of(module: str) -> str:
    parts = module.split(".")
    return parts[1] if len(parts) > 1 else parts[0]


def package_graph() -> dict[str, set[str]]:
    out: dict[str, set[str]] = {}
    for name, targets in module_graph().items():
        here = node_of(name)
        out.setdefault(here, set()).update(node_of(t) for t in targets if node_of(t) != here)
    return out


def upward_arrows(graph: dict[str, set[str]], layers: list[set[str]]) -> list[str]:
    rank = {node: i for i, layer in enumerate(layers) for node in layer}
    return sorted(f"{a} -> {b}" for a, targets in graph.items() for b in targets
                  if rank[b] >= rank[a])


def test_every_package_has_a_layer():
    """A new subpackage or top-level module must be placed in LAYERS."""
    placed = set().union(*LAYERS)
    assert set(package_graph()) - placed == set()


def test_packages_import_only_layers_below():
    """No package imports one of its own layer or above (issue 25: builders <-> io,
    io <-> solvers, io <-> system and solvers <-> system were cycles through
    function-local imports)."""
    assert upward_arrows(package_graph(), LAYERS) == []


def test_no_package_cycles():
    assert cycles(package_graph()) == []


def test_io_is_a_leaf():
    """Parsing and validation import nothing of the package but its errors, its records
    (dataclasses made without compiled source) and the lazy loader (the general scene's builder is registered by builders.general and loaded by
    the name the package gives it, _lazy.load("general_builder"), never imported), and the
    lazy loader imports nothing of the package."""
    graph = package_graph()
    assert graph["io"] <= {"errors", "_lazy", "records"}
    assert not graph.get("_lazy")


def test_package_checks_can_fail():
    """The checks see a back arrow and an unplaced edge (the old io -> builders one)."""
    layers = [{"errors"}, {"io"}, {"builders"}]
    assert upward_arrows({"io": {"builders", "errors"}, "builders": {"io"}}, layers) == \
        ["io -> builders"]
    assert cycles({"io": {"builders"}, "builders": {"io"}}) == [["builders", "io", "builders"]]
