"""Report writer ``markdown``: ``summary.md``, the headline figures with their 95 % intervals, the
Zheng Table 5-2 breakdown (lighting x max target radius), the state tables and skipped inputs."""

from __future__ import annotations

from pathlib import Path

from tsrkit.api import (
    ReportWriter,
    RunResult,
    atomic_open,
    fmt,
    headline,
    hookimpl,
    markdown_table,
    radius_label,
    recall_sort_key,
    title,
)


class MarkdownSummary(ReportWriter):
    name = "markdown"
    summary = "summary.md: headline figures, Table 5-2 breakdown, state tables, skipped inputs"

    def files(self, run: RunResult) -> list[str]:
        return ["summary.md"]

    def write(self, run: RunResult, folder: Path) -> None:
        with atomic_open(folder / "summary.md") as fh:
            fh.write(summary_markdown(run.report))


def summary_markdown(report: dict) -> str:
    """The Markdown summary: headline figures, skipped inputs and the Table 5-2 breakdown."""
    pf = report["per_frame"]
    lines = [
        f"# {title(report)} on {report['dataset']['name']}",
        "",
        f"{report['frames']} frames evaluated, {len(report['skipped'])} skipped; "
        f"box convention: {report['dataset']['box_convention']}; evaluated box: "
        f"{report.get('evaluated_box') or '-'}.",
        "",
        *[f"**Note:** {note}\n" for note in report.get("notes", [])],
        markdown_table(
            ["figure", "value", "95 % interval"],
            [[label, value, _interval(report, label)] for label, value in headline(report).items()],
        ),
        "",
        pf.get("note")
        or f"Frames without ground truth: {pf['frames_without_gt']} "
        f"({pf['false_positives_without_gt']} false positives on "
        f"{pf['frames_without_gt_with_detections']} of them).",
        "",
    ]
    if report["categories"]:
        lines += [
            "## Frame counts by lighting and max target radius (Zheng Table 5-2 layout)",
            "",
            category_markdown(report["categories"]),
            "",
        ]
    if report["state"]["pairs"] and "note" not in report["state"]:
        lines += ["## States of matched detections", "", state_markdown(report["state"]), ""]
    if report["skipped"]:
        lines += (
            ["## Skipped", ""]
            + [f"- `{s['source']}`: {s['reason']}" for s in report["skipped"]]
            + [""]
        )
    return "\n".join(lines)


def _interval(report: dict, label: str) -> str:
    key = {"recall": "recall_mean", "prec.": "precision_mean", "hit": "hit_frame_fraction"}.get(
        label
    )
    interval = report.get("intervals", {}).get(key) if key else None
    return f"{interval[0]:.3f} - {interval[1]:.3f}" if interval else ""


def category_markdown(rows: list[dict]) -> str:
    """Table 5-2: one row per lighting (total) and radius; recall labels then precision bounds."""
    recall_cols = sorted({k for r in rows for k in r["recall_counts"]}, key=recall_sort_key)
    precision_cols = sorted(
        {k for r in rows for k in r["precision_counts"]}, key=lambda k: int(k[:-1])
    )
    header = (
        ["lighting - max radius"]
        + [f"R {c}" for c in recall_cols]
        + [f"P {c}" for c in precision_cols]
        + ["total"]
    )
    body = []
    for r in rows:
        name = r["lighting"] if r["max_radius"] is None else radius_label(r["max_radius"])
        body.append(
            [name]
            + [str(r["recall_counts"].get(c, "")) for c in recall_cols]
            + [str(r["precision_counts"].get(c, "")) for c in precision_cols]
            + [str(r["frames"])]
        )
    return markdown_table(header, body) if rows else "(no frame with ground truth)"


def state_markdown(state: dict) -> str:
    """Confusion matrix (rows truth, columns predicted), per-class figures and R-Y errors."""
    labels, matrix = state["confusion"]["labels"], state["confusion"]["matrix"]
    confusion = markdown_table(
        ["truth \\ predicted"] + labels,
        [[label] + [str(v) for v in row] for label, row in zip(labels, matrix)],
    )
    classes = markdown_table(
        ["state", "precision", "recall", "support"],
        [
            [name, fmt(c["precision"]), fmt(c["recall"]), str(c["support"])]
            for name, c in state["per_class"].items()
        ],
    )
    ry = state["red_yellow_errors"]
    ratio = f"mean discriminative ratio (Zheng 5.3): {fmt(state['discriminative_ratio']['mean'])}."
    if not ry:  # sign classes: no red/yellow pair
        return f"{confusion}\n\n{classes}\n\n{ratio[0].upper()}{ratio[1:]}"
    return (
        f"{confusion}\n\n{classes}\n\nR-Y errors (Mascetti 5.1): {ry['total']} "
        f"({ry['red_as_yellow']} red as yellow, {ry['yellow_as_red']} yellow as red); {ratio}"
    )


@hookimpl
def register_report_writers(register):
    register(MarkdownSummary)
