"""COCO ground truth and detections of a run, and AP computed by pycocotools.

Detection AP is class-agnostic (every box is category 1, ``traffic_light``): detectors report
where lit lenses are, not their state. ``coco_ap`` returns pycocotools' AP at IoU 0.5 and its AP
averaged over IoU 0.5:0.05:0.95, computed on exactly the dictionaries the COCO writer puts on
disk (:func:`coco_frame` builds both). Image ids are the dataset positions plus one.
"""

from __future__ import annotations

import contextlib
import io
from collections.abc import Iterable, Mapping
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, ClassVar

from tsrkit.core.geometry import xyxy_to_xywh
from tsrkit.core.records import FrameRecord
from tsrkit.core.results import Figure, MetricResult, Plot
from tsrkit.core.types import Sample

if TYPE_CHECKING:
    from matplotlib.figure import Figure as MplFigure

__all__ = [
    "ABOUT",
    "CATEGORY",
    "CocoResult",
    "coco_ap",
    "coco_dataset",
    "coco_frame",
    "coco_run",
    "draw_pr_curve",
]

CATEGORY = {"id": 1, "name": "traffic_light", "supercategory": "traffic_signal"}


def coco_frame(
    sample: Sample, record: FrameRecord, first_id: int, box: str
) -> tuple[dict, list[dict], list[dict]]:
    """One frame's COCO ``images`` entry, ground-truth ``annotations`` and ``results``.

    ``first_id`` numbers the annotations; ``box`` is the evaluated record box (``lens`` or
    ``housing``).
    """
    image_id = record.index + 1
    image = {
        "id": image_id,
        "file_name": record.source,
        "width": int(record.width),
        "height": int(record.height),
    }
    annotations = []
    for offset, ann in enumerate(sample.annotations):
        xywh = xyxy_to_xywh(ann.bbox)
        annotations.append(
            {
                "id": first_id + offset,
                "image_id": image_id,
                "category_id": 1,
                "bbox": xywh,
                "area": xywh[2] * xywh[3],
                "iscrowd": 0,
                "state": ann.state,
            }
        )
    results = [
        {
            "image_id": image_id,
            "category_id": 1,
            "bbox": xyxy_to_xywh(d.box(box)),
            "score": float(d.score),
            "state": d.state,
        }
        for d in record.detections
    ]
    return image, annotations, results


def coco_run(
    name: str, pairs: Iterable[tuple[Sample, FrameRecord]], box: str
) -> tuple[dict[str, Any], list[dict[str, Any]]]:
    """The COCO ground-truth dictionary and the results list of evaluated frames."""
    images: list[dict] = []
    annotations: list[dict] = []
    results: list[dict] = []
    for sample, record in pairs:
        image, anns, dets = coco_frame(sample, record, len(annotations) + 1, box)
        images.append(image)
        annotations += anns
        results += dets
    return coco_dataset(images, annotations, name), results


def coco_dataset(images: list[dict], annotations: list[dict], name: str) -> dict[str, Any]:
    """A COCO ground-truth dictionary."""
    return {
        "info": {"description": f"tsrkit ground truth of {name}"},
        "images": images,
        "annotations": annotations,
        "categories": [CATEGORY],
    }


def coco_ap(ground_truth: Mapping[str, Any], results: list[dict[str, Any]]) -> dict[str, Any]:
    """AP at IoU 0.5 and 0.5:0.95 by pycocotools' COCOeval (bbox, 100 detections per image).

    Returns ``{"ap50": ..., "ap": ..., "curve": {"recall": [...], "precision": [...]}}`` (the
    curve is COCOeval's interpolated precision at IoU 0.5 on its 101 recall points); the APs are
    0 when there are no detections and None when there is no ground-truth box.
    """
    # pycocotools: only when COCO AP is computed
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
    curve = {
        "recall": evaluator.params.recThrs.tolist(),
        "precision": evaluator.eval["precision"][0, :, 0, 0, -1].tolist(),
    }
    return {"ap50": float(evaluator.stats[1]), "ap": float(evaluator.stats[0]), "curve": curve}


def draw_pr_curve(figure: MplFigure, curve: Mapping[str, list] | None, ap: float | None) -> None:
    """COCOeval's interpolated precision-recall curve at IoU 0.5 (``curve`` of :func:`coco_ap`)."""
    ax = figure.subplots()
    if curve:
        precision = [max(p, 0.0) for p in curve["precision"]]
        ax.plot(curve["recall"], precision, label="interpolated precision (101 recall points)")
        ax.legend(fontsize=8, loc="lower left")
    ax.set_xlabel("recall")
    ax.set_ylabel("precision")
    ax.set_xlim(0, 1)
    ax.set_ylim(0, 1.02)
    ax.set_title(f"IoU 0.5, AP = {ap:.3f}" if ap is not None else "IoU 0.5")


#: What the two AP figures are.
ABOUT = "pycocotools AP at IoU 0.5 and 0.5:0.95"


@dataclass(frozen=True)
class CocoResult(MetricResult):
    """``iou50.ap``, ``iou50.ap_50_95`` and ``iou50.pr_curve``: two headline figures and the
    precision-recall curve (detection runs only)."""

    order: ClassVar[int] = 30

    def headline(self) -> list[Figure]:
        iou50 = self.sections.get("iou50") or {}
        return [
            Figure("iou50.ap", "AP50", iou50.get("ap"), about=ABOUT),
            Figure("iou50.ap_50_95", "AP", iou50.get("ap_50_95"), about=ABOUT),
        ]

    def tables(self) -> list:
        return []

    def plots(self) -> list[Plot]:
        iou50 = self.sections.get("iou50") or {}
        if "ap" not in iou50:
            return []
        return [
            Plot(
                "pr_curve.png",
                "Precision against recall at IoU 0.5, class-agnostic (pycocotools' interpolated "
                "curve; AP50 is the mean precision over its 101 recall points).",
                lambda figure: draw_pr_curve(figure, iou50.get("pr_curve"), iou50["ap"]),
                (4.0, 4.0),
            )
        ]
