"""``tsrkit report RUN_DIR``: re-render ``report.html`` of a finished run (or ``compare.html`` of
a compare folder) from what the run wrote, without recomputing anything."""

from __future__ import annotations

from pathlib import Path

import click

from tsrkit.atomic import atomic_open
from tsrkit.eval.stats import format_p
from tsrkit.report import headline_rows, title
from tsrkit.runfolder import load_run, read_report


def compare_page(folder: Path) -> str:
    """``compare.html``: the runs side by side, the paired tests, links to each run's page."""
    from tsrkit_plugins.writers.html import SCRIPT, STYLE, table

    data = read_report(folder / "compare.json")
    reports = data["reports"]
    columns, values = headline_rows(reports)
    rows = [[title(r), *row] for r, row in zip(reports, values)]
    tests = [
        [
            *(str(t.get(k, "")) for k in ("a", "b", "metric", "verdict")),
            format_p(t.get("p_value")),
            str(t.get("frames", "")),
        ]
        for t in data.get("paired_tests", []) + data.get("verifier_tests", [])
    ]
    links = "".join(
        f'<li><a href="{d}/report.html">{d}</a></li>'
        for d in data.get("runs", data["detectors"])
        if (folder / d / "report.html").is_file()
    )
    body = (
        f"<h1>compare on {data['dataset']}</h1>"
        + table("runs", ["run", *(f.label for f in columns)], rows)
        + "<h2>Paired tests</h2>"
        + table("tests", ["a", "b", "metric", "verdict", "p", "frames"], tests)
        + f"<h2>Each run</h2><ul>{links}</ul>"
    )
    return (
        f'<!DOCTYPE html><html lang="en"><head><meta charset="utf-8"><title>compare</title>'
        f"<style>{STYLE}</style></head><body>{body}<script>{SCRIPT}</script></body></html>"
    )


@click.command("report")
@click.argument("run_dir", type=click.Path(exists=True, file_okay=False))
def report_command(run_dir) -> None:
    """Write RUN_DIR/report.html (a benchmark folder) or RUN_DIR/compare.html (a compare folder)
    from the files the run left, without recomputing.

    \b
    Examples:
      tsrkit report tsrkit-out/conspicuity     # one benchmark run: report.html
      tsrkit report tsrkit-out                 # a compare folder: compare.html
    """
    from tsrkit_plugins.writers.html import page

    folder = Path(run_dir)
    if (folder / "compare.json").is_file():
        out = folder / "compare.html"
        text = compare_page(folder)
    else:
        out = folder / "report.html"
        text = page(load_run(folder))
    with atomic_open(out) as fh:
        fh.write(text)
    click.echo(f"-> {out}")
