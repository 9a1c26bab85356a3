"""DriveU Traffic Light Dataset (DTLD) JSON label files (version 2.0 layout).

``{"images": [{"image_path", "labels": [{"x", "y", "w", "h", "unique_id", "track_id",
"attributes": {"state", "direction", "relevance", "occlusion", "orientation", "aspects",
"pictogram", "reflection"}}]}]}``; boxes are ``x, y, w, h`` pixels of the housing. The raw
``attributes.state`` is the label: red, yellow, green and off map to themselves,
``red_yellow`` (red and yellow lit together, German "get ready") maps to red — the vehicle must
still stop; change it per dataset with a ``states:`` entry — and ``unknown`` stays unknown.
Image paths resolve against the JSON file's folder (or ``--images``).
"""

from __future__ import annotations

from pathlib import Path

from tsrkit.api import Dataset, DatasetError, DatasetFormat, Sample, hookimpl
from tsrkit_plugins.formats.common import (
    annotation,
    checked_box,
    field,
    json_safe,
    numbers,
    read_json,
    resolve_image,
    sniff_json,
)

STATES = {
    "red": "red",
    "yellow": "yellow",
    "green": "green",
    "off": "off",
    "red_yellow": "red_yellow",
    "unknown": "unknown",
}


def _is_dtld(data) -> bool:
    return (
        isinstance(data, dict)
        and isinstance(data.get("images"), list)
        and bool(data["images"])
        and isinstance(data["images"][0], dict)
        and "image_path" in data["images"][0]
    )


class Dtld(DatasetFormat):
    name = "dtld"
    summary = "DriveU Traffic Light Dataset JSON (v2 labels with attributes.state)"
    section = "Fregin et al., ICRA 2018 (DTLD label format v2)"

    def sniff(self, path: Path) -> bool:
        return sniff_json(Path(path), _is_dtld)

    def read(self, path: Path, images: Path | None = None) -> Dataset:
        file = Path(path)
        data = read_json(file)
        if not _is_dtld(data):
            raise DatasetError(file, 'expected {"images": [{"image_path", "labels"}]}')
        samples = tuple(
            _sample(file, entry, f"images[{i}]", images) for i, entry in enumerate(data["images"])
        )
        return Dataset(file.stem, samples, self.name, str(file.parent), {"box": "housing"})


def _sample(file: Path, entry, where: str, images: Path | None) -> Sample:
    annotations = []
    for j, label in enumerate(field(entry, "labels", list, file, where)):
        at = f"{where}.labels[{j}]"
        x, y, w, h = numbers([field(label, k, (int, float), file, at) for k in "xywh"], 4, file, at)
        bbox = checked_box((x, y, x + w, y + h), file, at)
        attributes = field(label, "attributes", dict, file, at)
        state = field(attributes, "state", str, file, f"{at}.attributes")
        if state not in STATES:
            raise DatasetError(
                file,
                f"unknown state {state!r} (expected one of {', '.join(STATES)})",
                f"{at}.attributes",
            )
        extra = json_safe({k: v for k, v in attributes.items() if k != "state"})
        ids = {k: label[k] for k in ("unique_id", "track_id") if k in label}
        annotations.append(annotation(bbox, state, STATES[state], **{**extra, **ids}))
    metadata = {"timestamp": entry["time_stamp"]} if "time_stamp" in entry else {}
    return Sample(
        resolve_image(file.parent, field(entry, "image_path", str, file, where), images),
        tuple(annotations),
        metadata=metadata,
    )


@hookimpl
def register_dataset_formats(register):
    register(Dtld)
