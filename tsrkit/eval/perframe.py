"""Zheng 2016, 5.2.1: per-frame recall and precision, grouped as in Table 5-2 and Figure 5-1.

A candidate is a true positive when its centre lies in the minimum enclosing circle of any
ground-truth box of the same frame. Reading chosen for the per-frame figures (the prose: "how many
of the present traffic signals in a given frame can be correctly detected" and "how many false
objects are reported among all detections"): recall = boxes whose circle holds at least one
candidate centre / boxes; precision = candidates inside some circle / candidates.
Summary definitions follow DESIGN.md; false positives on frames without ground truth are counted
separately and do not enter ``precision_mean``.
"""
from __future__ import annotations

import math
from collections import Counter, defaultdict
from collections.abc import Iterable, Sequence
from dataclasses import dataclass

import numpy as np

from tsrkit.eval.matching import centre_hits

#: Lower bounds (percent) of the precision columns; Table 5-2 uses a subset of these 5 % steps.
PRECISION_BOUNDS = tuple(range(0, 101, 5))


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
    return FrameScore(n_gt=hits.shape[1], n_det=hits.shape[0],
                      gt_hit=int(hits.any(axis=0).sum()), det_tp=int(hits.any(axis=1).sum()),
                      lighting=lighting, max_radius=max_target_radius(boxes))


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


def recall_label(score: FrameScore) -> str:
    """Table 5-2 recall column: ``"0"``, ``"1"`` or the unreduced fraction such as ``"2/4"``."""
    if score.gt_hit == 0:
        return "0"
    if score.gt_hit == score.n_gt:
        return "1"
    return f"{score.gt_hit}/{score.n_gt}"


def precision_bound(score: FrameScore) -> int:
    """Table 5-2 precision column: the 5 % lower bound (a frame with no candidates counts as 0)."""
    precision = score.precision or 0.0
    return int(math.floor(precision * 20 + 1e-9)) * 5


def summarise(scores: Sequence[FrameScore]) -> dict:
    """``recall_mean``, ``precision_mean``, ``hit_frame_fraction`` and the no-ground-truth counts.

    ``recall_mean``: mean recall over frames with ground truth; ``precision_mean``: mean precision
    over frames with ground truth and at least one candidate; ``hit_frame_fraction``: share of
    ground-truth frames with recall > 0. Means over no frames are None.
    """
    with_gt = [s for s in scores if s.n_gt]
    recalls = [s.recall for s in with_gt]
    precisions = [s.precision for s in with_gt if s.n_det]
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


def category_table(scores: Sequence[FrameScore]) -> list[dict]:
    """The Table 5-2 rows: ground-truth frames grouped by lighting, then by max target radius.

    Each lighting condition gets a total row (``max_radius`` None) followed by one row per
    radius. A row holds the frame count, the counts per recall label and per precision lower
    bound, its summary means, and the Figure 5-1 bubbles (recall, FPR = 1 - precision, frames).
    """
    groups: dict[tuple[str, int], list[FrameScore]] = defaultdict(list)
    for s in scores:
        if s.n_gt:
            groups[(s.lighting, s.max_radius)].append(s)
    rows = []
    for lighting in sorted({key[0] for key in groups}):
        radii = sorted(r for (light, r) in groups if light == lighting)
        members = [s for r in radii for s in groups[(lighting, r)]]
        rows.append(_row(lighting, None, members))
        rows.extend(_row(lighting, r, groups[(lighting, r)]) for r in radii)
    return rows


def _row(lighting: str, radius: int | None, members: Sequence[FrameScore]) -> dict:
    summary = summarise(members)
    recall_counts = Counter(recall_label(s) for s in members)
    precision_counts = Counter(precision_bound(s) for s in members)
    bubbles = Counter((round(s.recall, 6), round(1 - (s.precision or 0.0), 6)) for s in members)
    return {
        "lighting": lighting, "max_radius": radius, "frames": len(members),
        "recall_mean": summary["recall_mean"], "precision_mean": summary["precision_mean"],
        "hit_frame_fraction": summary["hit_frame_fraction"],
        "recall_counts": dict(sorted(recall_counts.items(), key=lambda kv: recall_sort_key(kv[0]))),
        "precision_counts": {f"{b}%": precision_counts[b] for b in sorted(precision_counts)},
        "bubbles": [{"recall": r, "fpr": f, "frames": n} for (r, f), n in sorted(bubbles.items())],
    }


def recall_sort_key(label: str) -> tuple[float, str]:
    """Order Table 5-2 recall labels by value (``"1/4"`` before ``"1/3"`` before ``"2/4"``)."""
    top, _, bottom = label.partition("/")
    return (int(top) / int(bottom) if bottom else float(top), label)
