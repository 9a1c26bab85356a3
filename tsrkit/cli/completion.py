"""Shell completion of plugin, dataset and preset names (click ``shell_complete`` callbacks).

Enable it once per shell (README, "Shell completion")::

    eval "$(_TSRKIT_COMPLETE=bash_source tsrkit)"

A callback that fails (a broken registry file, say) completes nothing rather than printing a
traceback into the shell.
"""

from __future__ import annotations

import contextlib
from collections.abc import Callable, Iterable

import click
from click.shell_completion import CompletionItem

__all__ = [
    "Complete",
    "dataset_names",
    "plugin_list",
    "plugin_names",
    "preset_names_only",
    "preset_or_file",
    "trainable_names",
]

Complete = Callable[[click.Context, click.Parameter, str], list[CompletionItem]]


def _items(names: Callable[[], Iterable[str]], incomplete: str) -> list[CompletionItem]:
    with contextlib.suppress(Exception):  # completion must never break the shell
        return [CompletionItem(n) for n in sorted(set(names())) if n.startswith(incomplete)]
    return []


def plugin_names(kind: str) -> Complete:
    """Complete the installed plugins of ``kind`` (detector, classifier, format, writer...)."""

    def names() -> list[str]:
        # only when the shell asks for completions: start-up stays fast
        from tsrkit.plugin.registry import get_registry

        return [info.name for info in get_registry().plugins(kind)]

    return lambda ctx, param, incomplete: _items(names, incomplete)


def plugin_list(kind: str) -> Complete:
    """Complete the last name of a comma-separated list of ``kind`` plugins (``--detectors``)."""
    single = plugin_names(kind)

    def complete(ctx, param, incomplete: str) -> list[CompletionItem]:
        done, _, last = incomplete.rpartition(",")
        prefix = f"{done}," if done else ""
        return [CompletionItem(prefix + item.value) for item in single(ctx, param, last)]

    return complete


def trainable_names(ctx, param, incomplete: str) -> list[CompletionItem]:
    """Complete the trainable plugins (``tsrkit train PLUGIN``)."""

    def names() -> list[str]:
        # only when the shell asks for completions: start-up stays fast
        from tsrkit.plugin.base import is_trainable
        from tsrkit.plugin.registry import get_registry

        return [i.name for i in get_registry().plugins() if is_trainable(i.cls)]

    return _items(names, incomplete)


def dataset_names(ctx, param, incomplete: str) -> list[CompletionItem]:
    """Complete registered dataset names and ``sample``; paths are completed by the shell."""

    def names() -> list[str]:
        # only when the shell asks for completions: start-up stays fast
        from tsrkit.datasets import load_registry

        return ["sample", *load_registry()]

    found = _items(names, incomplete)
    return found or [CompletionItem(incomplete, type="file")]


def preset_or_file(ctx, param, incomplete: str) -> list[CompletionItem]:
    """Complete preset names for ``--config``, else let the shell complete a file."""
    # only when the shell asks for completions: start-up stays fast
    from tsrkit.plugin.presets import preset_names

    found = _items(preset_names, incomplete)
    return found or [CompletionItem(incomplete, type="file")]


def preset_names_only(ctx, param, incomplete: str) -> list[CompletionItem]:
    """Complete preset names (``tsrkit presets --show``)."""
    # only when the shell asks for completions: start-up stays fast
    from tsrkit.plugin.presets import preset_names

    return _items(preset_names, incomplete)
