"""Bosch Small Traffic Lights Dataset (BSTLD) YAML and JSON label files.

A list of ``{"path": image, "boxes": [{"label", "occluded", "x_min", "y_min", "x_max",
"y_max"}]}`` (the JSON variant holds the same list). Image paths resolve against the label
file's folder; the original ``test.yaml`` holds absolute paths of the authors' machine, so an
absolute path that does not exist is looked up by file name under ``--images``.

The 14 raw labels map onto states by their colour word (:data:`LABELS`). Known bad boxes are
repaired and counted in ``Dataset.info["repaired"]``: swapped corners (x_min > x_max or
y_min > y_max) are swapped back, and boxes reaching outside the image (``width`` x ``height``
parameters, 1280x720 for BSTLD) are clipped to it; a box with no area left is dropped and
counted in ``info["dropped"]``. The YAML files write the label ``off`` unquoted, which YAML 1.1
loads as boolean False; it is read back as ``off``.
"""

from __future__ import annotations

from pathlib import Path

from tsrkit.api import Dataset, DatasetError, DatasetFormat, Param, Sample, hookimpl, read_yaml
from tsrkit_plugins.formats.common import absolute, annotation, field, numbers, read_json

#: The 14 BSTLD labels and the state each means (arrows keep their colour).
LABELS = {
    "Red": "red",
    "RedLeft": "red",
    "RedRight": "red",
    "RedStraight": "red",
    "RedStraightLeft": "red",
    "RedStraightRight": "red",
    "Yellow": "yellow",
    "Green": "green",
    "GreenLeft": "green",
    "GreenRight": "green",
    "GreenStraight": "green",
    "GreenStraightLeft": "green",
    "GreenStraightRight": "green",
    "off": "off",
}
COORDS = ("x_min", "y_min", "x_max", "y_max")


def _load(file: Path):
    if file.suffix.lower() == ".json":
        return read_json(file)
    return read_yaml(file)


def _is_bosch(data) -> bool:
    return (
        isinstance(data, list)
        and bool(data)
        and isinstance(data[0], dict)
        and {"path", "boxes"} <= set(data[0])
    )


def repair_box(
    box: tuple[float, ...], width: float, height: float
) -> tuple[tuple[float, float, float, float], bool]:
    """Swap reversed corners and clip to the image; returns the box and whether it changed."""
    x0, y0, x1, y1 = box
    x0, x1 = sorted((x0, x1))
    y0, y1 = sorted((y0, y1))
    fixed = (
        min(max(x0, 0.0), width),
        min(max(y0, 0.0), height),
        min(max(x1, 0.0), width),
        min(max(y1, 0.0), height),
    )
    return fixed, fixed != tuple(box)


class Bosch(DatasetFormat):
    name = "bosch"
    summary = "Bosch Small Traffic Lights YAML/JSON (14 labels -> states, bad boxes repaired)"
    section = "Behrendt, Novak & Botros, ICRA 2017 (BSTLD label files)"
    PARAMS = (
        Param("width", "int", 1280, min=1, help="Image width for clipping boxes", section="BSTLD"),
        Param("height", "int", 720, min=1, help="Image height for clipping boxes", section="BSTLD"),
    )

    def sniff(self, path: Path) -> bool:
        path = Path(path)
        if not (path.is_file() and path.suffix.lower() in (".yaml", ".yml", ".json")):
            return False
        try:
            return _is_bosch(_load(path))
        except DatasetError:
            return False

    def read(self, path: Path, images: Path | None = None) -> Dataset:
        file = Path(path)
        data = _load(file)
        if not isinstance(data, list):
            raise DatasetError(file, "expected a list of {path, boxes} entries")
        counts = {"repaired": 0, "dropped": 0}
        samples = tuple(
            self._sample(file, entry, f"entry {i}", images, counts) for i, entry in enumerate(data)
        )
        return Dataset(
            file.stem, samples, self.name, str(file.parent), {**counts, "box": "housing"}
        )

    def _sample(self, file: Path, entry, where: str, images: Path | None, counts) -> Sample:
        width, height = self.params["width"], self.params["height"]
        annotations = []
        for j, box in enumerate(field(entry, "boxes", list, file, where)):
            at = f"{where} box {j}"
            label = _label(field(box, "label", (str, bool), file, at))
            if label not in LABELS:
                raise DatasetError(
                    file, f"unknown label {label!r} (expected one of {', '.join(LABELS)})", at
                )
            raw = numbers([field(box, k, (int, float), file, at) for k in COORDS], 4, file, at)
            bbox, changed = repair_box(raw, width, height)
            counts["repaired"] += changed
            if bbox[2] <= bbox[0] or bbox[3] <= bbox[1]:
                counts["dropped"] += 1
                continue
            annotations.append(
                annotation(bbox, label, LABELS[label], occluded=bool(box.get("occluded", False)))
            )
        return Sample(
            _image(file, field(entry, "path", str, file, where), images),
            tuple(annotations),
            width,
            height,
        )


def _label(value: str | bool) -> str:
    """The raw label; the unquoted ``off`` of the YAML files loads as boolean False."""
    return "off" if value is False else str(value)


def _image(file: Path, written: str, images: Path | None) -> str:
    path = Path(written)
    if path.is_absolute():
        chosen = path if path.exists() or images is None else images / path.name
    else:
        chosen = (images if images is not None else file.parent) / path
    return absolute(chosen)


@hookimpl
def register_dataset_formats(register):
    register(Bosch)
