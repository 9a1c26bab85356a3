"""The plugin manager: discovery through the ``tsrkit`` entry-point group, and look-up by name.

Built-ins, the metrics among them, load through the same entry points a third-party package
declares (the command line registers the built-in verbs through the same hooks,
:mod:`tsrkit.cli.main`). A
plugin that fails to import or to register is recorded as a :class:`PluginFailure` and the
others still load (a plugin that calls ``sys.exit`` while it loads included). Two plugins of
one kind and name: tsrkit's own is kept over another package's (else the first), and a
:class:`~tsrkit.core.errors.TsrkitWarning` names both packages.
``TSRKIT_LOAD_PLUGINS`` (comma-separated entry-point names or shell patterns;
empty for none) limits which installed plugins load; report writers (``writer-*``) and the
internal plugins always load, since every report needs them.
"""

from __future__ import annotations

import fnmatch
import os
import warnings
from collections.abc import Mapping
from dataclasses import dataclass, field
from importlib import metadata
from typing import Any, Literal, overload

import pluggy

from tsrkit.core.errors import TsrkitError, TsrkitWarning
from tsrkit.plugin import hookspecs
from tsrkit.plugin.base import (
    Classifier,
    DatasetFormat,
    Detector,
    Metric,
    Plugin,
    ReportWriter,
    Tracker,
    Verifier,
    is_trainable,
)
from tsrkit.plugin.hookspecs import ENTRY_POINT_GROUP
from tsrkit.plugin.params import PLUGIN_TYPES, Param, ParamError, Part, parse_parts, validate

__all__ = [
    "ENTRY_POINT_GROUP",
    "LOAD_ENV",
    "PluginFailure",
    "PluginInfo",
    "PluginNotFound",
    "Registry",
    "get_registry",
    "reset_registry",
]

LOAD_ENV = "TSRKIT_LOAD_PLUGINS"
KINDS = {
    "detector": "register_detectors",
    "verifier": "register_verifiers",
    "classifier": "register_classifiers",
    "tracker": "register_trackers",
    "format": "register_dataset_formats",
    "metric": "register_metrics",
    "writer": "register_report_writers",
}
#: Entry points that load whatever ``TSRKIT_LOAD_PLUGINS`` says.
ALWAYS_LOAD = ("writer-*", "metric-*")


class PluginNotFound(TsrkitError):
    """No plugin of that kind and name is installed."""


@dataclass(frozen=True)
class PluginInfo:
    """A registered plugin class with where it came from."""

    cls: type[Plugin]
    package: str
    package_version: str

    @property
    def name(self) -> str:
        return self.cls.name

    @property
    def kind(self) -> str:
        return self.cls.kind

    @property
    def version(self) -> str:
        return self.cls.version or self.package_version

    def to_json(self) -> dict[str, Any]:
        """What ``tsrkit plugins --json`` prints for this plugin."""
        return {
            "name": self.name,
            "kind": self.kind,
            "package": self.package,
            "version": self.version,
            "summary": self.cls.summary,
            "section": self.cls.section,
            "trainable": is_trainable(self.cls),
            "params": [p.to_json() for p in self.cls.PARAMS],
        }


@dataclass(frozen=True)
class PluginFailure:
    """A plugin that could not be loaded or registered."""

    plugin: str
    package: str
    error: str

    def to_json(self) -> dict[str, str]:
        return {"name": self.plugin, "kind": "failed", "package": self.package, "error": self.error}


@dataclass
class Registry:
    """One pluggy manager plus the plugin classes its hooks registered."""

    pm: pluggy.PluginManager = field(default_factory=lambda: _new_manager())
    failures: list[PluginFailure] = field(default_factory=list)
    _origin: dict[str, tuple[str, str]] = field(default_factory=dict)
    _plugins: dict[str, dict[str, PluginInfo]] | None = None

    def load_entry_points(self, only: str | None = None) -> None:
        """Import and register every entry point of the group that ``only`` admits."""
        patterns = None if only is None else [p.strip() for p in only.split(",") if p.strip()]
        if patterns is not None:
            patterns += ALWAYS_LOAD
        for ep in sorted(metadata.entry_points(group=ENTRY_POINT_GROUP), key=lambda e: e.name):
            if patterns is not None and not any(fnmatch.fnmatch(ep.name, p) for p in patterns):
                continue
            dist = ep.dist.name if ep.dist else "?"
            version = ep.dist.version if ep.dist else "?"
            try:
                module = ep.load()
                self.add(module, ep.name, dist, version)
            except (Exception, SystemExit) as exc:  # a broken plugin must not stop the others
                self.failures.append(PluginFailure(ep.name, dist, _describe(exc)))
        self.pm.check_pending()

    def add(
        self, plugin: object, name: str, package: str = "<in-process>", version: str = "0"
    ) -> None:
        """Register a plugin object (module or instance with hook implementations)."""
        self.pm.register(plugin, name=name)
        self._origin[name] = (package, version)
        self._plugins = None

    def remove(self, name: str) -> None:
        """Unregister the plugin object registered as ``name``."""
        self.pm.unregister(name=name)
        self._origin.pop(name, None)
        self.failures = [f for f in self.failures if f.plugin != name]
        self._plugins = None

    def plugins(self, kind: str | None = None) -> list[PluginInfo]:
        """Registered plugin classes, sorted by kind and name."""
        table = self._collect()
        kinds = [kind] if kind else list(KINDS)
        return [table[k][n] for k in kinds for n in sorted(table[k])]

    def get(self, kind: str, name: str) -> PluginInfo:
        """The plugin of ``kind`` called ``name``; :class:`PluginNotFound` lists the others."""
        table = self._collect()
        try:
            return table[kind][name]
        except KeyError:
            known = ", ".join(sorted(table.get(kind, {}))) or "none installed"
            raise PluginNotFound(f"no {kind} called '{name}' (available: {known})") from None

    @overload
    def create(
        self, kind: Literal["detector"], name: str, params: Mapping[str, Any] | None = None
    ) -> Detector: ...
    @overload
    def create(
        self, kind: Literal["verifier"], name: str, params: Mapping[str, Any] | None = None
    ) -> Verifier: ...
    @overload
    def create(
        self, kind: Literal["classifier"], name: str, params: Mapping[str, Any] | None = None
    ) -> Classifier: ...
    @overload
    def create(
        self, kind: Literal["tracker"], name: str, params: Mapping[str, Any] | None = None
    ) -> Tracker: ...
    @overload
    def create(
        self, kind: Literal["format"], name: str, params: Mapping[str, Any] | None = None
    ) -> DatasetFormat: ...
    @overload
    def create(
        self, kind: Literal["metric"], name: str, params: Mapping[str, Any] | None = None
    ) -> Metric: ...
    @overload
    def create(
        self, kind: Literal["writer"], name: str, params: Mapping[str, Any] | None = None
    ) -> ReportWriter: ...
    @overload
    def create(self, kind: str, name: str, params: Mapping[str, Any] | None = None) -> Plugin: ...

    def create(self, kind: str, name: str, params: Mapping[str, Any] | None = None) -> Plugin:
        """Instantiate a plugin with validated parameters (typed by ``kind`` for the checker).

        A plugin-typed parameter (:data:`tsrkit.plugin.params.PLUGIN_TYPES`) reaches the constructor
        as the :class:`~tsrkit.plugin.params.Part` (or tuple of parts) built here from its spec, so
        that a plugin receives the plugins it builds on instead of looking them up.
        """
        cls = self.get(kind, name).cls
        values = validate(cls.PARAMS, params or {}, f"{kind} '{name}'")
        for param in cls.PARAMS:
            if param.type in PLUGIN_TYPES and values[param.name] is not None:
                parts = self._parts(param, values[param.name], kind, name)
                values[param.name] = tuple(parts) if param.type == "detectors" else parts[0]
        return cls(**values)

    def _parts(self, param: Param, spec: str, kind: str, owner: str) -> list[Part]:
        """The plugins that ``owner``'s plugin-typed parameter names, built with their own
        parameters (``param.options`` keys stay with the declaring plugin)."""
        own_keys = {p.name for p in param.options}
        parts = []
        for name, assignments in parse_parts(spec):
            where = f"{kind} '{owner}': {param.name} {name!r}"
            if (PLUGIN_TYPES[param.type], name) == (kind, owner):
                raise ParamError(f"{where}: a plugin cannot be built on itself")
            own = {k: v for k, v in assignments.items() if k not in own_keys}
            options = validate(
                param.options, {k: v for k, v in assignments.items() if k in own_keys}, where
            )
            try:
                plugin = self.create(PLUGIN_TYPES[param.type], name, own)
            except ParamError as exc:
                raise ParamError(f"{kind} '{owner}': {param.name}: {exc}") from None
            text = " ".join([name, *(f"{k}={v}" for k, v in assignments.items())])
            parts.append(Part(plugin, text, options))
        return parts

    def _collect(self) -> dict[str, dict[str, PluginInfo]]:
        if self._plugins is not None:
            return self._plugins
        self.failures = [f for f in self.failures if not f.error.startswith("register")]
        table: dict[str, dict[str, PluginInfo]] = {k: {} for k in KINDS}
        owner: dict[tuple[str, str], str] = {}  # (kind, name): the plugin object registering it
        for kind, hook_name in KINDS.items():
            for impl in getattr(self.pm.hook, hook_name).get_hookimpls():
                package, version = self._origin.get(impl.plugin_name, ("<in-process>", "0"))
                found: list[type[Plugin]] = []
                try:
                    impl.function(register=found.append)
                except (Exception, SystemExit) as exc:
                    self.failures.append(
                        PluginFailure(impl.plugin_name, package, f"register: {_describe(exc)}")
                    )
                    continue
                for cls in found:
                    problem = _check_class(cls, kind)
                    info = PluginInfo(cls, package, version)
                    earlier = table[kind].get(getattr(cls, "name", ""))
                    if earlier is not None and not problem:
                        kept, lost = _clash(kind, earlier, info)
                        name = impl.plugin_name if lost is info else owner[kind, cls.name]
                        problem = f"register: {_clashed(kind, kept, lost)}"
                        self.failures.append(PluginFailure(name, lost.package, problem))
                        table[kind][cls.name] = kept
                        owner[kind, cls.name] = impl.plugin_name if kept is info else name
                    elif problem:
                        self.failures.append(
                            PluginFailure(impl.plugin_name, package, f"register: {problem}")
                        )
                    else:
                        table[kind][cls.name] = info
                        owner[kind, cls.name] = impl.plugin_name
        self._plugins = table
        return table


def _clash(kind: str, earlier: PluginInfo, later: PluginInfo) -> tuple[PluginInfo, PluginInfo]:
    """The plugin kept and the one left out of two of ``kind`` under one name (tsrkit's own
    over another package's, else the ``earlier``), said in one warning."""
    builtin = later.package == "tsrkit" != earlier.package
    kept, lost = (later, earlier) if builtin else (earlier, later)
    warnings.warn(_clashed(kind, kept, lost), TsrkitWarning, stacklevel=4)
    return kept, lost


def _clashed(kind: str, kept: PluginInfo, lost: PluginInfo) -> str:
    """The one line naming both packages of a name clash and the plugin kept."""
    return (
        f"duplicate {kind} name '{kept.name}': registered by {lost.package} and by "
        f"{kept.package}; {kept.package}'s is kept, {lost.package}'s is not used"
    )


def _new_manager() -> pluggy.PluginManager:
    pm = pluggy.PluginManager("tsrkit")
    pm.add_hookspecs(hookspecs)
    return pm


def _describe(exc: BaseException) -> str:
    if isinstance(exc, SystemExit):
        return f"called sys.exit({exc.code!r}) while loading"
    return f"{type(exc).__name__}: {exc}"


def _check_class(cls: object, kind: str) -> str | None:
    if not isinstance(cls, type) or not issubclass(cls, Plugin) or cls.kind != kind:
        return f"{cls!r} is not a {kind} plugin class"
    if not cls.name:
        return f"{cls.__name__} has no name"
    if isinstance(vars(cls).get("params"), tuple):
        return f"{cls.__name__} declares its parameters as 'params'; name the tuple 'PARAMS'"
    try:
        validate(cls.PARAMS, {}, f"{kind} '{cls.name}'")
    except (ParamError, ValueError) as exc:
        return f"invalid parameter schema: {exc}"
    return None


_REGISTRY: Registry | None = None


def get_registry() -> Registry:
    """The process-wide registry, loading entry points on first use."""
    global _REGISTRY
    if _REGISTRY is None:
        _REGISTRY = Registry()
        _REGISTRY.load_entry_points(os.environ.get(LOAD_ENV))
    return _REGISTRY


def reset_registry() -> None:
    """Forget the process-wide registry (tests, or after changing ``TSRKIT_LOAD_PLUGINS``)."""
    global _REGISTRY
    _REGISTRY = None
