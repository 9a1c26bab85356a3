"""``tsrkit report RUN_DIR``: re-render ``report.html`` of a finished run (or ``compare.html`` of
a compare folder) from what the run wrote, without recomputing anything."""

from __future__ import annotations

import dataclasses
import json
from pathlib import Path

import click

from tsrkit.atomic import atomic_open
from tsrkit.errors import TsrkitError
from tsrkit.records import FrameRecord
from tsrkit.report import RunResult, headline, title


def load_run(folder: Path) -> RunResult:
    """The :class:`RunResult` of a run folder: its ``report.json``, its ``detections.jsonl``
    and the dataset re-opened by the name the report gives (``name`` or ``name:split``)."""
    from tsrkit.benchmarking import eval_settings
    from tsrkit.datasets import open_dataset

    try:
        report = json.loads((folder / "report.json").read_text(encoding="utf-8"))
        lines = (folder / "detections.jsonl").read_text(encoding="utf-8").splitlines()
    except FileNotFoundError as exc:
        raise TsrkitError(
            f"{folder}: not a run folder ({Path(exc.filename).name} missing)"
        ) from None
    except ValueError as exc:
        raise TsrkitError(f"{folder}/report.json: not valid JSON ({exc})") from None
    name, _, split = report["dataset"]["name"].partition(":")
    dataset = open_dataset(name)
    if split:
        dataset = dataset.split(split)
    index = {s.source: k for k, s in enumerate(dataset.samples)}
    records = []
    for line in lines:
        record = FrameRecord.from_json(json.loads(line))
        if record.skipped is None and record.source in index:
            records.append(dataclasses.replace(record, index=index[record.source]))
    settings = eval_settings(dataset, True, 0.5, report.get("evaluated_box") or "auto")
    return RunResult(report, dataset, settings, tuple(records))


def compare_page(folder: Path) -> str:
    """``compare.html``: the runs side by side, the paired tests, links to each run's page."""
    from tsrkit_plugins.writers.html import SCRIPT, STYLE, table

    data = json.loads((folder / "compare.json").read_text(encoding="utf-8"))
    reports = data["reports"]
    labels = list(headline(reports[0]))
    rows = [[title(r), *headline(r).values()] for r in reports]
    tests = [
        [str(t.get(k, "")) for k in ("a", "b", "metric", "verdict", "p_value", "frames")]
        for t in data.get("paired_tests", [])
    ]
    links = "".join(
        f'<li><a href="{d}/report.html">{d}</a></li>'
        for d in data["detectors"]
        if (folder / d / "report.html").is_file()
    )
    body = (
        f"<h1>compare on {data['dataset']}</h1>"
        + table("runs", ["run", *labels], rows)
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
