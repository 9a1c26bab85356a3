"""Report writer ``html``: ``report.html``, one self-contained offline page of a run.

The headline figures, the Zheng Table 5-2 breakdown (lighting x max target radius), the state
confusion and per-class tables, the plots and a gallery of the run's worst frames with overlays
(ground truth in green, detections whose centre is in a box in blue, false positives in red,
misses marked): inline CSS and JavaScript (every table sorts by a click on its header and
filters by the text box above it), images embedded as data URIs, nothing fetched.
"""

from __future__ import annotations

import base64
import html
import tempfile
from pathlib import Path

import cv2

from tsrkit.api import (
    DetectionRecord,
    ReportWriter,
    RunResult,
    atomic_open,
    fmt,
    headline,
    hookimpl,
    radius_label,
    title,
)
from tsrkit_plugins.writers.plots import plot_names, write_plots

#: Frames shown in the gallery of worst frames.
GALLERY = 8
#: Width (px) of a gallery image.
THUMB_WIDTH = 480

STYLE = """
body{font-family:system-ui,sans-serif;margin:1.5em;color:#222;max-width:1200px}
table{border-collapse:collapse;margin:.5em 0 1.5em}td,th{border:1px solid #ccc;padding:3px 8px}
th{background:#eee;cursor:pointer;user-select:none}td.num{text-align:right}
input.filter{margin:.2em 0;padding:2px 6px}figure{display:inline-block;margin:.5em}
figcaption{font-size:.85em;color:#555;max-width:480px}img{max-width:100%}
"""

SCRIPT = """
document.querySelectorAll('table.sortable').forEach(function (table) {
  table.querySelectorAll('th').forEach(function (th, col) {
    th.addEventListener('click', function () {
      var body = table.tBodies[0], rows = Array.from(body.rows);
      var up = th.dataset.order !== 'asc'; th.dataset.order = up ? 'asc' : 'desc';
      rows.sort(function (a, b) {
        var x = a.cells[col].innerText, y = b.cells[col].innerText;
        var nx = parseFloat(x), ny = parseFloat(y);
        var c = (!isNaN(nx) && !isNaN(ny)) ? nx - ny : x.localeCompare(y);
        return up ? c : -c;
      });
      rows.forEach(function (r) { body.appendChild(r); });
    });
  });
});
document.querySelectorAll('input.filter').forEach(function (input) {
  input.addEventListener('input', function () {
    var table = document.getElementById(input.dataset.table), q = input.value.toLowerCase();
    Array.from(table.tBodies[0].rows).forEach(function (r) {
      r.style.display = r.innerText.toLowerCase().indexOf(q) >= 0 ? '' : 'none';
    });
  });
});
"""


def table(ident: str, header: list[str], rows: list[list[str]]) -> str:
    """A sortable, filterable HTML table (numbers right-aligned)."""

    def cell(value: str) -> str:
        try:
            float(value)
            return f'<td class="num">{html.escape(value)}</td>'
        except ValueError:
            return f"<td>{html.escape(value)}</td>"

    head = "".join(f"<th>{html.escape(h)}</th>" for h in header)
    body = "".join("<tr>" + "".join(cell(v) for v in row) + "</tr>" for row in rows)
    return (
        f'<input class="filter" data-table="{ident}" placeholder="filter rows">'
        f'<table class="sortable" id="{ident}"><thead><tr>{head}</tr></thead>'
        f"<tbody>{body}</tbody></table>"
    )


def data_uri(png_or_jpeg: bytes, kind: str = "png") -> str:
    return f"data:image/{kind};base64,{base64.b64encode(png_or_jpeg).decode('ascii')}"


def frame_errors(sample, record) -> tuple[list, list, list, int]:
    """Detections whose centre is in a box, false positives (in none), missed boxes, and the
    detections in a box whose state differs from the box's (both known)."""
    boxes = [a.bbox for a in sample.annotations]
    hits: list[DetectionRecord] = []
    false: list[DetectionRecord] = []
    covered, wrong = set(), 0
    for d in record.detections:
        inside = [
            k for k, (x0, y0, x1, y1) in enumerate(boxes) if x0 <= d.x <= x1 and y0 <= d.y <= y1
        ]
        (hits if inside else false).append(d)
        covered.update(inside)
        truth = {sample.annotations[k].state for k in inside} - {"unknown", None}
        wrong += bool(truth) and d.state != "unknown" and d.state not in truth
    missed = [b for k, b in enumerate(boxes) if k not in covered]
    return hits, false, missed, wrong


def overlay(sample, hits, false, missed, box: str) -> bytes | None:
    """The frame with its errors drawn, as a JPEG at most :data:`THUMB_WIDTH` wide."""
    try:
        image = sample.load().image.copy()
    except Exception:
        return None
    for a in sample.annotations:
        x0, y0, x1, y1 = (int(round(v)) for v in a.bbox)
        cv2.rectangle(image, (x0, y0), (x1, y1), (0, 200, 0), 2)
    for colour, dets in (((255, 120, 0), hits), ((0, 0, 255), false)):
        for d in dets:
            x0, y0, x1, y1 = (int(round(v)) for v in d.box(box))
            cv2.rectangle(image, (x0, y0), (x1, y1), colour, 2)
    for x0, _, x1, y1 in missed:
        cv2.drawMarker(
            image, (int((x0 + x1) / 2), int(y1) + 8), (0, 200, 255), cv2.MARKER_TRIANGLE_UP, 12, 2
        )
    scale = min(1.0, THUMB_WIDTH / image.shape[1])
    if scale < 1.0:
        image = cv2.resize(image, None, fx=scale, fy=scale, interpolation=cv2.INTER_AREA)
    ok, encoded = cv2.imencode(".jpg", image, [cv2.IMWRITE_JPEG_QUALITY, 85])
    return encoded.tobytes() if ok else None


def gallery(run: RunResult) -> str:
    """The :data:`GALLERY` frames with the most misses plus false positives, with overlays."""
    box = run.report.get("evaluated_box") or "lens"
    scored = []
    for sample, record in run.pairs():
        hits, false, missed, wrong = frame_errors(sample, record)
        errors = len(missed) + len(false) + wrong
        scored.append((errors, sample, record, hits, false, missed, wrong))
    scored.sort(key=lambda s: -s[0])  # stable: equal errors keep dataset order
    figures = []
    for errors, sample, _, hits, false, missed, wrong in scored[:GALLERY]:
        if errors == 0:
            break
        image = overlay(sample, hits, false, missed, box)
        if image is None:
            continue
        caption = (
            f"{Path(sample.source).name}: {len(missed)} missed, {len(false)} false positives, "
            f"{len(hits)} found, {wrong} wrong states"
        )
        figures.append(
            f'<figure><img class="gallery" alt="{html.escape(caption)}" '
            f'src="{data_uri(image, "jpeg")}">'
            f"<figcaption>{html.escape(caption)}</figcaption></figure>"
        )
    if not figures:
        return "<p>No frame with a miss or a false positive.</p>"
    return (
        "<p>Green: ground truth; blue: detections in a box; red: false positives; "
        "orange triangle: a missed light.</p>" + "".join(figures)
    )


def plots(report: dict) -> str:
    """The run's plots, drawn into a temporary folder and embedded."""
    with tempfile.TemporaryDirectory() as folder:
        write_plots(Path(folder), report)
        return "".join(
            f'<figure><img alt="{name}" src="{data_uri((Path(folder) / name).read_bytes())}">'
            f"<figcaption>{name}</figcaption></figure>"
            for name in plot_names(report)
        )


def page(run: RunResult) -> str:
    """The whole self-contained page."""
    report = run.report
    name = f"{title(report)} on {report['dataset']['name']}"
    parts = [
        f"<h1>{html.escape(name)}</h1>",
        f"<p>{report['frames']} frames evaluated, {len(report['skipped'])} skipped; evaluated "
        f"box: {html.escape(str(report.get('evaluated_box') or '-'))}.</p>",
        *[f"<p><b>Note:</b> {html.escape(n)}</p>" for n in report.get("notes", [])],
        "<h2>Headline</h2>",
        table("headline", ["figure", "value"], [[k, v] for k, v in headline(report).items()]),
    ]
    if report["categories"]:
        rows = [
            [
                r["lighting"],
                "all" if r["max_radius"] is None else radius_label(r["max_radius"]),
                str(r["frames"]),
                fmt(r["recall_mean"]),
                fmt(r["precision_mean"]),
                fmt(r["hit_frame_fraction"]),
            ]
            for r in report["categories"]
        ]
        parts += [
            "<h2>Lighting x max target radius (Zheng Table 5-2 layout)</h2>",
            table(
                "categories",
                ["lighting", "max radius", "frames", "recall", "precision", "hit"],
                rows,
            ),
        ]
    state = report["state"]
    if state.get("pairs") and "note" not in state:
        labels, matrix = state["confusion"]["labels"], state["confusion"]["matrix"]
        parts += [
            "<h2>State confusion (rows: truth, columns: predicted)</h2>",
            table(
                "confusion",
                ["truth", *labels],
                [[t, *map(str, row)] for t, row in zip(labels, matrix)],
            ),
        ]
        per_class = state.get("per_class") or {}
        if per_class:
            keys = sorted({k for v in per_class.values() for k in v})
            parts += [
                "<h2>Per class</h2>",
                table(
                    "per-class",
                    ["state", *keys],
                    [[s, *(fmt(v.get(k)) for k in keys)] for s, v in per_class.items()],
                ),
            ]
    if report["skipped"]:
        parts += [
            "<h2>Skipped</h2>",
            table(
                "skipped",
                ["source", "reason"],
                [[s["source"], s["reason"]] for s in report["skipped"]],
            ),
        ]
    parts += ["<h2>Plots</h2>", plots(report), "<h2>Worst frames</h2>", gallery(run)]
    return (
        f'<!DOCTYPE html><html lang="en"><head><meta charset="utf-8"><title>{html.escape(name)}'
        f"</title><style>{STYLE}</style></head><body>{''.join(parts)}<script>{SCRIPT}</script>"
        "</body></html>"
    )


class HtmlReport(ReportWriter):
    name = "html"
    summary = "report.html: one offline page with tables, plots and the worst frames' overlays"

    def files(self, run: RunResult) -> list[str]:
        return ["report.html"]

    def write(self, run: RunResult, folder: Path) -> None:
        with atomic_open(folder / "report.html") as fh:
            fh.write(page(run))

    def write_comparison(self, folder: Path) -> list[str]:
        from tsrkit_plugins.writers.html.compare import compare_page

        with atomic_open(folder / "compare.html") as fh:
            fh.write(compare_page(folder))
        return ["compare.html"]


@hookimpl
def register_report_writers(register):
    register(HtmlReport)
