"""Report writer ``html``: ``report.html``, one self-contained offline page of a run.

Every result of the run, rendered generically: the notes, the headline figures with their 95 %
intervals, each result's remarks and tables (the run's dataset, split, plugins, parameters and
versions first), the plots with their captions, and for a benchmark a gallery of the worst
frames with enlarged crops around each light that went wrong. Inline CSS and JavaScript (every
table sorts by a click on its header and filters by the text box above it), images embedded as
data URIs, nothing fetched; links to the run's other files.
"""

from __future__ import annotations

import html
from collections.abc import Sequence
from pathlib import Path

from tsrkit.api import ReportWriter, RunResult, atomic_open, heading, headline_table, hookimpl
from tsrkit_plugins.writers.html.gallery import data_uri, gallery

STYLE = """
body{font-family:system-ui,sans-serif;margin:1.5em;color:#222;max-width:1200px}
table{border-collapse:collapse;margin:.5em 0 1.5em}td,th{border:1px solid #ccc;padding:3px 8px}
th{background:#eee;cursor:pointer;user-select:none}td.num{text-align:right}
input.filter{margin:.2em 0;padding:2px 6px}figure{display:inline-block;margin:.5em}
figcaption{font-size:.85em;color:#555;max-width:480px}img{max-width:100%}
p.caption{font-size:.85em;color:#555;margin-top:-1em;max-width:900px}p.note{color:#8a4b00}
div.frame{border-top:1px solid #ddd;padding:.5em 0;display:flex;flex-wrap:wrap;gap:.5em}
div.frame p{flex-basis:100%;margin:.2em 0}div.crops{display:flex;flex-wrap:wrap;max-width:700px}
figure.crop{margin:0 .3em .3em 0}figure.crop figcaption{text-align:center;max-width:160px}
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


def table(ident: str, header: Sequence[str], rows: Sequence[Sequence[str]]) -> str:
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
        f'<input class="filter" data-table="{html.escape(ident)}" placeholder="filter rows">'
        f'<table class="sortable" id="{html.escape(ident)}"><thead><tr>{head}</tr></thead>'
        f"<tbody>{body}</tbody></table>"
    )


def results_html(run: RunResult) -> str:
    """The headline table, the remarks and every result's tables, in order."""
    figures = run.headline()
    parts, idents = [], set()
    if figures:
        parts += ["<h2>Headline</h2>", table("headline", *headline_table(figures))]
    parts += [f"<p>{html.escape(r)}</p>" for r in run.remarks()]
    for result in run.results:
        for t in result.tables():
            ident = t.ident if t.ident not in idents else f"{result.metric}-{t.ident}"
            idents.add(ident)
            parts += [f"<h2>{html.escape(t.title)}</h2>", table(ident, t.columns, t.rows)]
            if t.caption:
                parts.append(f'<p class="caption">{html.escape(t.caption)}</p>')
    return "".join(parts)


def plots_html(run: RunResult) -> str:
    """Every plot, embedded, with its caption."""
    captions = run.captions()
    return "".join(
        f'<figure><img alt="{html.escape(name)}" src="{data_uri(png)}">'
        f"<figcaption>{html.escape(captions.get(name, name))}</figcaption></figure>"
        for name, png in run.plot_images().items()
    )


def links(report: dict) -> str:
    """Links to the run's other files that a reader opens (``report.json``, ``summary.md``...)."""
    names = [f for f in report.get("files", []) if f != "report.html"]
    if not names:
        return ""
    shown = "".join(f'<a href="{html.escape(f)}">{html.escape(f)}</a> ' for f in names)
    return f'<p class="files">Files of this run: {shown}</p>'


def page(run: RunResult) -> str:
    """The whole self-contained page."""
    report = run.report
    name = heading(report)
    parts = [
        f"<h1>{html.escape(name)}</h1>",
        links(report),
        *[f'<p class="note"><b>Note:</b> {html.escape(n)}</p>' for n in report.get("notes", [])],
        results_html(run),
    ]
    drawn = plots_html(run)
    if drawn:
        parts += ["<h2>Plots</h2>", drawn]
    if run.dataset is not None:
        parts += ["<h2>Worst frames</h2>", gallery(run)]
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
