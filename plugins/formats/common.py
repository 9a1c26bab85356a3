"""Helpers the format plugins share: image paths, raw labels, checked boxes and JSON input."""

from __future__ import annotations

import json
import math
import os
from collections.abc import Iterable, Mapping, Sequence
from pathlib import Path
from typing import Any

from tsrkit.api import STATES, Annotation, Dataset, DatasetError, read_json, to_state


def resolve_image(base: Path, name: str, images: Path | None = None) -> str:
    """Absolute path of image ``name``: under ``images`` when given, else under ``base``.

    With ``images`` given, only the file name's path as written is joined to it (absolute
    names are kept as they are).
    """
    root = images if images is not None else base
    return absolute(Path(root) / name)


def absolute(path: str | os.PathLike) -> str:
    """``path`` made absolute and normalised, without following symbolic links."""
    return os.path.abspath(path)


def annotation(
    bbox: Sequence[float], label: Any, state: str | None = None, /, **attributes: Any
) -> Annotation:
    """An annotation whose raw ``label`` is kept in ``attributes["label"]``.

    ``state`` defaults to :func:`tsrkit.datasets.to_state` of the label. An attribute read
    from a file may be called ``label``, ``bbox`` or ``state`` without clashing (the raw label
    wins).
    """
    label = str(label)
    x_min, y_min, x_max, y_max = (float(v) for v in bbox)
    return Annotation(
        (x_min, y_min, x_max, y_max), state or to_state(label), {**attributes, "label": label}
    )


def raw_label(ann: Annotation) -> str:
    """The raw label a writer stores: ``attributes["label"]``, else the state."""
    return str(ann.attributes.get("label", ann.state))


def class_names(dataset: Dataset) -> list[str]:
    """Sorted distinct raw labels of a dataset (the class list writers emit)."""
    return sorted({raw_label(a) for s in dataset for a in s.annotations})


def extra_attributes(ann: Annotation) -> dict[str, Any]:
    """JSON-safe attributes other than the raw label (e.g. the synthetic ``radius``)."""
    return json_safe({k: v for k, v in ann.attributes.items() if k != "label"})


def json_safe(values: Mapping[str, Any]) -> dict[str, Any]:
    """The entries of ``values`` that survive a JSON round trip unchanged."""
    out = {}
    for key, value in values.items():
        try:
            if json.loads(json.dumps(value)) == value:
                out[str(key)] = value
        except (TypeError, ValueError):
            continue
    return out


def numbers(values: Any, count: int, path: Path, where: str) -> tuple[float, ...]:
    """Exactly ``count`` finite numbers from ``values``, or a DatasetError saying what is wrong."""
    try:
        out = tuple(float(v) for v in values)
    except (TypeError, ValueError):
        raise DatasetError(path, f"expected {count} numbers, got {values!r}", where) from None
    if len(out) != count or not all(math.isfinite(v) for v in out):
        raise DatasetError(path, f"expected {count} finite numbers, got {values!r}", where)
    return out


def checked_box(values: Iterable[Any], path: Path, where: str) -> tuple[float, ...]:
    """Four finite numbers ``(x_min, y_min, x_max, y_max)`` with min <= max, or a DatasetError."""
    box = numbers(values, 4, path, where)
    if box[0] > box[2] or box[1] > box[3]:
        raise DatasetError(path, f"box has min > max: {box}", where)
    return box


def explicit_state(record: Mapping[str, Any], path: Path, where: str) -> str | None:
    """The optional ``"state"`` key tsrkit writers add, checked against STATES."""
    state = record.get("state")
    if state is not None and state not in STATES:
        raise DatasetError(path, f"state {state!r} is not one of {', '.join(STATES)}", where)
    return state


def field(record: Any, key: str, kind: type | tuple[type, ...], path: Path, where: str) -> Any:
    """``record[key]`` checked to be of ``kind``; a DatasetError says what is missing or wrong."""
    if not isinstance(record, Mapping):
        raise DatasetError(path, f"expected an object, got {type(record).__name__}", where)
    if key not in record:
        raise DatasetError(path, f"missing '{key}'", where)
    value = record[key]
    kinds = kind if isinstance(kind, tuple) else (kind,)
    if not isinstance(value, kinds) or (isinstance(value, bool) and bool not in kinds):
        names = kind.__name__ if isinstance(kind, type) else " or ".join(k.__name__ for k in kind)
        raise DatasetError(path, f"'{key}' must be {names}, got {value!r}", where)
    return value


def optional(
    record: Mapping[str, Any], key: str, kind: type | tuple[type, ...], path: Path, where: str
) -> Any:
    """``record[key]`` when present and not null, checked like :func:`field`; else None."""
    return field(record, key, kind, path, where) if record.get(key) is not None else None


def attributes(record: Mapping[str, Any], path: Path, where: str) -> dict[str, Any]:
    """The optional ``"attributes"`` object tsrkit writers add to a box (empty when absent)."""
    return dict(optional(record, "attributes", dict, path, where) or {})


def sniff_json(path: Path, test) -> bool:
    """True when ``path`` is a ``.json`` file whose parsed content passes ``test``."""
    if not (path.is_file() and path.suffix.lower() == ".json"):
        return False
    try:
        return bool(test(read_json(path)))
    except DatasetError:
        return False


def unique_path(path: Path, used: set[Path]) -> Path:
    """``path``, or ``stem_N.suffix`` when an earlier sample already took that name."""
    candidate, n = path, 1
    while candidate in used:
        candidate = path.with_name(f"{path.stem}_{n}{path.suffix}")
        n += 1
    used.add(candidate)
    return candidate
