"""The house as built (docs/architecture.md): stages along the data flow, no import circles.

Parses every module of femmech with :mod:`ast` (imports inside functions included, so a
deferred import cannot hide a circle) and checks that

* no module imports, directly or through others, a module that imports it back;
* every import goes down the stage order of :data:`STAGES` or stays in its own package;
* nothing inside femmech imports the top-level package (it re-exports, it is not a layer);
* old paths (module files kept only so that names moved by a restructure still import,
  docs/architecture.md "Moved names") import nothing but :mod:`femmech.deprecation`, and
  nothing inside femmech imports them: they stand outside the stages;
* no test file imports another test file: shared test models live in helper modules.
* no module imports another module's underscore name, no UPPER_CASE constant is defined
  with the same value in two modules, and every package docstring names its modules.
"""

from __future__ import annotations

import ast
import re
from pathlib import Path

import numpy as np
import pytest

PACKAGE = Path(__file__).resolve().parents[1] / "femmech"

STAGES = {
    "errors": 0, "version": 0, "html": 0, "deprecation": 0,
    "solve": 1,
    "fe": 2, "mechanisms": 2,
    "reduction": 3,
    "coupling": 4,
    "analysis": 5,
    "chain": 6,
    "output": 7,
    "scene": 8,
    "cli": 9, "__main__": 10,
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


def is_old_path(path: Path) -> bool:
    """A module file kept only for an old import path: a docstring, imports of
    :mod:`femmech.deprecation`, a module ``__getattr__`` and calls (``alias_module``), nothing
    else (femmech.deprecation says how they work)."""
    shim = False
    for node in ast.parse(path.read_text(encoding="utf-8")).body:
        if isinstance(node, ast.ImportFrom) and node.module == "femmech.deprecation":
            continue
        if isinstance(node, ast.Expr) and isinstance(node.value, ast.Constant):
            continue  # the docstring
        if (isinstance(node, ast.FunctionDef) and node.name == "__getattr__"
                or isinstance(node, ast.Expr) and isinstance(node.value, ast.Call)):
            shim = True
            continue
        return False
    return shim


def old_paths() -> set[str]:
    """Old-path modules, and packages of nothing but old paths (``femmech.elements``)."""
    paths = sorted(PACKAGE.rglob("*.py"))
    old = {module_name(p) for p in paths if is_old_path(p)}
    for init in (p for p in paths if p.name == "__init__.py"):
        members = [p for p in init.parent.glob("*.py") if p != init]
        if members and all(module_name(p) in old for p in members):
            old.add(module_name(init))
    return old


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


def test_old_paths_stand_outside():
    """Old paths import only femmech.deprecation and nothing in femmech imports them."""
    graph, old = import_graph(), old_paths()
    assert {"femmech.io", "femmech.linalg", "femmech.elements", "femmech.elements.beam"} <= old
    assert not {"femmech.fe", "femmech.fe.mesh_io", "femmech.analysis.stability"} & old
    for module in old:
        assert graph[module] <= {"femmech.deprecation"}, module
    users = sorted(f"{m} imports {t}" for m, ts in graph.items() for t in ts & old)
    assert not users, "\n".join(users)


def test_stage_order():
    old = old_paths()
    graph = {m: t for m, t in import_graph().items() if m not in old}
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


# --- test files share models through helper modules, never through each other ------------

TESTS = Path(__file__).resolve().parent
SHARED_TEST_MODULES = frozenset({"models", "scene_texts", "roundoff", "hard_models"})
"""The helper modules of tests/ that test files import (shared models, scene texts,
round-off bounds, the hard cases' models); ``conftest.py`` serves fixtures."""


def test_files_import_no_other_test_file():
    """A test file imports only the shared helper modules of tests/, never another test
    file, so that moving or renaming a test does not break its neighbours."""
    local = {path.stem for path in TESTS.rglob("*.py")} | {"tests"}
    wrong = []
    for path in sorted(TESTS.rglob("*.py")):
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if isinstance(node, ast.Import):
                names = [alias.name for alias in node.names]
            elif isinstance(node, ast.ImportFrom):
                names = ["." * node.level + (node.module or "")]
            else:
                continue
            for name in names:
                head = name.split(".")[0]
                if name.startswith(".") or (head in local and head not in SHARED_TEST_MODULES):
                    wrong.append(f"{path.relative_to(TESTS)} imports {name}")
    assert {"models", "hard_models"} <= local  # the helpers exist where listed
    assert not wrong, "\n".join(wrong)


# --- adding an element type touches only femmech/fe/elements/ plus its registration ---

WEDGE_TETS = np.array([[0, 1, 2, 3], [1, 2, 3, 4], [2, 3, 4, 5]])
"""A 6-node wedge (meshio order: bottom triangle 0 1 2, top 3 4 5 above them) as three
linear tetrahedra (the split femmech.fe.checks.cell_measure uses for its volume)."""


def _positive_tets(points, cells):
    """Tetrahedra of each wedge, two nodes swapped where the volume would be negative."""
    tets = cells[:, WEDGE_TETS].reshape(-1, 4)
    x = points[tets]
    volume = np.linalg.det(np.stack([x[:, 1] - x[:, 0], x[:, 2] - x[:, 0], x[:, 3] - x[:, 0]],
                                    axis=1))
    tets[volume < 0] = tets[volume < 0][:, [0, 2, 1, 3]]
    return tets


def wedge_matrices(points, cells, kind, E, nu, rho, n_dof):
    """A toy solid element: the wedge as the sum of its three linear tetrahedra (family
    "solid" signature of femmech.fe.elements.registry)."""
    from femmech.fe.elements.solid import assemble_solid

    tets = _positive_tets(points, cells)
    return assemble_solid(points, tets, "tetra", np.repeat(E, 3), np.repeat(nu, 3),
                          np.repeat(rho, 3), n_dof)


def _wedge_bar(n: int = 4):
    """A 1 m bar of n cells along x with a right-triangle cross-section of 0.1 m legs,
    as wedges; and the same bar as the wedges' tetrahedra."""
    import femmech as fm

    x = np.linspace(0.0, 1.0, n + 1)
    section = np.array([[0.0, 0.0], [0.1, 0.0], [0.0, 0.1]])
    points = np.array([[xi, y, z] for xi in x for y, z in section])
    wedges = np.array([[3 * i, 3 * i + 1, 3 * i + 2, 3 * i + 3, 3 * i + 4, 3 * i + 5]
                       for i in range(n)])
    tets = _positive_tets(points, wedges)
    as_wedges = fm.Mesh(points, {"wedge": wedges}, {"bar": {"wedge": np.arange(n)}})
    as_tets = fm.Mesh(points, {"tetra": tets}, {"bar": {"tetra": np.arange(len(tets))}})
    return as_wedges, as_tets


def test_toy_element_touches_only_elements(monkeypatch):
    """A new cell kind computed by a function of this test file, registered once, runs
    through build_model and fm.modes unchanged: same K, M and frequencies as the same
    tetrahedra given as tetra cells (the toy element is their sum, so only the order of
    summation differs: round-off, rtol 1e-12)."""
    import femmech as fm
    from femmech.fe.elements import registry

    as_wedges, as_tets = _wedge_bar()
    steel = fm.SolidProperty(fm.Material(E=210e9, nu=0.3, rho=7850.0))
    with pytest.raises(ValueError, match="wedge"):  # not registered: a clear error
        fm.build_model(as_wedges, solids={"bar": steel})
    monkeypatch.setitem(registry.ELEMENTS, "wedge",
                        registry.ElementType("wedge", "solid", wedge_matrices))
    assert "wedge" in registry.kinds("solid")
    support = [fm.Support(np.flatnonzero(as_wedges.points[:, 0] == 0.0))]
    toy = fm.build_model(as_wedges, solids={"bar": steel}, supports=support)
    reference = fm.build_model(as_tets, solids={"bar": steel}, supports=support)
    for a, b in ((toy.K, reference.K), (toy.M, reference.M)):
        # bound: the same element sums in another order (<= ~20 terms per entry): ~20 eps
        assert abs(a - b).max() <= 1e-12 * abs(b).max()
    f_toy = fm.modes(toy, n_modes=4).freq_hz
    f_ref = fm.modes(reference, n_modes=4).freq_hz
    # bound: K, M differ by the order of summation only: at most ~20 terms per entry, so
    # <= 20 eps = 4.4e-15 relative; a frequency moves by <= 1/2 that times
    # lambda_max / lambda_1 = 1.1e5 of this 36-DOF bar (measured), i.e. <= 2.5e-10
    np.testing.assert_allclose(f_toy, f_ref, rtol=1e-9)


def test_registry_refuses_bad_entries():
    from femmech.fe.elements import registry

    with pytest.raises(ValueError, match="already has an element"):
        registry.register(registry.ElementType("quad", "shell", wedge_matrices))
    with pytest.raises(ValueError, match="unknown cell kind 'prism'"):
        registry.ElementType("prism", "solid", wedge_matrices)
    with pytest.raises(ValueError, match="family"):
        registry.ElementType("wedge", "membrane", wedge_matrices)
    assert registry.kinds("shell")[:2] == ("triangle", "quad")  # registration order
    assert "quad9" in registry.kinds("shell")


# --- public names across module boundaries, each constant once, package docstrings ---

PRIVATE_IMPORTS_LEFT: set[tuple[str, str]] = set()
"""(importing module, name) of the underscore imports still to be switched to public names;
it only shrinks: an entry that is no longer needed fails the test too."""

CONSTANTS_TWICE_LEFT: set[tuple[str, str]] = set()
"""(module, name) of a constant that repeats another module's definition, still to be
imported from there; it only shrinks like :data:`PRIVATE_IMPORTS_LEFT`."""

UPPER_CASE = re.compile(r"[A-Z][A-Z0-9_]*")


def _is_private(name: str) -> bool:
    return name.startswith("_") and not name.startswith("__")


def private_imports() -> set[tuple[str, str, str]]:
    """(importing module, imported module, name) of every ``from femmech.x import _name``
    of another module (relative imports resolved; dunder names are not private)."""
    found = set()
    for path in sorted(PACKAGE.rglob("*.py")):
        name = module_name(path)
        package = name if path.name == "__init__.py" else name.rpartition(".")[0]
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if not isinstance(node, ast.ImportFrom):
                continue
            if node.level:
                base = package.split(".")[: len(package.split(".")) - node.level + 1]
                target = ".".join(base + ([node.module] if node.module else []))
            else:
                target = node.module or ""
            if target.startswith("femmech") and target != name:
                found |= {(name, target, alias.name) for alias in node.names
                          if _is_private(alias.name)}
    return found


def test_no_private_names_across_modules():
    """What one module takes from another is a public name of it (no underscore)."""
    found = private_imports()
    new = sorted(f"{m} imports {n} from {t}: make it public there (drop the underscore)"
                 for m, t, n in found if (m, n) not in PRIVATE_IMPORTS_LEFT)
    stale = sorted(f"{m}: {n}" for m, n in PRIVATE_IMPORTS_LEFT - {(m, n) for m, _, n in found})
    assert not new, "\n".join(new)
    assert not stale, "no longer imported, remove from PRIVATE_IMPORTS_LEFT:\n" + "\n".join(stale)


def literal_constants(path: Path) -> dict[str, str]:
    """Module-level ``UPPER_CASE = literal`` of ``path``: name → repr of the value. An alias
    (``A = B``, a name bound by an import or a computation) is no literal and not listed."""
    found = {}
    for node in ast.parse(path.read_text(encoding="utf-8")).body:
        targets = node.targets if isinstance(node, ast.Assign) else (
            [node.target] if isinstance(node, ast.AnnAssign) and node.value else [])
        try:
            value = repr(ast.literal_eval(node.value)) if targets else None
        except (ValueError, TypeError, SyntaxError, RecursionError):
            continue
        found |= {t.id: value for t in targets
                  if isinstance(t, ast.Name) and UPPER_CASE.fullmatch(t.id)}
    return found


def constants_defined_twice() -> dict[tuple[str, str], list[str]]:
    """(name, value) → the modules (old paths aside) that define the same UPPER_CASE name
    with the same literal value, for those defined in more than one module."""
    old, where = old_paths(), {}
    for path in sorted(PACKAGE.rglob("*.py")):
        if module_name(path) in old:
            continue
        for name, value in literal_constants(path).items():
            where.setdefault((name, value), []).append(module_name(path))
    return {key: modules for key, modules in where.items() if len(modules) > 1}


def test_each_constant_defined_once():
    """A constant with the same name and value in two modules is one constant: one module
    defines it, the other imports it."""
    twice = constants_defined_twice()
    offenders = {(m, name) for (name, _), modules in twice.items() for m in modules}
    new = sorted(f"{name} = {value} in {', '.join(modules)}: define it once, import it"
                 for (name, value), modules in twice.items()
                 if not {(m, name) for m in modules} & CONSTANTS_TWICE_LEFT)
    stale = sorted(f"{m}: {n}" for m, n in CONSTANTS_TWICE_LEFT - offenders)
    assert not new, "\n".join(new)
    assert not stale, "defined once now, remove from CONSTANTS_TWICE_LEFT:\n" + "\n".join(stale)


def test_constant_checker_sees_literals_only(tmp_path):
    """The checker lists literal constants and skips aliases and computed values."""
    path = tmp_path / "m.py"
    path.write_text("from x import B\nA = 6\nC = B\nD = (1, 'a')\nE = 2 * A\ne = 1\n")
    assert literal_constants(path) == {"A": "6", "D": "(1, 'a')"}


def undocumented_modules() -> list[str]:
    """``package: module`` for each module or subpackage (old paths aside) that its
    package's ``__init__`` docstring does not name as ``:mod:`.name```,
    ``:mod:`package.name``` or ```name```."""
    old, missing = old_paths(), []
    for init in sorted(PACKAGE.rglob("__init__.py")):
        package = module_name(init)
        if package in old:
            continue
        doc = ast.get_docstring(ast.parse(init.read_text(encoding="utf-8"))) or ""
        members = [p.stem for p in init.parent.glob("*.py") if p != init]
        members += [d.name for d in init.parent.iterdir() if (d / "__init__.py").is_file()]
        for member in sorted(members):
            named = re.search(rf":mod:`~?(?:{re.escape(package)})?\.{member}`|`{member}(?:\.py)?`",
                              doc)
            if f"{package}.{member}" not in old and not named:
                missing.append(f"{package}: {member}")
    return missing


def test_package_docstrings_name_their_modules():
    """Every package's ``__init__`` docstring names each of its modules, so that reading
    it is enough to find where something is."""
    missing = undocumented_modules()
    assert not missing, "name these in their package's __init__ docstring:\n" + "\n".join(
        missing)


def test_every_analysis_kind_module_is_registered():
    """Each module of femmech/scene/kinds/ (but the shared one) is a registry entry with a
    reader, a runner and a one-line description."""
    from femmech.scene import registry

    modules = sorted(p.stem for p in (PACKAGE / "scene" / "kinds").glob("*.py")
                     if p.stem != "__init__" and p.stem not in registry.SHARED)
    assert sorted(registry.KINDS) == modules
    for kind in registry.KINDS.values():
        assert callable(kind.read), kind.name
        assert callable(kind.run), kind.name
        assert kind.describe, kind.name
        assert "\n" not in kind.describe, kind.name
