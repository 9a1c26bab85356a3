"""Zheng 2016, 5.2.1: per-frame recall and precision, and the ``per_frame`` section's result (the
metric that fills it is the plugin ``tsrkit_plugins.metrics.per_frame``).

A candidate is a true positive when its centre lies in the minimum enclosing circle of any
ground-truth box of the same frame. Reading chosen for the per-frame figures (the prose: "how many
of the present traffic signals in a given frame can be correctly detected" and "how many false
objects are reported among all detections"): recall = boxes whose circle holds at least one
candidate centre / boxes; precision = candidates inside some circle / candidates.
Summary definitions: ``recall_mean`` is the mean over frames with ground truth,
``precision_mean`` the mean over frames with detections; false positives on frames without
ground truth are counted separately and do not enter ``precision_mean``.
The Table 5-2 grouping is :mod:`tsrkit.eval.categories`.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from typing import ClassVar

import numpy as np

from tsrkit.core.records import FrameRecord
from tsrkit.core.results import Figure, MetricResult
from tsrkit.core.types import Sample
from tsrkit.eval.matching import centre_hits
from tsrkit.eval.stats import bootstrap_interval

__all__ = [
    "FIGURES",
    "FrameScore",
    "PerFrameResult",
    "frame_score",
    "headline_intervals",
    "max_target_radius",
    "score_frame",
    "summarise",
]


@dataclass(frozen=True)
class FrameScore:
    """What the per-frame metric needs from one frame."""

    n_gt: int
    n_det: int
    gt_hit: int
    det_tp: int
    lighting: str = "unknown"
    max_radius: int = 0

    @property
    def recall(self) -> float | None:
        """Share of ground-truth boxes hit; None for a frame without ground truth."""
        return self.gt_hit / self.n_gt if self.n_gt else None

    @property
    def precision(self) -> float | None:
        """Share of candidates that are true positives; None for a frame without candidates."""
        return self.det_tp / self.n_det if self.n_det else None


def score_frame(points, boxes, lighting: str = "unknown") -> FrameScore:
    """Score one frame's candidate centres against its ground-truth boxes (Zheng 5.2.1).

    Examples
    --------
    >>> s = score_frame([(5, 5), (50, 50)], [(0, 0, 10, 10), (20, 20, 30, 30)])
    >>> s.recall, s.precision
    (0.5, 0.5)
    """
    hits = centre_hits(points, boxes)
    return FrameScore(
        n_gt=hits.shape[1],
        n_det=hits.shape[0],
        gt_hit=int(hits.any(axis=0).sum()),
        det_tp=int(hits.any(axis=1).sum()),
        lighting=lighting,
        max_radius=max_target_radius(boxes),
    )


def max_target_radius(boxes) -> int:
    """The largest target radius of a frame in whole pixels (Table 5-2's second key).

    A box's target radius is half its shorter side (the lens radius for a lens box), rounded
    half up; 0 for a frame without boxes.
    """
    b = np.asarray(boxes, dtype=float).reshape(-1, 4)
    if not len(b):
        return 0
    radius = float(np.max(np.minimum(b[:, 2] - b[:, 0], b[:, 3] - b[:, 1]) / 2))
    return int(math.floor(radius + 0.5))


def summarise(scores: Sequence[FrameScore]) -> dict:
    """``recall_mean``, ``precision_mean``, ``hit_frame_fraction`` and the no-ground-truth counts.

    ``recall_mean``: mean recall over frames with ground truth; ``precision_mean``: mean precision
    over frames with ground truth and at least one candidate; ``hit_frame_fraction``: share of
    ground-truth frames with recall > 0. Means over no frames are None.
    """
    with_gt = [s for s in scores if s.n_gt]
    recalls = [s.gt_hit / s.n_gt for s in with_gt]
    precisions = [s.det_tp / s.n_det for s in with_gt if s.n_det]
    without_gt = [s for s in scores if not s.n_gt]
    return {
        "frames_with_gt": len(with_gt),
        "recall_mean": _mean(recalls),
        "precision_mean": _mean(precisions),
        "hit_frame_fraction": _mean([r > 0 for r in recalls]),
        "frames_without_gt": len(without_gt),
        "false_positives_without_gt": sum(s.n_det for s in without_gt),
        "frames_without_gt_with_detections": sum(1 for s in without_gt if s.n_det),
    }


def _mean(values: Iterable[float]) -> float | None:
    values = list(values)
    return float(np.mean(values)) if values else None


def frame_score(sample: Sample, record: FrameRecord) -> FrameScore:
    """One evaluated frame's :class:`FrameScore`: detection centres against its ground truth."""
    return score_frame(
        [(d.x, d.y) for d in record.detections],
        [a.bbox for a in sample.annotations],
        record.lighting or "unknown",
    )


def headline_intervals(scores: Sequence[FrameScore]) -> dict[str, list[float] | None]:
    """Bootstrap 95 % intervals (over frames) of the three per-frame headline figures."""
    with_gt = [s for s in scores if s.n_gt]
    return {
        "recall_mean": bootstrap_interval([s.gt_hit / s.n_gt for s in with_gt]),
        "precision_mean": bootstrap_interval([s.det_tp / s.n_det for s in with_gt if s.n_det]),
        "hit_frame_fraction": bootstrap_interval([float(s.gt_hit > 0) for s in with_gt]),
    }


#: The per-frame headline figures: (key of ``per_frame``, label).
FIGURES = (
    ("recall_mean", "recall"),
    ("precision_mean", "prec."),
    ("hit_frame_fraction", "hit"),
)


@dataclass(frozen=True)
class PerFrameResult(MetricResult):
    """``per_frame`` and ``intervals``: three headline figures with their bootstrap intervals,
    and what happened on the frames without ground truth."""

    order: ClassVar[int] = 10

    def headline(self) -> list[Figure]:
        figures = self.sections.get("per_frame") or {}
        intervals = self.sections.get("intervals") or {}
        return [
            Figure(
                f"per_frame.{key}",
                label,
                figures.get(key),
                interval=_pair(intervals.get(key)),
                about="Zheng 5.2.1 per-frame means",
            )
            for key, label in FIGURES
        ]

    def remarks(self) -> list[str]:
        figures = self.sections.get("per_frame") or {}
        if "note" in figures:
            return [figures["note"]]
        return [
            f"Frames without ground truth: {figures['frames_without_gt']} "
            f"({figures['false_positives_without_gt']} false positives on "
            f"{figures['frames_without_gt_with_detections']} of them)."
        ]

    def tables(self) -> list:
        return []


def _pair(interval: Sequence[float] | None) -> tuple[float, float] | None:
    return (interval[0], interval[1]) if interval else None
