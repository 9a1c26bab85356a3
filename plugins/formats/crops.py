"""Crop folders for state classification: ``labels.csv`` (file,label[,split,condition...]) or
folder name = label. Each crop becomes a Sample with ONE annotation covering the whole image.

Layouts read: ``ROOT/labels.csv`` (columns ``file`` and ``label`` required; ``split``,
``width``, ``height`` and ``condition`` used when present: ``condition`` day/night goes to
``Sample.metadata["lighting"]``), else ``ROOT/<label>/*.png`` or ``ROOT/<split>/<label>/*.png``
with split one of train, valid, val, test.
"""

from __future__ import annotations

import csv
import io
from pathlib import Path
from typing import Any

from tsrkit.api import (
    IMAGE_EXTENSIONS,
    Dataset,
    DatasetError,
    DatasetFormat,
    Sample,
    hookimpl,
    image_size,
    read_text,
)
from tsrkit_plugins.formats.common import absolute, annotation, resolve_image

LABELS = "labels.csv"
SPLITS = {"train": "train", "valid": "valid", "val": "valid", "test": "test"}
#: Files whose presence anywhere below means the folder is an annotated dataset, not crops.
ANNOTATION_SUFFIXES = {".json", ".yaml", ".yml", ".xml", ".csv", ".txt"}


def _header(path: Path) -> list[str]:
    with open(path, newline="", encoding="utf-8", errors="replace") as fh:
        return next(csv.reader(fh), [])


def _has_labels_csv(root: Path) -> bool:
    file = root / LABELS
    return file.is_file() and {"file", "label"} <= set(_header(file))


def _image_files(root: Path) -> list[Path]:
    return sorted(
        p for p in root.rglob("*") if p.suffix.lower() in IMAGE_EXTENSIONS and p.is_file()
    )


def _looks_like_label_folders(root: Path) -> bool:
    if any(p.suffix.lower() in ANNOTATION_SUFFIXES for p in root.rglob("*")):
        return False
    images = _image_files(root)
    return bool(images) and all(len(p.relative_to(root).parts) in (2, 3) for p in images)


def crop_sample(
    source: str, label: str, width: int, height: int, split: str | None = None, **metadata
) -> Sample:
    """A crop: one annotation ``(0, 0, width, height)`` with the crop's label and state."""
    return Sample(
        source, (annotation((0, 0, width, height), label),), width, height, split, metadata
    )


class Crops(DatasetFormat):
    name = "crops"
    summary = "Crop folders (labels.csv or folder name = label) for state classification"
    section = "shared/datasets/README.md"

    def sniff(self, path: Path) -> bool:
        path = Path(path)
        if path.is_file():
            return path.name == LABELS and {"file", "label"} <= set(_header(path))
        return path.is_dir() and (_has_labels_csv(path) or _looks_like_label_folders(path))

    def read(self, path: Path, images: Path | None = None) -> Dataset:
        path = Path(path)
        root = path.parent if path.is_file() else path
        if path.is_file() or _has_labels_csv(root):
            samples = _from_csv(root / LABELS if path.is_dir() else path, images)
        elif path.is_dir():
            samples = _from_folders(root)
        else:
            raise DatasetError(path, "no such crop folder or labels.csv")
        if not samples:
            raise DatasetError(path, "no crops found")
        return Dataset(
            root.name,
            tuple(samples),
            self.name,
            str(root),
            {"task": "classification", "box": "crop"},
        )


def _from_csv(file: Path, images: Path | None) -> list[Sample]:
    samples = []
    with io.StringIO(read_text(file), newline="") as fh:
        reader = csv.DictReader(fh)
        missing = {"file", "label"} - set(reader.fieldnames or ())
        if missing:
            raise DatasetError(file, f"missing column(s) {', '.join(sorted(missing))}", "line 1")
        for row in reader:
            where = f"line {reader.line_num}"
            if not row["file"] or not row["label"]:
                raise DatasetError(file, "empty file or label", where)
            source = resolve_image(file.parent, row["file"], images)
            size = _size(file, row, source, where)
            metadata: dict[str, Any] = (
                {"lighting": row["condition"]} if row.get("condition") else {}
            )
            samples.append(
                crop_sample(
                    source, row["label"], *size, SPLITS.get(row.get("split") or ""), **metadata
                )
            )
    return samples


def _size(file: Path, row: dict, source: str, where: str) -> tuple[int, int]:
    if row.get("width") and row.get("height"):
        try:
            return int(row["width"]), int(row["height"])
        except ValueError:
            raise DatasetError(
                file,
                f"width/height must be integers, got {row['width']!r}, {row['height']!r}",
                where,
            ) from None
    return image_size(source)


def _from_folders(root: Path) -> list[Sample]:
    samples = []
    for image in _image_files(root):
        parts = image.relative_to(root).parts
        split = SPLITS.get(parts[0]) if len(parts) == 3 else None
        samples.append(crop_sample(absolute(image), parts[-2], *image_size(image), split))
    return samples


@hookimpl
def register_dataset_formats(register):
    register(Crops)
