"""Options shared by the verbs that run plugins: selection, ``--param`` and ``--config``."""
from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

import click

from tsrkit.errors import TsrkitError
from tsrkit.params import ParamError, load_config, parse_assignments
from tsrkit.pipeline import Pipeline
from tsrkit.registry import get_registry

DEFAULT_DETECTOR = "conspicuity"


def plugin_options(func):
    """Add ``--detector``, ``--verifier``, ``--classifier``, ``--tracker``, ``--param``,
    ``--config``."""
    options = [
        click.option("--detector", "-d", default=None,
                     help=f"Detector plugin (default {DEFAULT_DETECTOR})."),
        click.option("--verifier", "-V", default=None,
                     help="Verifier plugin: rescores, refines or rejects candidates."),
        click.option("--classifier", "-c", default=None, help="Classifier plugin."),
        click.option("--tracker", "-t", default=None, help="Tracker plugin (videos)."),
        click.option("--param", "-p", "params", multiple=True, metavar="KEY=VALUE",
                     help="Plugin parameter; repeatable. Prefix with detector., verifier., "
                          "classifier. or tracker. when two plugins share a key."),
        click.option("--config", type=click.Path(dir_okay=False), default=None,
                     help="YAML run configuration (plugins and their params)."),
    ]
    for option in reversed(options):
        func = option(func)
    return func


def route_params(selected: Mapping[str, str], assignments: Sequence[str],
                 config: Mapping[str, Any] | None = None) -> dict[str, dict[str, Any]]:
    """Give each ``key=value`` to the selected plugin that declares ``key``.

    A key may be prefixed with the plugin kind (``classifier.model=...``); an unprefixed key
    goes to the only selected plugin that declares it. Config params come first; ``--param``
    overrides them.
    """
    registry = get_registry()
    routed: dict[str, dict[str, Any]] = {kind: {} for kind in selected}
    for kind in selected:
        routed[kind].update((config or {}).get(kind, {}).get("params", {}))
    for key, value in parse_assignments(assignments).items():
        kind, dot, bare = key.partition(".")
        if dot and kind in selected:
            routed[kind][bare] = value
            continue
        owners = [k for k, name in selected.items()
                  if key in {p.name for p in registry.get(k, name).cls.params}]
        if len(owners) == 1:
            routed[owners[0]][key] = value
        elif owners:
            raise ParamError(f"parameter '{key}' is declared by both {' and '.join(owners)}; "
                             f"write {owners[0]}.{key}=...")
        else:
            names = " or ".join(f"{k} '{n}'" for k, n in selected.items())
            allowed = sorted({p.name for k, n in selected.items()
                              for p in registry.get(k, n).cls.params})
            raise ParamError(f"{names}: unknown parameter '{key}' "
                             f"(allowed: {', '.join(allowed) or 'none'})")
    return routed


def selected_plugins(detector: str | None, classifier: str | None, tracker: str | None,
                     config: Mapping[str, Any] | None,
                     verifier: str | None = None) -> dict[str, str]:
    """Plugin names by kind: the command line wins over the config, which wins over defaults."""
    config = config or {}
    chosen = {}
    for kind, given in (("detector", detector), ("verifier", verifier),
                        ("classifier", classifier), ("tracker", tracker)):
        name = given or (config.get(kind) or {}).get("name")
        if kind == "detector":
            name = name or DEFAULT_DETECTOR
        if name:
            chosen[kind] = name
    return chosen


def build_pipeline(detector: str | None, classifier: str | None, tracker: str | None,
                   params: Sequence[str], config_path: str | None,
                   verifier: str | None = None) -> Pipeline:
    """Instantiate the selected plugins with validated parameters."""
    config = load_config(config_path) if config_path else None
    chosen = selected_plugins(detector, classifier, tracker, config, verifier)
    registry = get_registry()
    for kind, name in chosen.items():
        registry.get(kind, name)  # a clear error for an unknown name before routing params
    routed = route_params(chosen, params, config)
    plugins = {kind: registry.create(kind, name, routed[kind]) for kind, name in chosen.items()}
    return Pipeline(plugins["detector"], plugins.get("classifier"), plugins.get("tracker"),
                    plugins.get("verifier"))


class UserError(click.ClickException):
    """Raised by commands for mistakes that need no traceback."""

    exit_code = 2


def fail(exc: TsrkitError) -> UserError:
    """Wrap a library error for click."""
    return UserError(str(exc))
