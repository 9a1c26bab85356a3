"""Streaming evaluation: fold frame records into the metrics of ``report.json`` one at a time.

Only small per-frame numbers are kept (scores, COCO boxes, state pairs, times), never images, so
memory grows with the number of boxes rather than pixels. See DESIGN.md for the report keys.
"""
from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import numpy as np

from tsrkit.eval.coco import coco_annotations, coco_ap, coco_dataset, coco_image, coco_results
from tsrkit.eval.matching import centre_hits, greedy_match
from tsrkit.eval.overlap import score_overlap, summarise_overlap
from tsrkit.eval.perframe import FrameScore, category_table, score_frame, summarise
from tsrkit.eval.state import state_metrics
from tsrkit.eval.stats import bootstrap_interval
from tsrkit.types import Sample


class Evaluation:
    """Accumulates frames; :meth:`metrics` returns the evaluation part of the report.

    Parameters
    ----------
    name : str
        Dataset name (for the COCO ground truth).
    iou_threshold : float
        Lee 3.6.2's ``tau`` for the ``iou`` section (``iou50`` always uses 0.5).
    """

    def __init__(self, name: str, iou_threshold: float = 0.5):
        self.name = name
        self.iou_threshold = iou_threshold
        self.scores: dict[int, FrameScore] = {}
        self.overlap50, self.overlap = [], []
        self.truth, self.predicted, self.state_scores = [], [], []
        self.images, self.annotations, self.results = [], [], []
        self.ms: list[float] = []
        self.pr_curve: dict | None = None

    def add(self, image_id: int, sample: Sample, record: Mapping[str, Any]) -> None:
        """Fold in one frame: its sample (ground truth) and its detection record."""
        gt_boxes = [a.bbox for a in sample.annotations]
        dets = record["detections"]
        points = [(d["x"], d["y"]) for d in dets]
        boxes = [d["bbox"] for d in dets]
        scores = [d["score"] for d in dets]
        self.scores[image_id] = score_frame(points, gt_boxes, record["lighting"])
        self.overlap50.append(score_overlap(boxes, scores, gt_boxes, 0.5))
        self.overlap.append(score_overlap(boxes, scores, gt_boxes, self.iou_threshold))
        hits = centre_hits(points, gt_boxes).astype(float)
        for i, j in greedy_match(scores, hits, 0.5):
            self.truth.append(sample.annotations[j].state)
            self.predicted.append(dets[i]["state"])
            self.state_scores.append(dets[i]["state_scores"])
        self.images.append(coco_image(image_id, record["source"], record["width"],
                                      record["height"]))
        self.annotations.extend(coco_annotations(
            image_id, [{"bbox": a.bbox, "state": a.state} for a in sample.annotations],
            len(self.annotations) + 1))
        self.results.extend(coco_results(image_id, dets))
        self.ms.append(float(record["ms"]))

    def ground_truth(self) -> dict[str, Any]:
        """The COCO ground truth of the evaluated frames."""
        return coco_dataset(self.images, self.annotations, self.name)

    def state(self) -> dict[str, Any]:
        """State metrics of the centre-matched pairs; empty when no state was predicted."""
        if all(p == "unknown" for p in self.predicted):
            return {**state_metrics([], []),
                    "note": "the method predicts no state (every detection is 'unknown')"}
        return state_metrics(self.truth, self.predicted, self.state_scores)

    def metrics(self) -> dict[str, Any]:
        """``frames``, ``per_frame``, ``iou50``, ``iou``, ``state``, ``categories``, ``intervals``."""
        scores = list(self.scores.values())
        ap = coco_ap(self.ground_truth(), self.results)
        self.pr_curve = ap["curve"]
        iou50 = summarise_overlap(self.overlap50, 0.5)
        iou50["ap"] = ap["ap50"]
        iou50["ap_50_95"] = ap["ap"]
        return {
            "frames": len(scores),
            "per_frame": summarise(scores),
            "iou50": iou50,
            "iou": summarise_overlap(self.overlap, self.iou_threshold),
            "state": self.state(),
            "categories": category_table(scores),
            "intervals": headline_intervals(scores),
            "ms_per_frame_median": float(np.median(self.ms)) if self.ms else None,
        }


def headline_intervals(scores: list[FrameScore]) -> dict[str, list[float] | None]:
    """Bootstrap 95 % intervals (over frames) of the three per-frame headline figures."""
    with_gt = [s for s in scores if s.n_gt]
    return {
        "recall_mean": bootstrap_interval([s.recall for s in with_gt]),
        "precision_mean": bootstrap_interval([s.precision for s in with_gt if s.n_det]),
        "hit_frame_fraction": bootstrap_interval([float(s.recall > 0) for s in with_gt]),
    }
