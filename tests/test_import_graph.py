"""No import circles in ``olp`` (issue 11).

Every module under ``olp/`` is read with :mod:`ast` (nothing is imported) and its imports become
the edges of a graph. At module level (not inside functions, not under ``if TYPE_CHECKING:``)
the graph of all of ``olp`` has no cycle. The commands have none even counting the imports
inside their functions: they share :mod:`olp.commands.options` and :mod:`olp.commands.common`
and never import each other.
"""

from __future__ import annotations

import ast
from collections.abc import Iterator
from pathlib import Path

OLP = Path(__file__).resolve().parents[1] / "olp"


def module_files() -> dict[str, Path]:
    """Module name -> file, for every module of the ``olp`` package."""
    found = {}
    for path in sorted(OLP.rglob("*.py")):
        parts = list(path.relative_to(OLP.parent).with_suffix("").parts)
        if parts[-1] == "__init__":
            parts.pop()
        found[".".join(parts)] = path
    return found


def _is_type_checking(test: ast.expr) -> bool:
    return (isinstance(test, ast.Name) and test.id == "TYPE_CHECKING") or (
        isinstance(test, ast.Attribute) and test.attr == "TYPE_CHECKING"
    )


def import_nodes(
    body: list[ast.stmt], *, in_functions: bool
) -> Iterator[ast.Import | ast.ImportFrom]:
    """The import statements that run when ``body`` runs (functions' bodies if asked)."""
    for node in body:
        if isinstance(node, ast.Import | ast.ImportFrom):
            yield node
        elif isinstance(node, ast.FunctionDef | ast.AsyncFunctionDef):
            if in_functions:
                yield from import_nodes(node.body, in_functions=True)
        elif isinstance(node, ast.If) and _is_type_checking(node.test):
            yield from import_nodes(node.orelse, in_functions=in_functions)
        else:
            for child in ast.iter_child_nodes(node):
                block = getattr(child, "body", None)
                if isinstance(child, ast.stmt):
                    yield from import_nodes([child], in_functions=in_functions)
                elif isinstance(block, list):  # an except handler, a match case
                    yield from import_nodes(block, in_functions=in_functions)


def imported_modules(name: str, path: Path, known: set[str], *, in_functions: bool) -> set[str]:
    """The ``olp`` modules ``name`` imports: ``from olp.a import b`` is ``olp.a.b`` when that is
    a module, else ``olp.a``; relative imports are resolved."""
    package = name if path.name == "__init__.py" else name.rpartition(".")[0]
    found = set()
    tree = ast.parse(path.read_text(encoding="utf-8"))
    for node in import_nodes(tree.body, in_functions=in_functions):
        if isinstance(node, ast.Import):
            found |= {alias.name for alias in node.names if alias.name in known}
            continue
        base = node.module or ""
        if node.level:
            parent = package.split(".")[: len(package.split(".")) - node.level + 1]
            base = ".".join([*parent, base] if base else parent)
        for alias in node.names:
            module = f"{base}.{alias.name}"
            if module in known:
                found.add(module)
            elif base in known:
                found.add(base)
    return found - {name}


def import_graph(*, in_functions: bool) -> dict[str, set[str]]:
    files = module_files()
    known = set(files)
    return {
        name: imported_modules(name, path, known, in_functions=in_functions)
        for name, path in files.items()
    }


def find_cycle(graph: dict[str, set[str]]) -> list[str] | None:
    """One cycle of ``graph`` as a path (first node repeated at the end), or None."""
    state: dict[str, str] = {}
    stack: list[str] = []

    def visit(node: str) -> list[str] | None:
        state[node] = "open"
        stack.append(node)
        for nxt in sorted(graph.get(node, ())):
            if state.get(nxt) == "open":
                return [*stack[stack.index(nxt) :], nxt]
            if nxt not in state and (cycle := visit(nxt)) is not None:
                return cycle
        state[node] = "done"
        stack.pop()
        return None

    for node in sorted(graph):
        if node not in state and (cycle := visit(node)) is not None:
            return cycle
    return None


def test_the_cycle_finder_finds_a_cycle() -> None:
    graph = {"a": {"b"}, "b": {"c"}, "c": {"a"}, "d": {"a"}}
    assert find_cycle(graph) == ["a", "b", "c", "a"]
    assert find_cycle({"a": {"b"}, "b": set()}) is None


def test_the_graph_sees_imports_where_they_run() -> None:
    graph = import_graph(in_functions=False)
    assert "olp.errors" in graph["olp.frontends"]  # module level
    assert "olp.diagnostics" not in graph["olp.frontends"]  # under TYPE_CHECKING, in a function
    assert "olp.frontends.krl" not in graph["olp.frontends.bundled"]  # inside load()
    assert "olp.frontends.krl" in import_graph(in_functions=True)["olp.frontends.bundled"]


def test_olp_has_no_module_level_import_cycle() -> None:
    cycle = find_cycle(import_graph(in_functions=False))
    assert cycle is None, " -> ".join(cycle or [])


def test_the_commands_import_each_other_in_no_circle() -> None:
    graph = import_graph(in_functions=True)
    commands = {name: deps for name, deps in graph.items() if name.startswith("olp.commands")}
    cycle = find_cycle({name: deps & set(commands) for name, deps in commands.items()})
    assert cycle is None, " -> ".join(cycle or [])
