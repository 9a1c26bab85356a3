"""Several datasets as one: ``NAME[:SPLIT]`` references and their concatenation.

``tsrkit train --dataset A:valid --dataset B --split train`` opens ``A``'s valid split and
``B``'s train split and trains on both; the Python API uses the same two functions.

>>> from tsrkit.datasets import open_datasets
>>> both = open_datasets(["roboflow_cinta_v2_id:valid", "dtld_fridtjofs"], split="train")
...     # doctest: +SKIP
"""

from __future__ import annotations

import os
from collections.abc import Iterable, Mapping, Sequence
from pathlib import Path

from tsrkit.core.errors import TsrkitError
from tsrkit.core.types import Dataset
from tsrkit.datasets.registry import load_registry

__all__ = ["concat_datasets", "dataset_inputs", "open_datasets", "parse_reference"]


def parse_reference(ref: str, split: str | None = None) -> tuple[str, str | None]:
    """Split ``NAME[:SPLIT]`` into the dataset reference and its split (``split`` if none).

    An existing path is taken whole, so a path that contains a colon still opens.

    Examples
    --------
    >>> parse_reference("dtld_fridtjofs:test")
    ('dtld_fridtjofs', 'test')
    >>> parse_reference("dtld_fridtjofs", "train")
    ('dtld_fridtjofs', 'train')
    """
    name, colon, own = str(ref).rpartition(":")
    if not colon or not name or Path(ref).exists() or "/" in own or os.sep in own:
        return str(ref), split
    if not own:
        raise TsrkitError(f"dataset '{ref}': empty split after ':' (write NAME or NAME:SPLIT)")
    return name, own


def concat_datasets(datasets: Sequence[Dataset]) -> Dataset:
    """One dataset holding every sample of ``datasets``, in order.

    The name joins the parts' names with ``+``; ``info`` keeps the facts the parts agree on
    (for example the ``box`` convention) and lists the parts under ``parts``.

    Raises
    ------
    TsrkitError
        When no dataset is given.
    """
    if not datasets:
        raise TsrkitError("no dataset to concatenate")
    if len(datasets) == 1:
        return datasets[0]
    shared = _agreed([d.info for d in datasets])
    formats = {d.format for d in datasets}
    return Dataset(
        "+".join(d.name for d in datasets),
        tuple(s for d in datasets for s in d.samples),
        formats.pop() if len(formats) == 1 else "mixed",
        "",
        {**shared, "parts": [d.name for d in datasets]},
    )


def open_datasets(
    refs: Sequence[str],
    split: str | None = None,
    format: str | None = None,
    images: str | os.PathLike | None = None,
) -> Dataset:
    """Open each ``NAME[:SPLIT]`` of ``refs`` (``split`` for those without their own) and
    concatenate them.

    Raises
    ------
    TsrkitError
        An unknown dataset, or a split that leaves a dataset empty (naming its splits).
    """
    import tsrkit.datasets  # the package attribute, so that a patched open_dataset is used

    parts = []
    for ref in refs:
        name, own = parse_reference(ref, split)
        dataset = tsrkit.datasets.open_dataset(name, format=format, images=images)
        if own is not None:
            chosen = dataset.split(own)
            if not len(chosen):
                present = sorted({str(s.split) for s in dataset.samples})
                raise TsrkitError(
                    f"dataset '{name}' has no samples in split '{own}' "
                    f"(its splits: {', '.join(present)})"
                )
            dataset = chosen
        parts.append(dataset)
    return concat_datasets(parts)


def _agreed(infos: Sequence[Mapping]) -> dict:
    """The key/value pairs every mapping of ``infos`` has alike."""
    first, *rest = infos
    return {k: v for k, v in first.items() if all(k in i and i[k] == v for i in rest)}


def dataset_inputs(refs: Iterable[str], dataset) -> list[str]:
    """What a run on ``dataset`` reads: the annotation file or folder of each reference
    (a registered name, ``NAME:SPLIT``, or a path) and every sample's image."""
    registry = load_registry()
    files = []
    for ref in refs:
        name, _ = parse_reference(ref, None)
        entry = registry.get(name)
        files.append(str(entry.annotation_path()) if entry is not None else name)
    return [*files, *(s.source for s in dataset.samples if s.source)]
