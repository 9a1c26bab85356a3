"""Benchmark outputs: report.json, summary.md (Table 5-2 layout), COCO files, plots, rich tables.

Every file is written atomically (:mod:`tsrkit.atomic`), so a killed run never leaves half a
report. ``summary_markdown`` and ``report_table`` render the same headline figures.
"""
from __future__ import annotations

import platform
import sys
from importlib import metadata
from pathlib import Path
from typing import Any

from rich import box
from rich.console import Console
from rich.progress import (BarColumn, MofNCompleteColumn, Progress, TextColumn,
                           TimeRemainingColumn)
from rich.table import Table

from tsrkit.atomic import atomic_open, write_json
from tsrkit.eval.perframe import recall_sort_key
from tsrkit.types import Dataset

#: (section, key, column label, format) of the headline figures.
HEADLINE = (("per_frame", "recall_mean", "recall", ".3f"),
            ("per_frame", "precision_mean", "prec.", ".3f"),
            ("per_frame", "hit_frame_fraction", "hit", ".3f"), ("iou50", "ap", "AP50", ".3f"),
            ("iou50", "ap_50_95", "AP", ".3f"), ("state", "accuracy", "state", ".3f"),
            ("timing", "ms_per_frame_median", "ms", ".1f"))


class ProgressBar:
    """A rich progress bar with frames/s on stderr; does nothing when disabled."""

    def __init__(self, total: int, enabled: bool, label: str = "benchmark"):
        self.progress = Progress(
            TextColumn(f"[bold]{label}"), BarColumn(), MofNCompleteColumn(),
            TextColumn("{task.fields[rate]} frames/s"), TimeRemainingColumn(),
            console=Console(stderr=True), disable=not enabled, transient=False)
        self.task = self.progress.add_task("frames", total=total, rate="-")

    def __enter__(self) -> ProgressBar:
        self.progress.start()
        return self

    def __exit__(self, *exc) -> None:
        self.progress.stop()

    def advance(self) -> None:
        self.progress.advance(self.task)
        speed = self.progress.tasks[0].speed
        self.progress.update(self.task, rate=f"{speed:.1f}" if speed else "-")


def versions() -> dict[str, str]:
    """Versions of Python and the libraries that shape the numbers."""
    found = {"python": platform.python_version()}
    for package in ("tsrkit", "numpy", "opencv-python-headless", "opencv-python", "scipy",
                    "scikit-learn", "pycocotools"):
        try:
            found[package] = metadata.version(package)
        except metadata.PackageNotFoundError:
            continue
    return found


def base_report(dataset: Dataset, detector: dict | None, classifier: dict | None) -> dict:
    """The descriptive keys of report.json (the metrics are added by the runner)."""
    return {
        "dataset": {"name": dataset.name, "format": dataset.format, "root": dataset.root,
                    "samples": len(dataset),
                    "box_convention": (dataset.info.get("box") or dataset.info.get("box_convention")
                                       or "unknown")},
        "detector": detector, "classifier": classifier,
        "params": {kind: plugin["params"] for kind, plugin in
                   (("detector", detector), ("classifier", classifier)) if plugin},
        "versions": versions(),
    }


def write_outputs(out: Path, report: dict, evaluation) -> None:
    """report.json, summary.md, detections.coco.json, ground_truth.coco.json and plots/."""
    from tsrkit.plots import write_plots

    out.mkdir(parents=True, exist_ok=True)
    write_json(out / "ground_truth.coco.json", evaluation.ground_truth())
    write_json(out / "detections.coco.json", evaluation.results)
    report["plots"] = write_plots(out / "plots", report, evaluation.pr_curve)
    report["files"] = sorted(["report.json", "summary.md", "detections.jsonl",
                              "detections.coco.json", "ground_truth.coco.json"])
    write_json(out / "report.json", report)
    with atomic_open(out / "summary.md") as fh:
        fh.write(summary_markdown(report))


def fmt(value: Any, spec: str = ".3f") -> str:
    """A number for a table (``spec`` for floats), or a dash for a missing value."""
    if value is None:
        return "-"
    return format(value, spec) if isinstance(value, float) else str(value)


def headline(report: dict) -> dict[str, str]:
    """The headline figures of a report, formatted."""
    return {label: fmt((report.get(section) or {}).get(key), spec)
            for section, key, label, spec in HEADLINE}


def title(report: dict) -> str:
    """``detector + classifier`` as a run's name."""
    names = [p["name"] for p in (report["detector"], report["classifier"]) if p]
    return " + ".join(names)


def summary_markdown(report: dict) -> str:
    """The Markdown summary: headline figures, skipped inputs and the Table 5-2 breakdown."""
    pf = report["per_frame"]
    lines = [f"# {title(report)} on {report['dataset']['name']}", "",
             f"{report['frames']} frames evaluated, {len(report['skipped'])} skipped; "
             f"box convention: {report['dataset']['box_convention']}.", "",
             markdown_table(["figure", "value", "95 % interval"],
                            [[label, value, _interval(report, label)]
                             for label, value in headline(report).items()]), "",
             pf.get("note") or
             f"Frames without ground truth: {pf['frames_without_gt']} "
             f"({pf['false_positives_without_gt']} false positives on "
             f"{pf['frames_without_gt_with_detections']} of them).", ""]
    if report["categories"]:
        lines += ["## Frame counts by lighting and max target radius (Zheng Table 5-2 layout)",
                  "", category_markdown(report["categories"]), ""]
    if report["state"]["pairs"] and "note" not in report["state"]:
        lines += ["## States of matched detections", "", state_markdown(report["state"]), ""]
    if report["skipped"]:
        lines += ["## Skipped", ""] + [f"- `{s['source']}`: {s['reason']}"
                                       for s in report["skipped"]] + [""]
    return "\n".join(lines)


def _interval(report: dict, label: str) -> str:
    key = {"recall": "recall_mean", "prec.": "precision_mean",
           "hit": "hit_frame_fraction"}.get(label)
    interval = report.get("intervals", {}).get(key) if key else None
    return f"{interval[0]:.3f} - {interval[1]:.3f}" if interval else ""


def category_markdown(rows: list[dict]) -> str:
    """Table 5-2: one row per lighting (total) and radius; recall labels then precision bounds."""
    recall_cols = sorted({k for r in rows for k in r["recall_counts"]}, key=recall_sort_key)
    precision_cols = sorted({k for r in rows for k in r["precision_counts"]},
                            key=lambda k: int(k[:-1]))
    header = (["lighting - max radius"] + [f"R {c}" for c in recall_cols]
              + [f"P {c}" for c in precision_cols] + ["total"])
    body = []
    for r in rows:
        name = r["lighting"] if r["max_radius"] is None else f"{r['max_radius']}"
        body.append([name] + [str(r["recall_counts"].get(c, "")) for c in recall_cols]
                    + [str(r["precision_counts"].get(c, "")) for c in precision_cols]
                    + [str(r["frames"])])
    return markdown_table(header, body) if rows else "(no frame with ground truth)"


def state_markdown(state: dict) -> str:
    """Confusion matrix (rows truth, columns predicted), per-class figures and R-Y errors."""
    labels, matrix = state["confusion"]["labels"], state["confusion"]["matrix"]
    confusion = markdown_table(["truth \\ predicted"] + labels,
                               [[label] + [str(v) for v in row]
                                for label, row in zip(labels, matrix)])
    classes = markdown_table(["state", "precision", "recall", "support"],
                             [[name, fmt(c["precision"]), fmt(c["recall"]), str(c["support"])]
                              for name, c in state["per_class"].items()])
    ry = state["red_yellow_errors"]
    ratio = f"mean discriminative ratio (Zheng 5.3): {fmt(state['discriminative_ratio']['mean'])}."
    if not ry:  # sign classes: no red/yellow pair
        return f"{confusion}\n\n{classes}\n\n{ratio[0].upper()}{ratio[1:]}"
    return (f"{confusion}\n\n{classes}\n\nR-Y errors (Mascetti 5.1): {ry['total']} "
            f"({ry['red_as_yellow']} red as yellow, {ry['yellow_as_red']} yellow as red); {ratio}")


def markdown_table(header: list[str], rows: list[list[str]]) -> str:
    """A GitHub Markdown table."""
    lines = ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    lines += ["| " + " | ".join(row) + " |" for row in rows]
    return "\n".join(lines)


def report_table(reports: list[dict]) -> Table:
    """A rich table of the headline figures, one row per run."""
    table = Table(title=f"tsrkit benchmark: {reports[0]['dataset']['name']} "
                        f"({reports[0]['frames']} frames)", box=box.SIMPLE_HEAD, pad_edge=False,
                  caption="recall, precision, hit: Zheng 5.2.1 per-frame means; AP50 / AP "
                          "(0.5:0.95): pycocotools; state: accuracy; ms: median per frame")
    table.add_column("method", overflow="fold")
    for _, _, label, _ in HEADLINE:
        table.add_column(label, justify="right", min_width=5, no_wrap=True)
    table.add_column("skip", justify="right")
    for report in reports:
        table.add_row(title(report), *headline(report).values(), str(len(report["skipped"])))
    return table


def print_table(reports: list[dict], file=None) -> None:
    """Print the headline table to stdout (or ``file``)."""
    Console(file=file or sys.stdout).print(report_table(reports))


def compare_markdown(comparison: dict) -> str:
    """compare.md: the side-by-side headline table and the paired tests."""
    reports = comparison["reports"]
    lines = [f"# Comparison on {comparison['dataset']}", "",
             markdown_table(["method"] + [label for _, _, label, _ in HEADLINE],
                            [[title(r)] + list(headline(r).values()) for r in reports]), "",
             "## Paired tests on the same frames (Wilcoxon signed-rank, per-frame recall)", ""]
    lines.append(markdown_table(
        ["A", "B", "frames", "mean A - B", "p", "verdict"],
        [[t["a"], t["b"], str(t["frames"]), fmt(t["mean_difference"]), fmt(t["p_value"]),
          t["verdict"]] for t in comparison["paired_tests"]]))
    return "\n".join(lines) + "\n"


def write_compare(out: Path, comparison: dict) -> None:
    """compare.json and compare.md in ``out``."""
    write_json(out / "compare.json", comparison)
    with atomic_open(out / "compare.md") as fh:
        fh.write(compare_markdown(comparison))
