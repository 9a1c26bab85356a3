"""Lazy re-exports declared by a type stub (after scikit-image's ``lazy_loader.attach_stub``).

A module ``m.py`` whose public names live in other modules lists them once, as
``from tsrkit.x import name as name`` lines, in ``m.pyi`` beside it; type checkers read the stub,
and :func:`attach_stub` gives ``m`` the ``__getattr__``, ``__dir__`` and ``__all__`` that
import each name on first use (PEP 562).
"""

from __future__ import annotations

import ast
import importlib
import sys
from collections.abc import Callable
from pathlib import Path
from typing import Any

__all__ = ["attach_stub"]


def attach_stub(
    module: str, file: str
) -> tuple[Callable[[str], Any], Callable[[], list[str]], list[str]]:
    """``__getattr__``, ``__dir__`` and ``__all__`` of ``module`` from the stub beside ``file``.

    Raises
    ------
    ValueError
        A stub line that is not ``from PACKAGE.MODULE import NAME as NAME``.
    """
    stub = Path(file).with_suffix(".pyi")
    where: dict[str, str] = {}
    for node in ast.parse(stub.read_text(encoding="utf-8")).body:
        if isinstance(node, ast.ImportFrom) and node.level == 0 and node.module:
            for alias in node.names:
                if alias.asname != alias.name:
                    raise ValueError(f"{stub}: write 'import {alias.name} as {alias.name}'")
                where[alias.name] = node.module
        elif not isinstance(node, ast.Expr | ast.ImportFrom):
            raise ValueError(f"{stub}:{node.lineno}: only 'from ... import' lines belong here")
    names = sorted(where)

    def __getattr__(name: str) -> Any:
        if name not in where:
            raise AttributeError(f"module {module!r} has no attribute {name!r}")
        value = getattr(importlib.import_module(where[name]), name)
        setattr(sys.modules[module], name, value)
        return value

    def __dir__() -> list[str]:
        return list(names)

    return __getattr__, __dir__, names
