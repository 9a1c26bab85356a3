"""The boundary between the core and its plugins, read from the code itself.

- Plugins (``plugins/``, and the example third-party package) import the core only from the
  declared plugin API, :mod:`tsrkit.api`, and only names it declares; so no plugin reaches the
  global registry.
- A built-in plugin imports another plugin module only from its own kind's folder or from
  ``plugins/shared/`` (helpers several kinds use); ``shared`` imports no kind.
- The core imports no plugin module, and only the command line imports the command line.
- Every public core module (no ``_`` in its path) declares ``__all__``, and every name in it exists.
"""

from __future__ import annotations

import ast
import importlib
from pathlib import Path

import pytest

import tsrkit.api

REPO = Path(__file__).resolve().parents[2]
PLUGINS = REPO / "plugins"
EXAMPLE = REPO / "examples" / "tsrkit-brightest-blobs"
CORE = REPO / "tsrkit"


def imports(path: Path) -> list[tuple[int, str, list[str]]]:
    """Every ``import`` / ``from ... import`` of a file, anywhere in it: (line, module, names)."""
    found = []
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.ImportFrom) and node.level == 0 and node.module:
            found.append((node.lineno, node.module, [a.name for a in node.names]))
        elif isinstance(node, ast.Import):
            found += [(node.lineno, a.name, []) for a in node.names]
    return found


def plugin_files() -> list[Path]:
    return sorted([*PLUGINS.rglob("*.py"), *EXAMPLE.glob("*.py")])


def is_core(module: str) -> bool:
    return module == "tsrkit" or module.startswith("tsrkit.")


def test_plugins_import_the_core_only_through_the_declared_api():
    declared = set(tsrkit.api.__all__)
    outside = [
        f"{path.relative_to(REPO)}:{line} {module} {names}"
        for path in plugin_files()
        for line, module, names in imports(path)
        if is_core(module) and (module != "tsrkit.api" or not set(names) <= declared)
    ]
    assert outside == []


def test_a_plugin_imports_only_its_own_kind_and_the_shared_helpers():
    crossing = []
    for path in PLUGINS.rglob("*.py"):
        parts = path.relative_to(PLUGINS).parts
        if len(parts) < 2:
            continue
        kind = parts[0]
        allowed = {kind} if kind == "shared" else {kind, "shared"}
        for line, module, _ in imports(path):
            if module.startswith("tsrkit_plugins.") and module.split(".")[1] not in allowed:
                crossing.append(f"{path.relative_to(REPO)}:{line} {module}")
    assert crossing == []


def test_the_core_imports_no_plugin_and_only_the_cli_imports_the_cli():
    wrong = []
    for path in CORE.rglob("*.py"):
        relative = path.relative_to(CORE)
        in_cli = relative.parts[0] in ("cli", "__main__.py")
        for line, module, _ in imports(path):
            if module.startswith("tsrkit_plugins") or (
                not in_cli and module.startswith("tsrkit.cli")
            ):
                wrong.append(f"{path.relative_to(REPO)}:{line} {module}")
        tree = ast.parse(path.read_text(encoding="utf-8"))
        docstrings = {
            id(n.value) for n in ast.walk(tree) if isinstance(n, ast.Expr)
        }  # prose may mention the built-ins; code may not name them
        wrong += [
            f"{path.relative_to(REPO)}:{n.lineno} names {n.value!r}"
            for n in ast.walk(tree)
            if isinstance(n, ast.Constant)
            and isinstance(n.value, str)
            and "tsrkit_plugins" in n.value
            and id(n) not in docstrings
        ]
    assert wrong == []


def public_modules() -> list[str]:
    names = []
    for path in sorted(CORE.rglob("*.py")):
        parts = path.relative_to(REPO).with_suffix("").parts
        if parts[-1] == "__init__":
            parts = parts[:-1]
        if not any(p.startswith("_") for p in parts):
            names.append(".".join(parts))
    return names


@pytest.mark.parametrize("name", public_modules())
def test_every_public_core_module_declares_what_is_public(name):
    module = importlib.import_module(name)
    assert isinstance(getattr(module, "__all__", None), list), f"{name} has no __all__"
    assert [n for n in module.__all__ if not hasattr(module, n)] == []


def test_the_plugin_api_resolves_every_name_it_declares():
    assert tsrkit.api.__all__ == sorted(tsrkit.api.__all__) == sorted(dir(tsrkit.api))
    assert all(getattr(tsrkit.api, name) is not None for name in tsrkit.api.__all__)
    with pytest.raises(AttributeError, match="no_such_name"):
        _ = tsrkit.api.no_such_name
