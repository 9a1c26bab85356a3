"""COCO detection JSON (``images``, ``annotations``, ``categories``): read and write.

Boxes are ``[x, y, width, height]`` in pixels; ``file_name`` resolves against the JSON file's
folder (or ``--images``). Categories are the raw labels; the state goes in each annotation's
extra ``"state"`` key when it differs from what the label maps to, and non-label attributes in
``"attributes"`` (COCO readers ignore unknown keys). Images carry tsrkit's ``split`` and
``metadata`` the same way. Category and image ids start at 1.
"""

from __future__ import annotations

from collections import defaultdict
from pathlib import Path
from typing import Any

from tsrkit.api import (
    Dataset,
    DatasetError,
    DatasetFormat,
    Sample,
    hookimpl,
    to_state,
    write_json,
    xywh_to_xyxy,
    xyxy_to_xywh,
)
from tsrkit_plugins.formats.common import (
    annotation,
    attributes,
    checked_box,
    class_names,
    explicit_state,
    extra_attributes,
    field,
    json_safe,
    numbers,
    optional,
    raw_label,
    read_json,
    resolve_image,
    sniff_json,
)
from tsrkit_plugins.shared.paths import relative_source


def _is_coco(data) -> bool:
    return isinstance(data, dict) and {"images", "annotations", "categories"} <= set(data)


class Coco(DatasetFormat):
    name = "coco"
    summary = "COCO detection JSON (images, annotations, categories), read and write"
    section = "cocodataset.org/#format-data"
    writable = True

    def sniff(self, path: Path) -> bool:
        return sniff_json(Path(path), _is_coco)

    def read(self, path: Path, images: Path | None = None) -> Dataset:
        path = Path(path)
        data = read_json(path)
        if not _is_coco(data):
            raise DatasetError(path, "expected an object with images, annotations, categories")
        categories = {}
        for i, cat in enumerate(field(data, "categories", list, path, "")):
            categories[field(cat, "id", int, path, f"categories[{i}]")] = str(
                field(cat, "name", (str, int), path, f"categories[{i}]")
            )
        by_image = defaultdict(list)
        for i, ann in enumerate(field(data, "annotations", list, path, "")):
            by_image[field(ann, "image_id", int, path, f"annotations[{i}]")].append(
                _annotation(path, ann, f"annotations[{i}]", categories)
            )
        samples = []
        for i, image in enumerate(field(data, "images", list, path, "")):
            where = f"images[{i}]"
            image_id = field(image, "id", int, path, where)
            size = {k: image[k] for k in ("width", "height") if isinstance(image.get(k), int)}
            metadata = optional(image, "metadata", dict, path, where) or {}
            samples.append(
                Sample(
                    resolve_image(path.parent, field(image, "file_name", str, path, where), images),
                    tuple(by_image.pop(image_id, ())),
                    split=optional(image, "split", str, path, where),
                    metadata={**metadata, "coco_id": image_id},
                    **size,
                )
            )
        if by_image:
            raise DatasetError(
                path,
                f"annotations refer to unknown image ids {sorted(by_image)[:5]}",
                "annotations",
            )
        return Dataset(
            path.stem, tuple(samples), self.name, str(path.parent), {"annotation_file": str(path)}
        )

    def write(self, dataset: Dataset, out: Path) -> None:
        out = Path(out)
        names = class_names(dataset)
        ids = {name: i for i, name in enumerate(names, 1)}
        images: list[dict[str, Any]] = []
        annotations: list[dict[str, Any]] = []
        for image_id, sample in enumerate(dataset, 1):
            image = {
                "id": image_id,
                "file_name": relative_source(sample.source, out.parent),
                "width": sample.width,
                "height": sample.height,
                "split": sample.split,
            }
            metadata = json_safe({k: v for k, v in sample.metadata.items() if k != "coco_id"})
            if metadata:
                image["metadata"] = metadata
            images.append(image)
            for ann in sample.annotations:
                annotations.append(_coco_annotation(ann, len(annotations) + 1, image_id, ids))
        write_json(
            out,
            {
                "info": {"description": dataset.name, "generator": "tsrkit"},
                "images": images,
                "annotations": annotations,
                "categories": [{"id": i, "name": n} for n, i in ids.items()],
            },
        )


def _annotation(path: Path, ann, where: str, categories: dict):
    category = field(ann, "category_id", int, path, where)
    if category not in categories:
        raise DatasetError(path, f"unknown category_id {category}", where)
    values = numbers(field(ann, "bbox", list, path, where), 4, path, where)
    bbox = checked_box(xywh_to_xyxy(*values), path, where)
    return annotation(
        bbox,
        categories[category],
        explicit_state(ann, path, where),
        **attributes(ann, path, where),
    )


def _coco_annotation(ann, ann_id: int, image_id: int, ids: dict) -> dict:
    x, y, w, h = xyxy_to_xywh(ann.bbox)
    label = raw_label(ann)
    record = {
        "id": ann_id,
        "image_id": image_id,
        "category_id": ids[label],
        "bbox": [round(x, 3), round(y, 3), round(w, 3), round(h, 3)],
        "area": round(w * h, 3),
        "iscrowd": 0,
    }
    if ann.state != to_state(label):
        record["state"] = ann.state
    extra = extra_attributes(ann)
    if extra:
        record["attributes"] = extra
    return record


@hookimpl
def register_dataset_formats(register):
    register(Coco)
