"""COCO detection JSON (``images``, ``annotations``, ``categories``): read and write.

Boxes are ``[x, y, width, height]`` in pixels; ``file_name`` resolves against the JSON file's
folder (or ``--images``). Categories are the raw labels; the state goes in each annotation's
extra ``"state"`` key when it differs from what the label maps to, and non-label attributes in
``"attributes"`` (COCO readers ignore unknown keys). Images carry tsrkit's ``split`` and
``metadata`` the same way. The ids of images and categories read from COCO are kept (a
sample's ``metadata["coco_id"]``, the dataset's ``info["coco_categories"]``); others are
numbered from 1 (after the kept ones), and a file giving two images one id is refused.
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
        categories: dict[int, str] = {}
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
        seen: dict[int, int] = {}
        for i, image in enumerate(field(data, "images", list, path, "")):
            where = f"images[{i}]"
            image_id = field(image, "id", int, path, where)
            if image_id in seen:
                raise DatasetError(
                    path, f"image id {image_id} is also the id of images[{seen[image_id]}]", where
                )
            seen[image_id] = i
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
        info = {
            "annotation_file": str(path),
            "coco_categories": {name: cid for cid, name in categories.items()},
        }
        return Dataset(path.stem, tuple(samples), self.name, str(path.parent), info)

    def write(self, dataset: Dataset, out: Path) -> None:
        out = Path(out)
        known = dict(dataset.info.get("coco_categories") or {})
        ids = _numbered(known, [n for n in class_names(dataset) if n not in known])
        kept = [s.metadata.get("coco_id") for s in dataset]
        if not all(isinstance(i, int) for i in kept) or len(set(kept)) < len(kept):
            kept = list(range(1, len(kept) + 1))
        images: list[dict[str, Any]] = []
        annotations: list[dict[str, Any]] = []
        for image_id, sample in zip(kept, dataset):
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
                "categories": [
                    {"id": i, "name": n} for n, i in sorted(ids.items(), key=lambda item: item[1])
                ],
            },
        )


def _numbered(known: dict, new) -> dict:
    """``known`` ids (name: id) and the ``new`` names numbered on after the largest."""
    start = max(known.values(), default=0) + 1
    return {**known, **{key: start + k for k, key in enumerate(new)}}


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
        "bbox": [x, y, w, h],
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
