"""The normalised JSON label file of ``shared/datasets`` (``annotations.json``): read and write.

A list of ``{"file", "split", "width", "height", "boxes": [{"label", "x_min", "y_min", "x_max",
"y_max"}]}`` in absolute pixels, image paths relative to the JSON file's folder. tsrkit adds two
optional keys that round-trip what the base format cannot hold: per box ``"state"`` (when it is
not what the label maps to) and ``"attributes"``; per record ``"metadata"`` (e.g. ``lighting``).
"""

from __future__ import annotations

from pathlib import Path

from tsrkit.api import Dataset, DatasetError, DatasetFormat, Sample, hookimpl, to_state, write_json
from tsrkit_plugins.formats.common import (
    annotation,
    attributes,
    checked_box,
    explicit_state,
    extra_attributes,
    field,
    json_safe,
    optional,
    raw_label,
    read_json,
    resolve_image,
    sniff_json,
)
from tsrkit_plugins.shared.paths import relative_source

FILE_NAME = "annotations.json"
COORDS = ("x_min", "y_min", "x_max", "y_max")


def _is_normalized(data) -> bool:
    return isinstance(data, list) and all(
        isinstance(r, dict) and "file" in r and "boxes" in r for r in data[:5]
    )


def annotation_file(path: Path) -> Path:
    """The JSON file itself, or ``annotations.json`` inside a folder."""
    return path / FILE_NAME if path.is_dir() else path


class Normalized(DatasetFormat):
    name = "normalized"
    summary = "Normalised JSON of shared/datasets (annotations.json), read and write"
    section = "shared/datasets/README.md"
    writable = True

    def sniff(self, path: Path) -> bool:
        return sniff_json(annotation_file(Path(path)), _is_normalized)

    def read(self, path: Path, images: Path | None = None) -> Dataset:
        file = annotation_file(Path(path))
        data = read_json(file)
        if not isinstance(data, list):
            raise DatasetError(file, "expected a list of image records")
        samples = tuple(
            _sample(file, record, f"entry {i}", images) for i, record in enumerate(data)
        )
        return Dataset(
            file.parent.name, samples, self.name, str(file.parent), {"annotation_file": str(file)}
        )

    def write(self, dataset: Dataset, out: Path) -> None:
        out = Path(out)
        write_json(out, [_record(s, out.parent) for s in dataset])


def _sample(file: Path, record, where: str, images: Path | None) -> Sample:
    name = field(record, "file", str, file, where)
    boxes = field(record, "boxes", list, file, where)
    annotations = []
    for j, box in enumerate(boxes):
        at = f"{where} box {j}"
        label = str(field(box, "label", (str, int), file, at))
        bbox = checked_box([field(box, k, (int, float), file, at) for k in COORDS], file, at)
        annotations.append(
            annotation(bbox, label, explicit_state(box, file, at), **attributes(box, file, at))
        )
    size = {k: record[k] for k in ("width", "height") if isinstance(record.get(k), int)}
    return Sample(
        resolve_image(file.parent, name, images),
        tuple(annotations),
        split=optional(record, "split", str, file, where),
        metadata=dict(optional(record, "metadata", dict, file, where) or {}),
        **size,
    )


def _record(sample: Sample, folder: Path) -> dict:
    boxes = []
    for ann in sample.annotations:
        label = raw_label(ann)
        box = {"label": label, **{k: float(v) for k, v in zip(COORDS, ann.bbox)}}
        if ann.state != to_state(label):
            box["state"] = ann.state
        extra = extra_attributes(ann)
        if extra:
            box["attributes"] = extra
        boxes.append(box)
    record = {
        "file": relative_source(sample.source, folder),
        "split": sample.split,
        "width": sample.width,
        "height": sample.height,
        "boxes": boxes,
    }
    metadata = json_safe(sample.metadata)
    if metadata:
        record["metadata"] = metadata
    return record


@hookimpl
def register_dataset_formats(register):
    register(Normalized)
