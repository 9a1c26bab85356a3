"""The rooms of the core import downwards only, and no modules import each other at load time.

The import graph of ``tsrkit/`` is read with :mod:`ast` (nothing is imported): every
``import`` / ``from ... import`` statement, at module level and inside functions, is an edge.
Statements under ``if TYPE_CHECKING:`` are annotations only and never run; they are left out.

- No import goes from a lower room to a higher one, nor between two rooms on one floor
  (:data:`tsrkit._rooms.ROOMS`), whether it runs at load time or inside a function.
- No cycle between modules among the imports that run at load time (module level).
- Every module belongs to a room, and the package root holds at most eight modules besides
  ``__init__`` and ``__main__``.
"""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

from tsrkit._rooms import ROOMS

PACKAGE = Path(__file__).resolve().parents[2] / "tsrkit"


def module_name(path: Path) -> str:
    parts = ("tsrkit", *path.relative_to(PACKAGE).with_suffix("").parts)
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


MODULES = {module_name(p): p for p in sorted(PACKAGE.rglob("*.py"))}


def room_of(module: str) -> str:
    """``tsrkit.plugin.registry`` -> ``plugin``; the package itself -> ``""``."""
    parts = module.split(".")
    return parts[1] if len(parts) > 1 else ""


FLOOR = {room: floor for floor, rooms in enumerate(ROOMS) for room in rooms}


def is_type_checking(test: ast.expr) -> bool:
    return "TYPE_CHECKING" in ast.unparse(test)


def imports(module: str) -> list[tuple[str, int, bool]]:
    """``(imported tsrkit module, line, at load time)`` for each import statement of
    ``module``: at load time unless inside a function."""
    path = MODULES[module]
    package = module if path.name == "__init__.py" else module.rpartition(".")[0]
    found: list[tuple[str, int, bool]] = []

    def target(name: str) -> str | None:
        while name and name not in MODULES:  # a name inside a module, as ``tsrkit.x.Name``
            name = name.rpartition(".")[0]
        return name or None

    def visit(node: ast.AST, in_function: bool) -> None:
        for child in ast.iter_child_nodes(node):
            if isinstance(child, ast.If) and is_type_checking(child.test):
                for orelse in child.orelse:
                    visit(orelse, in_function)
                continue
            inside = in_function or isinstance(child, ast.FunctionDef | ast.AsyncFunctionDef)
            names: list[str] = []
            if isinstance(child, ast.Import):
                names = [alias.name for alias in child.names]
            elif isinstance(child, ast.ImportFrom):
                if child.level:
                    base = package.split(".")[: len(package.split(".")) - child.level + 1]
                    source = ".".join([*base, *([child.module] if child.module else [])])
                else:
                    source = child.module or ""
                names = [f"{source}.{alias.name}" for alias in child.names]
            for name in names:
                if name.split(".")[0] == "tsrkit" and (hit := target(name)) and hit != module:
                    found.append((hit, child.lineno, not inside))
            visit(child, inside)

    visit(ast.parse(path.read_text(encoding="utf-8")), False)
    return found


GRAPH = {module: imports(module) for module in MODULES}


def test_every_module_is_in_a_room():
    assert [m for m in MODULES if room_of(m) not in FLOOR] == []


def test_the_package_root_holds_few_modules():
    root = [p.name for p in PACKAGE.glob("*.py") if p.name not in ("__init__.py", "__main__.py")]
    assert len(root) <= 8, root


def test_no_import_goes_up_or_across_a_floor():
    wrong = []
    for module, edges in GRAPH.items():
        for imported, line, _ in edges:
            here, there = room_of(module), room_of(imported)
            if here != there and FLOOR[there] >= FLOOR[here]:
                wrong.append(f"{MODULES[module].relative_to(PACKAGE.parent)}:{line} {imported}")
    assert wrong == []


def test_no_cycle_among_load_time_imports():
    edges = {m: {t for t, _, load in GRAPH[m] if load} for m in MODULES}
    state: dict[str, int] = {}  # 1: on the path, 2: done
    cycles = []

    def walk(module: str, path: list[str]) -> None:
        state[module] = 1
        for nxt in sorted(edges[module]):
            if state.get(nxt) == 1:
                cycles.append(" -> ".join([*path[path.index(nxt) :], nxt]))
            elif nxt not in state:
                walk(nxt, [*path, nxt])
        state[module] = 2

    for module in MODULES:
        if module not in state:
            walk(module, [module])
    assert cycles == []


@pytest.mark.parametrize(
    ("source", "expected"),
    [
        ("from tsrkit.core.types import Frame\n", [("tsrkit.core.types", 1, True)]),
        (
            "def f():\n    from tsrkit.plugin import registry\n",
            [("tsrkit.plugin.registry", 2, False)],
        ),
        ("from typing import TYPE_CHECKING\nif TYPE_CHECKING:\n    import tsrkit.cli\n", []),
        ("from ..core import files\n", [("tsrkit.core.files", 1, True)]),
    ],
)
def test_the_walk_sees_each_kind_of_import(source, expected, tmp_path, monkeypatch):
    path = PACKAGE / "geo" / "errors.py"  # any module: its text is replaced for the walk
    monkeypatch.setattr(Path, "read_text", lambda self, encoding=None: source)
    assert imports(module_name(path)) == expected
