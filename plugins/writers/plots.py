"""Report writer ``plots``: PNG plots (matplotlib Agg): Fig. 5-1 bubbles, bars, PR curve, confusion.

``bubble_plot`` follows Zheng 2016 Figure 5-1 (recall against FPR = 1 - precision per lighting x
max-radius category, circle area proportional to the share of the category's frames, bluer towards
(FPR 0, recall 1) and redder away from it, ``N = frames`` in grey), drawn as one compact grid.
"""

from __future__ import annotations

import functools
from pathlib import Path

from tsrkit.api import ReportWriter, RunResult, atomic_open, hookimpl, radius_label


@functools.cache
def pyplot():
    """matplotlib's pyplot on the Agg backend, imported on first use (it costs a quarter second,
    which every verb that loads the plugins would otherwise pay)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot

    return matplotlib.pyplot


def _save(fig, path: Path) -> str:
    plt = pyplot()
    with atomic_open(path, "wb") as fh:
        fig.savefig(fh, format="png", dpi=110)
    plt.close(fig)
    return path.name


def bubble_plot(rows: list[dict], path: Path) -> str:
    """Figure 5-1 as one compact figure: a grid of cells, lighting down, max-radius bin across.

    Zheng draws one panel per category; at full resolution that is dozens of panels, so here each
    category is one cell of a single axes, holding its recall (up) against FPR (right) bubbles
    with ``N = frames``. The figure's size is bounded by the number of radius bins
    (:data:`tsrkit.eval.categories.RADIUS_BIN_STARTS`) and lighting conditions, whatever the
    dataset size.
    """
    plt = pyplot()
    cells = [r for r in rows if r["max_radius"] is not None] or rows
    lightings = sorted({r["lighting"] for r in cells})
    starts = sorted({r["max_radius"] for r in cells if r["max_radius"] is not None})
    column = {start: k for k, start in enumerate(starts)} or {None: 0}
    width, height = max(1, len(column)), max(1, len(lightings))
    fig, ax = plt.subplots(figsize=(min(1.0 * width + 1.6, 16), 1.0 * height + 1.2))
    cmap = plt.get_cmap("coolwarm")
    inner = 0.8  # share of a cell the unit square (FPR, recall) occupies
    for row in cells:
        x0 = column[row["max_radius"]] + (1 - inner) / 2
        y0 = height - 1 - lightings.index(row["lighting"]) + (1 - inner) / 2
        fpr = [b["fpr"] for b in row["bubbles"]]
        recall = [b["recall"] for b in row["bubbles"]]
        ax.scatter(
            [x0 + inner * f for f in fpr],
            [y0 + inner * r for r in recall],
            s=[250 * b["frames"] / row["frames"] for b in row["bubbles"]],
            c=[(f + (1 - r)) / 2 for f, r in zip(fpr, recall)],
            cmap=cmap,
            vmin=0,
            vmax=1,
            alpha=0.7,
            edgecolors="k",
            linewidths=0.3,
        )
        ax.add_patch(plt.Rectangle((x0, y0), inner, inner, fill=False, lw=0.4, color="grey"))
        ax.text(x0, y0 + inner + 0.01, f"N={row['frames']}", color="grey", fontsize=6)
    ax.set_xticks([k + 0.5 for k in range(width)], [_radius_name(s) for s in column])
    ax.set_yticks([height - 1 - k + 0.5 for k in range(height)], lightings)
    ax.set_xlim(0, width)
    ax.set_ylim(0, height)
    ax.tick_params(length=0, labelsize=8)
    ax.set_xlabel("max target radius (px); in each cell: recall up, false positive rate right")
    fig.tight_layout()
    return _save(fig, path)


def _radius_name(start: int | None) -> str:
    return "all" if start is None else radius_label(start)


def category_bars(rows: list[dict], path: Path) -> str:
    """Per-category bars of mean recall, mean precision and hit-frame fraction."""
    plt = pyplot()
    labels = [
        r["lighting"]
        if r["max_radius"] is None
        else f"{r['lighting']}-{radius_label(r['max_radius'])}"
        for r in rows
    ]
    fig, ax = plt.subplots(figsize=(max(5, 0.6 * len(rows) + 2), 3.5))
    width = 0.27
    for k, key in enumerate(("recall_mean", "precision_mean", "hit_frame_fraction")):
        ax.bar(
            [i + (k - 1) * width for i in range(len(rows))],
            [r[key] or 0.0 for r in rows],
            width,
            label=key,
        )
    ax.set_xticks(range(len(rows)), labels, rotation=45, ha="right", fontsize=8)
    ax.set_ylim(0, 1)
    ax.legend(fontsize=8)
    fig.tight_layout()
    return _save(fig, path)


def pr_curve(curve: dict | None, ap: float | None, path: Path) -> str:
    """COCOeval's interpolated precision-recall curve at IoU 0.5."""
    plt = pyplot()
    fig, ax = plt.subplots(figsize=(4, 4))
    if curve:
        precision = [max(p, 0.0) for p in curve["precision"]]
        ax.plot(curve["recall"], precision)
    ax.set_xlabel("recall")
    ax.set_ylabel("precision")
    ax.set_xlim(0, 1)
    ax.set_ylim(0, 1.02)
    ax.set_title(f"IoU 0.5, AP = {ap:.3f}" if ap is not None else "IoU 0.5")
    fig.tight_layout()
    return _save(fig, path)


def confusion_plot(state: dict, path: Path) -> str:
    """The state confusion matrix (rows: ground truth, columns: predicted), counts annotated."""
    plt = pyplot()
    labels, matrix = state["confusion"]["labels"], state["confusion"]["matrix"]
    fig, ax = plt.subplots(figsize=(4.5, 4))
    ax.imshow(matrix, cmap="Blues")
    for i, row in enumerate(matrix):
        for j, count in enumerate(row):
            ax.text(j, i, str(count), ha="center", va="center", fontsize=8)
    ax.set_xticks(range(len(labels)), labels, rotation=45, ha="right")
    ax.set_yticks(range(len(labels)), labels)
    ax.set_xlabel("predicted")
    ax.set_ylabel("ground truth")
    fig.tight_layout()
    return _save(fig, path)


def plot_names(report: dict) -> list[str]:
    """The plots that apply to a report: detection runs get the bubble plot, the category bars
    and the PR curve; runs with predicted states get the confusion matrix."""
    names = []
    if "ap" in report["iou50"]:
        names += ["recall_fpr_bubbles.png", "categories.png", "pr_curve.png"]
    if report["state"]["pairs"] and "note" not in report["state"]:
        names.append("confusion.png")
    return names


def write_plots(folder: Path, report: dict) -> None:
    """Write the plots of :func:`plot_names` into ``folder``."""
    folder.mkdir(parents=True, exist_ok=True)
    draw = {
        "recall_fpr_bubbles.png": lambda path: bubble_plot(report["categories"], path),
        "categories.png": lambda path: category_bars(report["categories"], path),
        "pr_curve.png": lambda path: pr_curve(
            report["iou50"].get("pr_curve"), report["iou50"]["ap"], path
        ),
        "confusion.png": lambda path: confusion_plot(report["state"], path),
    }
    for name in plot_names(report):
        draw[name](folder / name)


class Plots(ReportWriter):
    name = "plots"
    summary = "plots/: Figure 5-1 bubbles, category bars, PR curve, state confusion (PNG)"

    def files(self, run: RunResult) -> list[str]:
        return [f"plots/{name}" for name in plot_names(run.report)]

    def write(self, run: RunResult, folder: Path) -> None:
        write_plots(folder / "plots", run.report)


@hookimpl
def register_report_writers(register):
    register(Plots)
