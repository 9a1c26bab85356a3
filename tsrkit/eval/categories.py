"""Zheng 2016, Table 5-2 and Figure 5-1: frames grouped by lighting and by max target radius.

Each ground-truth frame falls into one lighting condition (labelled, else Mascetti 3.2's mean V
or, with ``--lighting zheng``, Zheng's Figure 4-2 conditions: :mod:`tsrkit.eval.lighting`)
and one maximum target radius; a row counts its frames by recall label and precision bound.
"""

from __future__ import annotations

import math
from collections import Counter, defaultdict
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, ClassVar

from tsrkit.core.results import MetricResult, Plot, Table, fmt
from tsrkit.eval.perframe import FrameScore, summarise

if TYPE_CHECKING:
    from matplotlib.figure import Figure as MplFigure

__all__ = [
    "CATEGORY_BARS",
    "CELL",
    "PRECISION_BOUNDS",
    "RADIUS_BIN_STARTS",
    "CategoriesResult",
    "bubble_size",
    "category_table",
    "counts_table",
    "draw_bubbles",
    "draw_category_bars",
    "means_table",
    "precision_bound",
    "radius_bin",
    "radius_label",
    "recall_label",
    "recall_sort_key",
    "row_name",
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


def row_name(row: Mapping[str, Any]) -> str:
    """A Table 5-2 row's name: its lighting on a total row, else its radius bin."""
    return row["lighting"] if row["max_radius"] is None else radius_label(row["max_radius"])


def counts_table(rows: Sequence[Mapping[str, Any]]) -> Table:
    """Table 5-2: one row per lighting (total) and radius; recall labels then precision bounds."""
    recall_cols = sorted({k for r in rows for k in r["recall_counts"]}, key=recall_sort_key)
    precision_cols = sorted(
        {k for r in rows for k in r["precision_counts"]}, key=lambda k: int(k[:-1])
    )
    return Table(
        "table-5-2",
        "Frame counts by lighting and max target radius (Zheng Table 5-2 layout)",
        (
            "lighting - max radius",
            *(f"R {c}" for c in recall_cols),
            *(f"P {c}" for c in precision_cols),
            "total",
        ),
        tuple(
            (
                row_name(r),
                *(str(r["recall_counts"].get(c, "")) for c in recall_cols),
                *(str(r["precision_counts"].get(c, "")) for c in precision_cols),
                str(r["frames"]),
            )
            for r in rows
        ),
        "Ground-truth frames of each lighting (its total row first) and max target radius "
        "(px): R columns count the frames by recall (boxes hit / boxes), P columns by the 5 % "
        "lower bound of their precision.",
    )


def means_table(rows: Sequence[Mapping[str, Any]]) -> Table:
    """The Table 5-2 rows' frame counts and per-frame means."""
    return Table(
        "categories",
        "Per-frame means by lighting and max target radius",
        ("lighting", "max radius", "frames", "recall", "precision", "hit"),
        tuple(
            (
                r["lighting"],
                "all" if r["max_radius"] is None else radius_label(r["max_radius"]),
                str(r["frames"]),
                fmt(r["recall_mean"]),
                fmt(r["precision_mean"]),
                fmt(r["hit_frame_fraction"]),
            )
            for r in rows
        ),
    )


#: Share of a bubble-grid cell the unit square (FPR, recall) occupies.
CELL = 0.8


def _cells(rows: Sequence[Mapping[str, Any]]) -> list[Mapping[str, Any]]:
    return [r for r in rows if r["max_radius"] is not None] or list(rows)


def bubble_size(rows: Sequence[Mapping[str, Any]]) -> tuple[float, float]:
    """The size (inches) of :func:`draw_bubbles`: bounded by the number of radius bins
    (:data:`RADIUS_BIN_STARTS`) and lighting conditions, whatever the dataset size."""
    cells = _cells(rows)
    width = max(1, len({r["max_radius"] for r in cells}))
    height = max(1, len({r["lighting"] for r in cells}))
    return (min(1.0 * width + 1.6, 16), 1.0 * height + 1.2)


def draw_bubbles(figure: MplFigure, rows: Sequence[Mapping[str, Any]]) -> None:
    """Figure 5-1 as one compact figure: a grid of cells, lighting down, max-radius bin across.

    Zheng draws one panel per category; at full resolution that is dozens of panels, so here
    each category is one cell of a single axes, holding its recall (up) against FPR = 1 -
    precision (right) bubbles, circle area proportional to the share of the category's frames,
    bluer towards (FPR 0, recall 1) and redder away from it, with ``N = frames`` in grey.
    """
    # matplotlib: only when a plot is drawn
    from matplotlib import colormaps
    from matplotlib.cm import ScalarMappable
    from matplotlib.colors import Normalize
    from matplotlib.patches import Rectangle

    cells = _cells(rows)
    lightings = sorted({r["lighting"] for r in cells})
    starts = sorted({r["max_radius"] for r in cells if r["max_radius"] is not None})
    column: dict[int | None, int] = {start: k for k, start in enumerate(starts)} or {None: 0}
    width, height = max(1, len(column)), max(1, len(lightings))
    ax = figure.subplots()
    for row in cells:
        x0 = column[row["max_radius"]] + (1 - CELL) / 2
        y0 = height - 1 - lightings.index(row["lighting"]) + (1 - CELL) / 2
        fpr = [b["fpr"] for b in row["bubbles"]]
        recall = [b["recall"] for b in row["bubbles"]]
        ax.scatter(
            [x0 + CELL * f for f in fpr],
            [y0 + CELL * r for r in recall],
            s=[250 * b["frames"] / row["frames"] for b in row["bubbles"]],
            c=[(f + (1 - r)) / 2 for f, r in zip(fpr, recall)],
            cmap=colormaps["coolwarm"],
            vmin=0,
            vmax=1,
            alpha=0.7,
            edgecolors="k",
            linewidths=0.3,
        )
        ax.add_patch(Rectangle((x0, y0), CELL, CELL, fill=False, lw=0.4, color="grey"))
        ax.text(x0, y0 + CELL + 0.01, f"N={row['frames']}", color="grey", fontsize=6)
    names = ["all" if s is None else radius_label(s) for s in column]
    ax.set_xticks([k + 0.5 for k in range(width)], names)
    ax.set_yticks([height - 1 - k + 0.5 for k in range(height)], lightings)
    ax.set_xlim(0, width)
    ax.set_ylim(0, height)
    ax.tick_params(length=0, labelsize=8)
    ax.set_xlabel("max target radius (px); in each cell: recall up, false positive rate right")
    scale = ScalarMappable(Normalize(0, 1), colormaps["coolwarm"])
    figure.colorbar(scale, ax=ax, label="(FPR + 1 - recall) / 2", fraction=0.04, pad=0.02)
    for share in (0.25, 1.0):
        ax.scatter([], [], s=250 * share, color="grey", alpha=0.5, label=f"{share:.0%} of N")
    ax.legend(loc="lower right", bbox_to_anchor=(1, 1), ncol=2, fontsize=7, frameon=False)


#: The bars of :func:`draw_category_bars`: (key of a category row, legend label).
CATEGORY_BARS = (
    ("recall_mean", "mean recall"),
    ("precision_mean", "mean precision"),
    ("hit_frame_fraction", "hit-frame fraction"),
)


def draw_category_bars(figure: MplFigure, rows: Sequence[Mapping[str, Any]]) -> None:
    """Per-category bars of mean recall, mean precision and hit-frame fraction."""
    labels = [
        r["lighting"]
        if r["max_radius"] is None
        else f"{r['lighting']}-{radius_label(r['max_radius'])}"
        for r in rows
    ]
    ax = figure.subplots()
    width = 0.27
    for k, (key, label) in enumerate(CATEGORY_BARS):
        ax.bar(
            [i + (k - 1) * width for i in range(len(rows))],
            [r[key] or 0.0 for r in rows],
            width,
            label=label,
        )
    ax.set_xticks(range(len(rows)), labels, rotation=45, ha="right", fontsize=8)
    ax.set_ylim(0, 1)
    ax.set_xlabel("lighting - max target radius (px)")
    ax.legend(fontsize=8)


@dataclass(frozen=True)
class CategoriesResult(MetricResult):
    """``categories``: the Table 5-2 counts and means, the Figure 5-1 bubbles and the bars."""

    order: ClassVar[int] = 50

    def tables(self) -> list[Table]:
        rows = self.sections.get("categories") or []
        return [counts_table(rows), means_table(rows)] if rows else []

    def plots(self) -> list[Plot]:
        rows = self.sections.get("categories") or []
        if not rows:
            return []
        return [
            Plot(
                "recall_fpr_bubbles.png",
                "Zheng Figure 5-1: for each lighting (down) and max target radius (across), the "
                "frames' recall (up) against their false positive rate, 1 - precision (right); "
                "a circle's area is its share of the cell's N frames, bluer towards recall 1 "
                "with no false positive, redder away from it.",
                lambda figure: draw_bubbles(figure, rows),
                bubble_size(rows),
            ),
            Plot(
                "categories.png",
                "Mean recall, mean precision and hit-frame fraction of each lighting (its "
                "total first) and max target radius (px), as in the means table.",
                lambda figure: draw_category_bars(figure, rows),
                (max(5, 0.6 * len(rows) + 2), 3.5),
            ),
        ]
