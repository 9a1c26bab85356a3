"""Opening a dataset by registry name, by the bundled ``sample`` name, or by path.

The format comes from the registry entry, from the caller, or from the format plugins'
``sniff`` when exactly one of them recognises the path.
"""

from __future__ import annotations

import dataclasses
import math
import os
import warnings
from collections.abc import Mapping
from pathlib import Path

from tsrkit.core.errors import TsrkitError, TsrkitWarning
from tsrkit.core.files import InputFileError, not_regular, read_json
from tsrkit.core.types import Annotation, Dataset
from tsrkit.datasets.errors import DatasetError
from tsrkit.datasets.registry import DatasetEntry, load_registry
from tsrkit.datasets.states import check_mapping, to_state
from tsrkit.plugin.registry import get_registry

__all__ = ["SAMPLE", "detect_format", "open_dataset", "read_dataset", "relabel"]

SAMPLE = "sample"


def open_dataset(
    ref: str | os.PathLike,
    format: str | None = None,
    images: str | os.PathLike | None = None,
    states: Mapping[str, str] | None = None,
) -> Dataset:
    """Read a dataset: a registry name, ``"sample"``, or a path to a file or folder.

    Parameters
    ----------
    ref : str or path-like
        A name from ``datasets.yaml`` (see :func:`tsrkit.datasets.load_registry`), the name
        ``"sample"`` (the bundled synthetic sample, generated on first use), or a path.
    format : str, optional
        A format plugin name; detected with the plugins' ``sniff`` when omitted.
    images : path-like, optional
        Folder that image paths inside the annotation file resolve against (default: the
        annotation file's folder).
    states : mapping, optional
        ``{raw label: state}`` overriding the registry entry's and the reader's mapping.

    Returns
    -------
    Dataset
        ``info`` carries the registry entry (licence, citation, ``box``, ``task``...) when
        opened by name, and ``opened_as``: the arguments that open it again (the path made
        absolute), which ``tsrkit report`` uses.

    Raises
    ------
    TsrkitError
        Unknown name, missing path, or a format that cannot be decided (naming the candidates).
    DatasetError
        A malformed annotation file (naming file, line or entry, and the problem).
    """
    images = Path(images) if images is not None else None
    entry = _registry_entry(ref)
    opened_as = {
        "ref": str(ref) if entry is not None or str(ref) == SAMPLE else str(Path(ref).resolve()),
        "format": format,
        "images": str(images.resolve()) if images is not None else None,
        "states": dict(states) if states else None,
    }
    if entry is None:
        path = _sample_path() if str(ref) == SAMPLE else Path(ref)
        dataset = read_dataset(path, format or detect_format(path), images)
        if str(ref) == SAMPLE:
            dataset = dataclasses.replace(dataset, name=SAMPLE)
    else:
        dataset = read_dataset(entry.annotation_path(), format or entry.format, images)
        dataset = dataclasses.replace(
            dataset, name=entry.name, info={**dataset.info, **entry.to_info()}
        )
        states = {**entry.states, **(states or {})}
    dataset = dataclasses.replace(dataset, info={**dataset.info, "opened_as": opened_as})
    return relabel(dataset, check_mapping(states, "states")) if states else dataset


def read_dataset(path: Path, format: str, images: Path | None = None) -> Dataset:
    """Read ``path`` with the format plugin called ``format``; every box is checked.

    Raises
    ------
    DatasetError
        A malformed file: the reader's own error, or one made here of what a reader let
        through (invalid UTF-8, values of the wrong type, a box that is not finite, or lies
        wholly outside the image size its sample declares), naming the file and the problem.

    Warns
    -----
    TsrkitWarning
        Boxes of zero width or height (a stray click in a labelling tool) are left out, and
        one warning names them.
    """
    reader = get_registry().create("format", format)
    try:
        dataset = reader.read(Path(path), images)
    except TsrkitError:
        raise
    except (UnicodeDecodeError, TypeError, KeyError, IndexError, ValueError, AttributeError) as exc:
        problem = f"malformed {format} data ({type(exc).__name__}: {exc})"
        raise DatasetError(path, problem) from None
    flat: list[str] = []
    for sample in dataset.samples:
        for k, ann in enumerate(sample.annotations):
            x0, y0, x1, y1 = (float(v) for v in ann.bbox)
            if not all(math.isfinite(v) for v in (x0, y0, x1, y1)) or x1 < x0 or y1 < y0:
                where = f"{Path(sample.source).name}, box {k}"
                raise DatasetError(
                    path, f"box {tuple(ann.bbox)} is not finite or has no area", where
                )
            if x1 == x0 or y1 == y0:
                flat.append(f"{Path(sample.source).name} box {k} {tuple(ann.bbox)}")
            w, h = sample.width, sample.height
            if w and h and (x0 >= w or y0 >= h or x1 <= 0 or y1 <= 0):
                where = f"{Path(sample.source).name}, box {k}"
                raise DatasetError(
                    path, f"box {tuple(ann.bbox)} lies outside the {w}x{h} image", where
                )
    if flat:
        warnings.warn(
            f"{path}: {len(flat)} box(es) of zero width or height left out: "
            + "; ".join(flat[:3])
            + ("; ..." if len(flat) > 3 else ""),
            TsrkitWarning,
            stacklevel=2,
        )
        dataset = _without_flat_boxes(dataset)
    return dataset


def _without_flat_boxes(dataset: Dataset) -> Dataset:
    """``dataset`` without its boxes of zero width or height."""
    return dataclasses.replace(
        dataset,
        samples=tuple(
            dataclasses.replace(
                sample,
                annotations=tuple(
                    a for a in sample.annotations if a.bbox[2] > a.bbox[0] and a.bbox[3] > a.bbox[1]
                ),
            )
            for sample in dataset.samples
        ),
    )


def detect_format(path: Path) -> str:
    """The one format plugin whose ``sniff`` accepts ``path``.

    Raises
    ------
    TsrkitError
        When none or several match, naming them and asking for ``--format``.
    """
    problem = None if Path(path).is_dir() else not_regular(path)
    if problem:
        raise DatasetError(path, problem)
    matched = [
        info.name
        for info in get_registry().plugins("format")
        if get_registry().create("format", info.name).sniff(Path(path))
    ]
    if len(matched) == 1:
        return matched[0]
    every = ", ".join(info.name for info in get_registry().plugins("format"))
    if matched:
        raise TsrkitError(
            f"{path}: several formats match ({', '.join(matched)}); "
            f"pass --format (format=...) to choose"
        )
    if Path(path).suffix.lower() == ".json":  # say why no JSON reader could read it
        try:
            read_json(path)
        except InputFileError as exc:
            if exc.problem.startswith("nested deeper"):
                raise DatasetError(path, exc.problem) from None
    raise TsrkitError(
        f"{path}: no format recognises it; pass --format (format=...), one of: {every}"
    )


def relabel(dataset: Dataset, states: Mapping[str, str]) -> Dataset:
    """Re-map every annotation whose raw ``attributes["label"]`` is a key of ``states``."""

    def remap(ann: Annotation) -> Annotation:
        label = ann.attributes.get("label")
        if label is None or label not in states:
            return ann
        return dataclasses.replace(ann, state=to_state(label, states))

    samples = tuple(
        dataclasses.replace(s, annotations=tuple(map(remap, s.annotations)))
        for s in dataset.samples
    )
    return dataclasses.replace(dataset, samples=samples)


def _registry_entry(ref: str | os.PathLike) -> DatasetEntry | None:
    """The registry entry ``ref`` names, None for a path; an error for neither."""
    if isinstance(ref, os.PathLike) or Path(ref).exists():
        return None
    registry = load_registry()
    if ref in registry:
        return registry[ref]
    if ref == SAMPLE:
        return None
    names = ", ".join(registry) or "none"
    raise TsrkitError(f"'{ref}' is neither a registered dataset ({names}) nor an existing path")


def _sample_path() -> Path:
    from tsrkit.datasets import scenes as synth  # cv2 and NumPy load only when the sample is made

    return Path(synth.sample_path())
