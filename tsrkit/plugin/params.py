"""Typed parameter schemas: what a plugin accepts, and validation of what a user gives.

A plugin lists :class:`Param` objects; values arrive as Python objects (API, YAML) or as
``key=value`` strings (``--param``) and are checked against the schema. Every failure is a
:class:`ParamError` whose message names the plugin, the key and what is allowed.
"""

from __future__ import annotations

import difflib
import math
import os
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

from tsrkit.core.errors import TsrkitError
from tsrkit.core.files import InputFileError, not_regular, read_yaml
from tsrkit.plugin.presets import resolve_config

if TYPE_CHECKING:
    from tsrkit.plugin.base import Plugin

__all__ = [
    "PLUGIN_TYPES",
    "TYPES",
    "Param",
    "ParamError",
    "Part",
    "load_config",
    "parse_assignments",
    "parse_parts",
    "validate",
]

#: Parameter types and what they accept.
TYPES = {
    "int": "an integer",
    "float": "a number",
    "bool": "true or false",
    "str": "a string",
    "path": "a file or folder path",
    "ints": "a list of integers, e.g. 1,2,3 or 1..10",
    "floats": "a list of numbers, e.g. 1,1,2",
    "detector": "a detector: NAME KEY=VALUE ... ('' for none)",
    "detectors": "detectors: NAME KEY=VALUE ...; NAME ...",
    "verifier": "a verifier: NAME KEY=VALUE ... ('' for none)",
    "classifier": "a classifier: NAME KEY=VALUE ... ('' for none)",
}

#: Parameter types whose values are plugins the core builds for the plugin that declares
#: them (:class:`Part`), and the kind of plugin each names.
PLUGIN_TYPES = {
    "detector": "detector",
    "detectors": "detector",
    "verifier": "verifier",
    "classifier": "classifier",
}

#: The most integers an ``ints`` range such as ``1..10`` may expand to.
MAX_RANGE = 10_000

_TRUE = {"1", "true", "yes", "on"}
_FALSE = {"0", "false", "no", "off"}


class ParamError(TsrkitError):
    """A parameter value that its plugin's schema does not allow."""


@dataclass(frozen=True)
class Param:
    """One parameter of a plugin.

    Parameters
    ----------
    name : str
        Key used in ``--param name=value``, YAML configs and the Python API.
    type : str
        One of :data:`TYPES`.
    default : object
        Value used when the user gives none (``None`` means "not set").
    help : str
        One line for ``tsrkit plugins`` and error messages.
    min, max : float, optional
        Inclusive bounds, checked on every element for list types.
    choices : tuple, optional
        Allowed values.
    length : int, optional
        Required number of elements for list types.
    section : str
        The document section or table the default comes from.
    options : tuple of Param
        For a plugin type (:data:`PLUGIN_TYPES`): keys written among a part's own
        ``KEY=VALUE`` that the declaring plugin reads itself (:attr:`Part.options`), not the
        part's plugin.
    """

    name: str
    type: str
    default: Any = None
    help: str = ""
    min: float | None = None
    max: float | None = None
    choices: tuple | None = None
    length: int | None = None
    section: str = ""
    options: tuple[Param, ...] = ()

    def __post_init__(self):
        if self.type not in TYPES:
            raise ValueError(f"parameter {self.name!r}: unknown type {self.type!r}")
        if self.options and self.type not in PLUGIN_TYPES:
            raise ValueError(f"parameter {self.name!r}: only plugin types take options")

    def allowed(self) -> str:
        """Describe the allowed values in words."""
        text = TYPES[self.type]
        if self.choices is not None:
            text = "one of " + ", ".join(map(str, self.choices))
        if self.length is not None:
            text += f" of length {self.length}"
        if self.min is not None and self.max is not None:
            text += f" in [{self.min}, {self.max}]"
        elif self.min is not None:
            text += f" >= {self.min}"
        elif self.max is not None:
            text += f" <= {self.max}"
        return text

    def to_json(self) -> dict[str, Any]:
        """The schema entry as plain JSON data."""
        out = {
            "name": self.name,
            "type": self.type,
            "default": _jsonable(self.default),
            "help": self.help,
        }
        for key in ("min", "max", "length", "section"):
            if getattr(self, key) not in (None, ""):
                out[key] = getattr(self, key)
        if self.choices is not None:
            out["choices"] = list(self.choices)
        if self.options:
            out["options"] = [p.to_json() for p in self.options]
        return out

    def coerce(self, value: Any, owner: str) -> Any:
        """Convert ``value`` (object or string) to this parameter's type and check it."""
        if value is None:
            return None

        def fail(reason: str = "") -> ParamError:
            why = f" ({reason})" if reason else ""
            return ParamError(
                f"{owner}: parameter '{self.name}' must be {self.allowed()}; got {value!r}{why}"
            )

        try:
            out = _convert(self.type, value)
        except (TypeError, ValueError) as exc:
            raise fail(str(exc) if not isinstance(exc, ParamError) else "") from None
        items = out if isinstance(out, tuple) else (out,)
        if self.length is not None and isinstance(out, tuple) and len(out) != self.length:
            raise fail(f"{len(out)} elements")
        if self.type in ("ints", "floats") and not out:
            raise fail("empty list")
        if self.choices is not None and out not in self.choices:
            raise fail()
        if self.type in ("int", "float", "ints", "floats"):
            for item in items:
                if (self.min is not None and item < self.min) or (
                    self.max is not None and item > self.max
                ):
                    raise fail("out of range")
        return out


@dataclass(frozen=True)
class Part:
    """A plugin that another plugin is built on, made by the core from a plugin-typed
    parameter (:data:`PLUGIN_TYPES`): a ``union``'s member, a verifier's stage before it.

    ``str(part)`` is the spec it was made from (reports and cache keys show it).
    """

    plugin: Plugin = field(repr=False)
    spec: str
    options: dict[str, Any] = field(default_factory=dict)

    def __str__(self) -> str:
        return self.spec


def parse_parts(text: str) -> list[tuple[str, dict[str, str]]]:
    """``"a k=v; b"`` -> ``[("a", {"k": "v"}), ("b", {})]``: the plugins a plugin-typed
    parameter names, each with its own assignments.

    Raises
    ------
    ParamError
        A ``KEY=VALUE`` without ``=``.
    """
    parts = []
    for chunk in text.split(";"):
        words = chunk.split()
        if words:
            parts.append((words[0], parse_assignments(words[1:])))
    return parts


def _spec(kind: str, value: Any) -> str:
    """The canonical spec of a plugin-typed value: ``NAME K=V ...``, parts joined by ``; ``."""
    if isinstance(value, Part):
        value = value.spec
    elif isinstance(value, tuple | list) and all(isinstance(v, Part) for v in value):
        value = "; ".join(v.spec for v in value)
    if not isinstance(value, str):
        raise ValueError("not a string")
    parts = parse_parts(value)
    if kind != "detectors" and len(parts) > 1:
        raise ValueError("one plugin only")
    if kind == "detectors" and not parts:
        raise ValueError("no plugin named")
    return "; ".join(
        " ".join([name, *(f"{k}={v}" for k, v in assignments.items())])
        for name, assignments in parts
    )


def _jsonable(value: Any) -> Any:
    return list(value) if isinstance(value, tuple) else value


def _convert(kind: str, value: Any) -> Any:
    if kind in PLUGIN_TYPES:
        return _spec(kind, value) or None  # '' names no plugin
    if kind == "bool":
        if isinstance(value, bool):
            return value
        text = str(value).strip().lower()
        if text in _TRUE:
            return True
        if text in _FALSE:
            return False
        raise ValueError("not a boolean")
    if kind == "int":
        if isinstance(value, bool) or (isinstance(value, float) and not value.is_integer()):
            raise ValueError("not an integer")
        return int(str(value).strip()) if isinstance(value, str) else int(value)
    if kind == "float":
        if isinstance(value, bool):
            raise ValueError("not a number")
        number = float(value)
        if not math.isfinite(number):
            raise ValueError("not a finite number")
        return number
    if kind in ("str", "path"):
        if not isinstance(value, str):
            raise ValueError("not a string")
        if kind == "path" and os.path.exists(value) and not os.path.isdir(value):
            problem = not_regular(value)
            if problem:  # a FIFO or device would block whatever reads it
                raise ValueError(problem)
        return value
    element = "int" if kind == "ints" else "float"
    if isinstance(value, str):
        text = value.strip().strip("()[]")
        if kind == "ints" and ".." in text:
            lo, hi = (int(part) for part in text.split(".."))
            if hi - lo >= MAX_RANGE:
                raise ValueError(f"a range of {hi - lo + 1} integers; at most {MAX_RANGE}")
            return tuple(range(lo, hi + 1))
        value = [part for part in text.replace(" ", ",").split(",") if part]
    if not isinstance(value, Sequence):
        value = [value]
    return tuple(_convert(element, item) for item in value)


def validate(schema: Sequence[Param], given: Mapping[str, Any], owner: str) -> dict[str, Any]:
    """Check ``given`` against ``schema`` and return every parameter with its final value.

    Parameters
    ----------
    schema : sequence of Param
        The plugin's parameters.
    given : mapping
        User values, as objects or strings.
    owner : str
        How to name the plugin in messages, e.g. ``"detector 'conspicuity'"``.

    Raises
    ------
    ParamError
        For an unknown key, a wrong type or an out-of-range value.

    Examples
    --------
    >>> validate([Param("h_peak", "float", 0.9, min=0, max=1)], {"h_peak": "0.8"}, "d")
    {'h_peak': 0.8}
    """
    by_name = {p.name: p for p in schema}
    unknown = sorted(set(given) - set(by_name))
    if unknown:
        allowed = ", ".join(sorted(by_name)) or "none"
        raise ParamError(f"{owner}: unknown parameter '{unknown[0]}' (allowed: {allowed})")
    return {name: p.coerce(given.get(name, p.default), owner) for name, p in by_name.items()}


def parse_assignments(items: Iterable[str]) -> dict[str, str]:
    """Turn ``["a=1", "b=x"]`` into ``{"a": "1", "b": "x"}``; raise ParamError on bad syntax."""
    out = {}
    for item in items:
        key, sep, value = item.partition("=")
        if not sep or not key.strip():
            raise ParamError(f"--param expects key=value; got {item!r}")
        out[key.strip()] = value.strip()
    return out


#: The keys of a run configuration, and the largest one read (bytes).
CONFIG_KEYS = ("detector", "verifier", "classifier", "tracker", "description")
MAX_CONFIG_BYTES = 2**20


def load_config(path: str | os.PathLike) -> dict[str, Any]:
    """Read a YAML run configuration: a file, or the name of a shipped preset
    (:mod:`tsrkit.plugin.presets`).

    The file is a mapping whose optional keys ``detector``, ``verifier``, ``classifier`` and
    ``tracker`` are each either a plugin name or ``{"name": ..., "params": {...}}``, and
    ``description`` a line of text; any other key is refused with the closest known one. The
    file is read as :func:`tsrkit.core.files.read_yaml` reads (a regular file of at most
    :data:`MAX_CONFIG_BYTES`, bounded nesting and aliases, no repeated key).

    Raises
    ------
    ParamError
        When the file cannot be read or does not have that shape.
    """
    path = resolve_config(path)
    try:
        data = read_yaml(path, MAX_CONFIG_BYTES)
    except InputFileError as exc:
        raise ParamError(f"config {exc}") from None
    data = {} if data is None else data
    if not isinstance(data, dict):
        raise ParamError(f"config {path}: expected a mapping at the top level")
    _string_keys(data, f"config {path}")
    _known_keys(data, CONFIG_KEYS, f"config {path}")
    for kind in ("detector", "verifier", "classifier", "tracker"):
        entry = data.get(kind)
        if isinstance(entry, str):
            data[kind] = {"name": entry, "params": {}}
        elif entry is not None:
            if isinstance(entry, dict):
                _string_keys(entry, f"config {path}: '{kind}'")
                _known_keys(entry, ("name", "params"), f"config {path}: '{kind}'")
            if not isinstance(entry, dict) or not isinstance(entry.get("name"), str):
                raise ParamError(f"config {path}: '{kind}' must be a name or have a 'name' key")
            params = entry.get("params") or {}
            if not isinstance(params, dict):
                raise ParamError(f"config {path}: '{kind}.params' must be a mapping")
            _string_keys(params, f"config {path}: '{kind}.params'")
            data[kind] = {"name": entry["name"], "params": params}
    return data


def _known_keys(mapping: Mapping[str, Any], known: Sequence[str], owner: str) -> None:
    """Refuse a key that is not one of ``known``, suggesting the closest (a misspelt key would
    otherwise be ignored without a word).

    Examples
    --------
    >>> _known_keys({"clasifier": "ab-hist"}, CONFIG_KEYS, "run.yaml")  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    tsrkit.plugin.params.ParamError: run.yaml: unknown key 'clasifier'; did you mean 'classifier'? \
...
    """
    for key in mapping:
        if key not in known:
            close = difflib.get_close_matches(key, known, n=1)
            hint = f"; did you mean '{close[0]}'?" if close else ""
            raise ParamError(f"{owner}: unknown key {key!r}{hint} (known: {', '.join(known)})")


def _string_keys(mapping: Mapping[Any, Any], owner: str) -> None:
    """Refuse a mapping with a key that is not a string (YAML reads ``1:`` as an integer)."""
    for key in mapping:
        if not isinstance(key, str):
            raise ParamError(f"{owner}: key {key!r} is not a name (keys must be strings)")
