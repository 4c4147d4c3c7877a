"""The house as built (docs/architecture.md): stages along the data flow, no import circles.

Parses every module of femmech with :mod:`ast` (imports inside functions included, so a
deferred import cannot hide a circle) and checks that

* no module imports, directly or through others, a module that imports it back;
* every import goes down the stage order of :data:`STAGES` or stays in its own package;
* nothing inside femmech imports the top-level package (it re-exports, it is not a layer).
"""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

PACKAGE = Path(__file__).resolve().parents[1] / "femmech"

STAGES = {
    "errors": 0, "version": 0,
    "solve": 1,
    "fe": 2, "mechanisms": 2,
    "reduction": 3,
    "coupling": 4,
    "analysis": 5,
    "output": 6,
    "scene": 7,
    "cli": 8, "__main__": 9,
}
"""Stage of each top-level module or package of femmech: a module may import modules of a
lower stage and of its own package, nothing else (fe and mechanisms, both stage 2, are
independent of each other)."""


def module_name(path: Path) -> str:
    parts = list(path.relative_to(PACKAGE.parent).with_suffix("").parts)
    if parts[-1] == "__init__":
        parts.pop()
    return ".".join(parts)


def imported_modules(path: Path, modules: set[str]) -> set[str]:
    """femmech modules that ``path`` imports (``from a import b``: a.b if a module, else a)."""
    name = module_name(path)
    package = name if path.name == "__init__.py" else name.rpartition(".")[0]
    found = set()
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.Import):
            found |= {alias.name for alias in node.names if alias.name.startswith("femmech")}
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = package.split(".")[: len(package.split(".")) - node.level + 1]
                target = ".".join(base + ([node.module] if node.module else []))
            else:
                target = node.module or ""
            if not target.startswith("femmech"):
                continue
            for alias in node.names:
                sub = f"{target}.{alias.name}"
                found.add(sub if sub in modules else target)
    return found - {name}


def import_graph() -> dict[str, set[str]]:
    paths = sorted(PACKAGE.rglob("*.py"))
    modules = {module_name(p) for p in paths}
    return {module_name(p): imported_modules(p, modules) for p in paths}


def top(name: str) -> str:
    """``femmech.fe.mesh`` → ``fe``; the package itself → ``""``."""
    parts = name.split(".")
    return parts[1] if len(parts) > 1 else ""


def cycles(graph: dict[str, set[str]]) -> list[list[str]]:
    """Strongly connected components with more than one module (Tarjan)."""
    index, low, stack, on_stack, found = {}, {}, [], set(), []

    def visit(v):
        index[v] = low[v] = len(index)
        stack.append(v)
        on_stack.add(v)
        for w in sorted(graph.get(v, ())):
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on_stack:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            component = []
            while True:
                w = stack.pop()
                on_stack.discard(w)
                component.append(w)
                if w == v:
                    break
            if len(component) > 1:
                found.append(sorted(component))

    for v in sorted(graph):
        if v not in index:
            visit(v)
    return found


def test_graph_is_read():
    graph = import_graph()
    assert "femmech.scene.run" in graph
    assert "femmech.fe.model" in graph
    # a known edge, so that an empty parse cannot pass the tests below
    assert "femmech.fe.dofs" in graph["femmech.fe.model"]


def test_no_import_circles():
    assert cycles(import_graph()) == []


def test_stage_order():
    graph = import_graph()
    unknown = sorted({top(m) for m in graph} - set(STAGES) - {""})
    assert not unknown, f"add {unknown} to STAGES (and to docs/architecture.md)"
    wrong = []
    for module, targets in graph.items():
        if module == "femmech":
            continue
        for target in targets:
            if target == "femmech":
                wrong.append(f"{module} imports the top-level package")
            elif top(target) != top(module) and STAGES[top(target)] >= STAGES[top(module)]:
                wrong.append(f"{module} (stage {STAGES[top(module)]}) imports {target}"
                             f" (stage {STAGES[top(target)]})")
    assert not wrong, "\n".join(sorted(wrong))


@pytest.mark.parametrize(("graph", "expected"), [
    ({"a": {"b"}, "b": {"c"}, "c": {"a"}, "d": {"a"}}, [["a", "b", "c"]]),
    ({"a": {"b"}, "b": set()}, []),
])
def test_cycle_finder(graph, expected):
    """The checker itself finds a circle of three and none in a chain."""
    assert cycles(graph) == expected
