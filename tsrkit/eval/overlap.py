"""Lee 3.6.2 (PASCAL): overlap matching and precision / recall over a dataset.

A detection box ``o`` matches a ground-truth box ``g`` of the same frame when
``tau < area(o & g) / area(o | g)``; each box is matched at most once, best score first.
Besides the counting precision and recall, Lee's area precision ``area(o & g) / area(o)`` and
area recall ``area(o & g) / area(g)`` are averaged over the matched pairs.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any, ClassVar

import numpy as np

from tsrkit.core.geometry import box_areas, intersection_matrix, iou_matrix
from tsrkit.core.results import MetricResult, Table, fmt
from tsrkit.eval.matching import greedy_match

__all__ = [
    "COLUMNS",
    "OverlapResult",
    "OverlapScore",
    "match_by_iou",
    "score_overlap",
    "summarise_overlap",
]


@dataclass(frozen=True)
class OverlapScore:
    """One frame's overlap matching: counts and the matched pairs' area ratios."""

    n_gt: int
    n_det: int
    matched: int
    area_precision_sum: float
    area_recall_sum: float


def match_by_iou(det_boxes, scores, gt_boxes, threshold: float = 0.5) -> list[tuple[int, int]]:
    """Pairs ``(detection, ground truth)`` with IoU above ``threshold`` (Lee's ``tau``)."""
    if not 0 <= threshold < 1:
        raise ValueError(f"IoU threshold must be in [0, 1); got {threshold}")
    return greedy_match(scores, iou_matrix(det_boxes, gt_boxes), threshold)


def score_overlap(det_boxes, scores, gt_boxes, threshold: float = 0.5) -> OverlapScore:
    """Match one frame and keep what :func:`summarise_overlap` needs."""
    det = np.asarray(det_boxes, dtype=float).reshape(-1, 4)
    gt = np.asarray(gt_boxes, dtype=float).reshape(-1, 4)
    pairs = match_by_iou(det, scores, gt, threshold)
    inter = intersection_matrix(det, gt)
    det_area, gt_area = box_areas(det), box_areas(gt)
    area_p = sum(inter[i, j] / det_area[i] for i, j in pairs if det_area[i] > 0)
    area_r = sum(inter[i, j] / gt_area[j] for i, j in pairs if gt_area[j] > 0)
    return OverlapScore(len(gt), len(det), len(pairs), float(area_p), float(area_r))


def summarise_overlap(scores: Sequence[OverlapScore], threshold: float) -> dict:
    """Dataset precision and recall at the threshold, and mean area precision / recall."""
    matched = sum(s.matched for s in scores)
    n_det = sum(s.n_det for s in scores)
    n_gt = sum(s.n_gt for s in scores)
    return {
        "threshold": threshold,
        "precision": matched / n_det if n_det else None,
        "recall": matched / n_gt if n_gt else None,
        "true_positives": matched,
        "detections": n_det,
        "ground_truth": n_gt,
        "area_precision": sum(s.area_precision_sum for s in scores) / matched if matched else None,
        "area_recall": sum(s.area_recall_sum for s in scores) / matched if matched else None,
    }


#: The columns of the overlap table: (key of a section, column label).
COLUMNS = (
    ("threshold", "IoU above"),
    ("precision", "precision"),
    ("recall", "recall"),
    ("true_positives", "true positives"),
    ("detections", "detections"),
    ("ground_truth", "ground truth"),
    ("area_precision", "area precision"),
    ("area_recall", "area recall"),
)


@dataclass(frozen=True)
class OverlapResult(MetricResult):
    """``iou50`` and ``iou``: one table row per threshold (``iou`` only when its threshold is
    not 0.5)."""

    order: ClassVar[int] = 20

    def _sections(self) -> list[dict[str, Any]]:
        at50, other = self.sections.get("iou50") or {}, self.sections.get("iou") or {}
        rows = [at50] + ([other] if other.get("threshold", 0.5) != 0.5 else [])
        return [row for row in rows if "note" not in row and "threshold" in row]

    def remarks(self) -> list[str]:
        note = (self.sections.get("iou50") or {}).get("note")
        return [note] if note else []

    def tables(self) -> list[Table]:
        rows = self._sections()
        if not rows:
            return []
        return [
            Table(
                "iou",
                "Overlap matching (Lee 2017, 3.6.2)",
                tuple(label for _, label in COLUMNS),
                tuple(tuple(fmt(row.get(key)) for key, _ in COLUMNS) for row in rows),
                "A detection's evaluated box matches a ground-truth box of its frame when their "
                "IoU exceeds the threshold, each box at most once, best score first. Area "
                "precision (recall): the overlap over the detection's (ground truth's) area, "
                "averaged over the matched pairs.",
            )
        ]
