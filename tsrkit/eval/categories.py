"""Zheng 2016, Table 5-2 and Figure 5-1: frames grouped by lighting and by max target radius.

Each ground-truth frame falls into one lighting condition (labelled, or Mascetti 3.2's mean V)
and one maximum target radius; a row counts its frames by recall label and precision bound.
"""

from __future__ import annotations

import math
from collections import Counter, defaultdict
from collections.abc import Sequence

from tsrkit.eval.perframe import FrameScore, FrameScoreMetric, summarise

__all__ = [
    "PRECISION_BOUNDS",
    "RADIUS_BIN_STARTS",
    "LightingBySize",
    "category_table",
    "precision_bound",
    "radius_bin",
    "radius_label",
    "recall_label",
    "recall_sort_key",
]

#: Lower bounds (percent) of the precision columns; Table 5-2 uses a subset of these 5 % steps.
PRECISION_BOUNDS = tuple(range(0, 101, 5))
#: Lower bounds of the max-radius rows. Zheng's Table 5-2 has one row per pixel of radius (2-9 px
#: on 480x356 frames), kept up to 9 px; above, rows widen about 1.5x per step so that 1280x720 or
#: larger frames (lens radii 2-40 px and more) give a handful of rows, not one per pixel.
RADIUS_BIN_STARTS = (*range(10), 10, 14, 20, 30, 45, 70)


def category_table(scores: Sequence[FrameScore]) -> list[dict]:
    """The Table 5-2 rows: ground-truth frames grouped by lighting, then by max target radius.

    Each lighting condition gets a total row (``max_radius`` None) followed by one row per
    radius bin (:func:`radius_bin`; ``max_radius`` is the bin's lower bound, :func:`radius_label`
    names it). A row holds the frame count, the counts per recall label and per precision lower
    bound, its summary means, and the Figure 5-1 bubbles (recall, FPR = 1 - precision, frames).
    """
    groups: dict[tuple[str, int], list[FrameScore]] = defaultdict(list)
    for s in scores:
        if s.n_gt:
            groups[(s.lighting, radius_bin(s.max_radius))].append(s)
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
    bubbles = Counter(
        (round(s.recall or 0.0, 6), round(1 - (s.precision or 0.0), 6)) for s in members
    )
    return {
        "lighting": lighting,
        "max_radius": radius,
        "frames": len(members),
        "recall_mean": summary["recall_mean"],
        "precision_mean": summary["precision_mean"],
        "hit_frame_fraction": summary["hit_frame_fraction"],
        "recall_counts": dict(sorted(recall_counts.items(), key=lambda kv: recall_sort_key(kv[0]))),
        "precision_counts": {f"{b}%": precision_counts[b] for b in sorted(precision_counts)},
        "bubbles": [{"recall": r, "fpr": f, "frames": n} for (r, f), n in sorted(bubbles.items())],
    }


def radius_bin(radius: int) -> int:
    """The lower bound of the :data:`RADIUS_BIN_STARTS` bin holding a max target radius.

    >>> radius_bin(7), radius_bin(12), radius_bin(100)
    (7, 10, 70)
    """
    return max(start for start in RADIUS_BIN_STARTS if start <= max(int(radius), 0))


def radius_label(start: int) -> str:
    """The row name of the radius bin starting at ``start``: ``"7"``, ``"10-13"``, ``">=70"``.

    >>> [radius_label(start) for start in (7, 10, 45, 70)]
    ['7', '10-13', '45-69', '>=70']
    """
    index = RADIUS_BIN_STARTS.index(start)
    if index + 1 == len(RADIUS_BIN_STARTS):
        return f">={start}"
    end = RADIUS_BIN_STARTS[index + 1] - 1
    return str(start) if end == start else f"{start}-{end}"


def recall_sort_key(label: str) -> tuple[float, str]:
    """Order Table 5-2 recall labels by value (``"1/4"`` before ``"1/3"`` before ``"2/4"``)."""
    top, _, bottom = label.partition("/")
    return (int(top) / int(bottom) if bottom else float(top), label)


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


class LightingBySize(FrameScoreMetric):
    """``categories``: the Table 5-2 rows (lighting x max target radius) with Figure 5-1 bubbles."""

    name = "categories"
    summary = "frame counts by lighting and max target radius, recall and precision columns"
    section = "Zheng 2016, 5.2.1, Table 5-2, Figure 5-1"

    def compute(self) -> dict:
        return {"categories": category_table(self.scores) if self.settings.detection else []}
