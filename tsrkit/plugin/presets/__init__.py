"""Named run configurations shipped with tsrkit (``--config NAME``, ``tsrkit presets``).

A preset is a YAML run configuration (:func:`tsrkit.plugin.params.load_config`) in this folder; its
``description`` key says in one line what it is for. ``--config`` takes a preset name wherever
it takes a file: a value is a file when it holds a path separator or ends in ``.yaml`` or
``.yml``, else a preset name (a file ``recommended`` in the working folder does not hide the
preset; write ``./recommended`` for it).

>>> "recommended" in preset_names()
True
>>> resolve_config("recommended").name
'recommended.yaml'
"""

from __future__ import annotations

import os
from pathlib import Path

import yaml

from tsrkit.core.errors import TsrkitError

__all__ = ["PRESET_DIR", "describe", "preset_names", "preset_path", "resolve_config"]

PRESET_DIR = Path(__file__).parent


def preset_names() -> list[str]:
    """The names of the shipped presets, sorted."""
    return sorted(p.stem for p in PRESET_DIR.glob("*.yaml"))


def preset_path(name: str) -> Path:
    """The YAML file of preset ``name``.

    Raises
    ------
    TsrkitError
        When no preset has that name (naming the presets there are).
    """
    path = PRESET_DIR / f"{name}.yaml"
    if name not in preset_names():
        raise TsrkitError(f"no preset called '{name}' (presets: {', '.join(preset_names())})")
    return path


def resolve_config(ref: str | os.PathLike) -> Path:
    """A run configuration's file: ``ref`` itself when it holds a path separator or ends in
    ``.yaml`` or ``.yml``, else the preset called ``ref``.

    Raises
    ------
    TsrkitError
        When ``ref`` is a name no preset has (saying how to name a file of that name).
    """
    text = os.fspath(ref)
    separators = {"/", os.sep, os.altsep} - {None}
    if any(s in text for s in separators) or Path(text).suffix.lower() in (".yaml", ".yml"):
        return Path(text)
    try:
        return preset_path(text)
    except TsrkitError as exc:
        hint = f"; for the file, write ./{text}" if Path(text).exists() else ""
        raise TsrkitError(f"{exc}{hint}") from None


def describe(name: str) -> str:
    """The preset's one-line ``description``."""
    with open(preset_path(name), encoding="utf-8") as fh:
        data = yaml.safe_load(fh) or {}
    return str(data.get("description", "")).strip()
