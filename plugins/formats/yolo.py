"""YOLO txt labels + ``data.yaml`` (Ultralytics layout): read and write.

``data.yaml`` gives the class ``names`` (list or ``{id: name}``) and the ``train`` / ``val`` /
``test`` image folders (or ``.txt`` lists of images), relative to its ``path`` key or its own
folder. Each image's labels sit in the sibling ``labels`` folder (the last ``images`` path part
replaced by ``labels``), one object per line in coordinates normalised to [0, 1]:
``class cx cy w h`` for a box, or ``class x1 y1 x2 y2 ...`` for a polygon of a segmentation
export (real exports mix both; the box is the min/max of the points). The image size, needed to
turn these into pixels, is read from the file header only when the label file has lines.
"""

from __future__ import annotations

import os
import shutil
from pathlib import Path

import yaml

from tsrkit.api import (
    IMAGE_EXTENSIONS,
    Dataset,
    DatasetError,
    DatasetFormat,
    Sample,
    atomic_open,
    hookimpl,
    image_size,
    read_text,
    read_yaml,
)
from tsrkit_plugins.formats.common import (
    absolute,
    annotation,
    class_names,
    numbers,
    raw_label,
    unique_path,
)

DATA_YAML = "data.yaml"
SPLIT_KEYS = {"train": "train", "val": "valid", "test": "test"}


def _data_yaml(path: Path) -> Path:
    return path / DATA_YAML if path.is_dir() else path


def read_data_yaml(file: Path) -> dict:
    """The parsed ``data.yaml``; a DatasetError when it is not YAML or has no ``names``."""
    data = read_yaml(file)
    if not isinstance(data, dict) or not isinstance(data.get("names"), (list, dict)):
        raise DatasetError(file, "expected a mapping with 'names' (list or id: name)", "names")
    return data


def class_table(data: dict, file: Path) -> dict[int, str]:
    """``{class id: name}`` from the ``names`` of the data.yaml ``file``."""
    names = data["names"]
    pairs = names.items() if isinstance(names, dict) else enumerate(names)
    table = {}
    for key, name in pairs:
        if isinstance(key, str) and key.strip().isdecimal():
            key = int(key)
        if isinstance(key, bool) or not isinstance(key, int):
            raise DatasetError(file, f"class id {key!r} is not an integer", "names")
        table[key] = str(name)
    return table


def labels_path(image: Path) -> Path:
    """The label file of ``image``: last ``images`` part replaced by ``labels``, ``.txt``."""
    parts = list(image.parts)
    for i in range(len(parts) - 1, -1, -1):
        if parts[i] == "images":
            parts[i] = "labels"
            break
    return Path(*parts).with_suffix(".txt")


def yolo_box(values: tuple[float, ...], width: int, height: int) -> tuple[float, ...]:
    """Pixels ``(x_min, y_min, x_max, y_max)`` of a normalised box or polygon line."""
    if len(values) == 4:
        cx, cy, w, h = values
        return (
            (cx - w / 2) * width,
            (cy - h / 2) * height,
            (cx + w / 2) * width,
            (cy + h / 2) * height,
        )
    xs, ys = values[0::2], values[1::2]
    return min(xs) * width, min(ys) * height, max(xs) * width, max(ys) * height


class Yolo(DatasetFormat):
    name = "yolo"
    summary = "YOLO txt labels + data.yaml, boxes and segmentation polygons; read and write"
    section = "docs.ultralytics.com/datasets/detect"
    writable = True

    def sniff(self, path: Path) -> bool:
        file = _data_yaml(Path(path))
        if not (file.is_file() and file.suffix in (".yaml", ".yml")):
            return False
        try:
            read_data_yaml(file)
        except DatasetError:
            return False
        return True

    def read(self, path: Path, images: Path | None = None) -> Dataset:
        file = _data_yaml(Path(path))
        data = read_data_yaml(file)
        classes = class_table(data, file)
        base = file.parent / str(data.get("path") or ".")
        samples: list[Sample] = []
        missing: list[str] = []
        for key, split in SPLIT_KEYS.items():
            if not data.get(key):
                continue
            entries = data[key] if isinstance(data[key], list) else [data[key]]
            for entry in entries:
                if not isinstance(entry, str):
                    raise DatasetError(
                        file, f"'{key}' must be a folder or list file, got {entry!r}"
                    )
                found = _split_images(base, entry, images)
                if found is None:
                    missing.append(split)
                    continue
                samples.extend(_sample(image, split, classes, file) for image in found)
        if not samples:
            raise DatasetError(file, "no images found under its train/val/test entries")
        info = {"classes": [classes[k] for k in sorted(classes)], "missing_splits": missing}
        return Dataset(file.parent.name, tuple(samples), self.name, str(file.parent), info)

    def write(self, dataset: Dataset, out: Path) -> None:
        out = Path(out)
        names = class_names(dataset)
        ids = {name: i for i, name in enumerate(names)}
        used: set[Path] = set()
        splits = set()
        for sample in dataset:
            split = sample.split if sample.split in ("train", "valid", "test") else "train"
            splits.add(split)
            image = unique_path(out / split / "images" / Path(sample.source).name, used)
            _place_image(Path(sample.source), image)
            size = (
                (sample.width, sample.height)
                if sample.width and sample.height
                else image_size(sample.source)
            )
            with atomic_open(labels_path(image)) as fh:
                fh.writelines(
                    _label_line(ids[raw_label(a)], a.bbox, *size) + "\n" for a in sample.annotations
                )
        data = {"names": names, "nc": len(names)}
        data.update(
            {key: f"{split}/images" for key, split in SPLIT_KEYS.items() if split in splits}
        )
        with atomic_open(out / DATA_YAML) as fh:
            yaml.safe_dump(data, fh, sort_keys=False)


def _split_images(base: Path, entry: str, images: Path | None) -> list[Path] | None:
    """The images a train/val/test entry names, or None when its folder or list is missing."""
    target = base / entry
    if not target.exists() and entry.startswith("../"):
        target = base / entry[3:]  # Roboflow exports write ../test/images beside data.yaml
    if target.is_dir():
        return sorted(p for p in target.iterdir() if p.suffix.lower() in IMAGE_EXTENSIONS)
    if target.is_file():
        root = images if images is not None else target.parent
        return [
            Path(absolute(root / line.strip()))
            for line in read_text(target).splitlines()
            if line.strip()
        ]
    return None


def _sample(image: Path, split: str, classes: dict[int, str], data_file: Path) -> Sample:
    label_file = labels_path(image)
    lines = read_text(label_file).splitlines() if label_file.is_file() else []
    rows = [(n, line.split()) for n, line in enumerate(lines, 1) if line.strip()]
    if not rows:
        return Sample(absolute(image), (), split=split)
    width, height = image_size(image)
    annotations = []
    for number, tokens in rows:
        where = f"line {number}"
        if not tokens[0].isdecimal() or int(tokens[0]) not in classes:
            raise DatasetError(
                label_file, f"class {tokens[0]!r} is not an id of {data_file.name} names", where
            )
        count = len(tokens) - 1
        if count != 4 and (count < 6 or count % 2):
            raise DatasetError(
                label_file,
                f"expected 4 box values or an even number >= 6 of polygon values, got {count}",
                where,
            )
        values = numbers(tokens[1:], count, label_file, where)
        shape = "box" if count == 4 else "polygon"
        annotations.append(
            annotation(yolo_box(values, width, height), classes[int(tokens[0])], yolo_shape=shape)
        )
    return Sample(absolute(image), tuple(annotations), width, height, split)


def _label_line(class_id: int, bbox, width: int, height: int) -> str:
    x0, y0, x1, y1 = bbox
    values = ((x0 + x1) / 2 / width, (y0 + y1) / 2 / height, (x1 - x0) / width, (y1 - y0) / height)
    return " ".join([str(class_id), *(f"{v:.8f}" for v in values)])


def _place_image(source: Path, target: Path) -> None:
    """A relative symlink to ``source`` at ``target`` (a copy where links are not allowed)."""
    if not source.is_file():
        raise DatasetError(
            source, "image not found; YOLO output needs the image beside its label file"
        )
    target.parent.mkdir(parents=True, exist_ok=True)
    if target.is_symlink() or target.exists():
        target.unlink()
    try:
        target.symlink_to(os.path.relpath(source.resolve(), target.parent.resolve()))
    except OSError:
        shutil.copy2(source, target)


@hookimpl
def register_dataset_formats(register):
    register(Yolo)
