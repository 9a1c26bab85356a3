"""COCO export of ground truth and detections, and AP computed by pycocotools.

Detection AP is class-agnostic (every box is category 1, ``traffic_light``): detectors report
where lit lenses are, not their state. ``coco_ap`` returns pycocotools' AP at IoU 0.5 and its AP
averaged over IoU 0.5:0.05:0.95, computed on exactly the dictionaries tsrkit writes to disk.
"""
from __future__ import annotations

import contextlib
import io
from collections.abc import Iterable, Mapping, Sequence
from typing import Any

CATEGORY = {"id": 1, "name": "traffic_light", "supercategory": "traffic_signal"}


def xywh(bbox: Sequence[float]) -> list[float]:
    """``(x_min, y_min, x_max, y_max)`` to COCO's ``[x, y, width, height]``."""
    x0, y0, x1, y1 = (float(v) for v in bbox)
    return [x0, y0, x1 - x0, y1 - y0]


def coco_image(image_id: int, source: str, width: int, height: int) -> dict[str, Any]:
    """One entry of the COCO ``images`` list."""
    return {"id": int(image_id), "file_name": source, "width": int(width), "height": int(height)}


def coco_annotations(image_id: int, annotations: Iterable[Mapping[str, Any]],
                     first_id: int) -> list[dict[str, Any]]:
    """COCO ``annotations`` entries for one image's ground-truth ``{"bbox", "state"}`` dicts."""
    entries = []
    for offset, ann in enumerate(annotations):
        box = xywh(ann["bbox"])
        entries.append({"id": first_id + offset, "image_id": int(image_id), "category_id": 1,
                        "bbox": box, "area": box[2] * box[3], "iscrowd": 0,
                        "state": ann["state"]})
    return entries


def coco_results(image_id: int, detections: Iterable[Mapping[str, Any]]) -> list[dict[str, Any]]:
    """COCO results entries for one image's detection records (``bbox``, ``score``, ``state``)."""
    return [{"image_id": int(image_id), "category_id": 1, "bbox": xywh(d["bbox"]),
             "score": float(d["score"]), "state": d.get("state", "unknown")}
            for d in detections]


def coco_dataset(images: list[dict], annotations: list[dict], name: str) -> dict[str, Any]:
    """A COCO ground-truth dictionary."""
    return {"info": {"description": f"tsrkit ground truth of {name}"}, "images": images,
            "annotations": annotations, "categories": [CATEGORY]}


def coco_ap(ground_truth: Mapping[str, Any], results: list[dict[str, Any]]) -> dict[str, Any]:
    """AP at IoU 0.5 and 0.5:0.95 by pycocotools' COCOeval (bbox, 100 detections per image).

    Returns ``{"ap50": ..., "ap": ..., "curve": {"recall": [...], "precision": [...]}}`` (the
    curve is COCOeval's interpolated precision at IoU 0.5 on its 101 recall points); the APs are
    0 when there are no detections and None when there is no ground-truth box.
    """
    from pycocotools.coco import COCO
    from pycocotools.cocoeval import COCOeval

    if not ground_truth["annotations"]:
        return {"ap50": None, "ap": None, "curve": None}
    if not results:
        return {"ap50": 0.0, "ap": 0.0, "curve": None}
    with contextlib.redirect_stdout(io.StringIO()):
        gt = COCO()
        gt.dataset = dict(ground_truth)
        gt.createIndex()
        dt = gt.loadRes([dict(r) for r in results])
        evaluator = COCOeval(gt, dt, "bbox")
        evaluator.evaluate()
        evaluator.accumulate()
        evaluator.summarize()
    curve = {"recall": evaluator.params.recThrs.tolist(),
             "precision": evaluator.eval["precision"][0, :, 0, 0, -1].tolist()}
    return {"ap50": float(evaluator.stats[1]), "ap": float(evaluator.stats[0]), "curve": curve}
