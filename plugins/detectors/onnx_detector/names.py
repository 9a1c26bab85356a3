"""Class names of a detection model, and the signal state a class name says.

The names come from, in this order: the ``names`` parameter (``red,yellow,green``); a file
beside the model with the model's name and ``.yaml``, ``.yml`` or ``.json`` (``model.onnx``:
``model.yaml``) holding ``names:`` as a list or an ``{id: name}`` mapping (an Ultralytics
data YAML serves); the ``names`` entry Ultralytics writes into the ONNX model's metadata
(``{0: 'person', 1: 'bicycle', ...}``, read as a Python literal, never evaluated).
"""

from __future__ import annotations

import ast
from collections.abc import Mapping
from pathlib import Path
from typing import Any

from tsrkit.api import DatasetError, ModelError, read_json, read_yaml, to_state

#: Suffixes of the class-names file beside a model.
NAMES_SUFFIXES = (".yaml", ".yml", ".json")


def parse_names(value: Any, where: str) -> list[str]:
    """Class names from a list, or from an ``{id: name}`` mapping whose ids are 0..n-1.

    Raises
    ------
    ModelError
        Naming ``where`` when ``value`` is neither.

    Examples
    --------
    >>> parse_names({1: "green", 0: "red"}, "x")
    ['red', 'green']
    >>> parse_names(["red", "green"], "x")
    ['red', 'green']
    """
    if isinstance(value, Mapping):
        try:
            ids = sorted(int(k) for k in value)
        except (TypeError, ValueError):
            ids = []
        if ids == list(range(len(value))) and ids:
            by_id = {int(k): v for k, v in value.items()}
            return [str(by_id[i]) for i in ids]
    elif isinstance(value, list) and value:
        return [str(v) for v in value]
    raise ModelError(f"{where}: 'names' must be a list or a mapping of ids 0..n-1 to names")


def file_names(model: Path) -> list[str] | None:
    """The names of the first of ``model``'s names files that exists, else None.

    Raises
    ------
    ModelError
        When that file cannot be read or has no usable ``names``.
    """
    for suffix in NAMES_SUFFIXES:
        path = model.with_suffix(suffix)
        if path.is_file():
            try:
                data = read_json(path) if suffix == ".json" else read_yaml(path)
            except DatasetError as exc:
                raise ModelError(str(exc)) from None
            if not isinstance(data, Mapping) or "names" not in data:
                raise ModelError(f"{path}: no 'names' in this class-names file")
            return parse_names(data["names"], str(path))
    return None


def metadata_names(metadata: Mapping[str, str], model: Path) -> list[str] | None:
    """The names in the model's Ultralytics metadata, else None.

    Examples
    --------
    >>> metadata_names({"names": "{0: 'red', 1: 'green'}"}, Path("m.onnx"))
    ['red', 'green']
    """
    text = metadata.get("names")
    if text is None:
        return None
    try:
        value = ast.literal_eval(text)
    except (ValueError, SyntaxError, MemoryError, RecursionError):
        raise ModelError(f"{model}: the 'names' metadata is not a list or mapping") from None
    return parse_names(value, f"{model}: metadata")


def class_names(given: str | None, model: Path, metadata: Mapping[str, str]) -> list[str] | None:
    """The model's class names by the rules of this module, or None when nothing names them."""
    if given:
        return [name.strip() for name in given.split(",")]
    return file_names(model) or metadata_names(metadata, model)


def state_of(name: str) -> str | None:
    """The state a class name says: :func:`tsrkit.api.to_state` of the name, else of its tail
    after each ``_``, ``-`` or space in turn (``tl_red_yellow``: ``red_yellow``), else None.

    Examples
    --------
    >>> [state_of(n) for n in ("Red", "GreenLeft", "tl_amber", "traffic light", "off")]
    ['red', 'green', 'yellow', None, 'off']
    >>> state_of("tl-red-yellow")
    'red_yellow'
    """
    words = name.replace("-", "_").replace(" ", "_").split("_")
    for i in range(len(words)):
        state = to_state("_".join(words[i:]))
        if state != "unknown":
            return state
    return None
