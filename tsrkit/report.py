"""report.json built in one place (:func:`build_report`), the finished run writers receive, and
the headline figures as tables (rich on the terminal, Markdown for the writers).

The files of a run's folder are written by report writers (``register_report_writers``; the
built-in ones are in ``tsrkit_plugins.writers``), each atomically (:mod:`tsrkit.atomic`).
"""

from __future__ import annotations

import dataclasses
import json
import platform
import sys
from collections.abc import Iterable, Iterator, Mapping, Sequence
from dataclasses import dataclass
from importlib import metadata
from pathlib import Path
from typing import Any

from rich import box
from rich.console import Console
from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn, TimeRemainingColumn
from rich.table import Table

from tsrkit.errors import TsrkitError
from tsrkit.eval.settings import EvalSettings
from tsrkit.records import FrameRecord
from tsrkit.types import Dataset, Sample

__all__ = [
    "HEADLINE",
    "ProgressBar",
    "RunResult",
    "build_report",
    "fmt",
    "headline",
    "load_run",
    "markdown_table",
    "merge_sections",
    "print_table",
    "report_table",
    "title",
    "versions",
]

#: (section, key, column label, format) of the headline figures.
HEADLINE = (
    ("per_frame", "recall_mean", "recall", ".3f"),
    ("per_frame", "precision_mean", "prec.", ".3f"),
    ("per_frame", "hit_frame_fraction", "hit", ".3f"),
    ("iou50", "ap", "AP50", ".3f"),
    ("iou50", "ap_50_95", "AP", ".3f"),
    ("state", "accuracy", "state", ".3f"),
    ("timing", "ms_per_frame_median", "ms", ".1f"),
)


class ProgressBar:
    """A rich progress bar with frames/s on stderr; does nothing when disabled."""

    def __init__(self, total: int, enabled: bool, label: str = "benchmark"):
        self.progress = Progress(
            TextColumn(f"[bold]{label}"),
            BarColumn(),
            MofNCompleteColumn(),
            TextColumn("{task.fields[rate]} frames/s"),
            TimeRemainingColumn(),
            console=Console(stderr=True),
            disable=not enabled,
            transient=False,
        )
        self.task = self.progress.add_task("frames", total=total, rate="-")

    def __enter__(self) -> ProgressBar:
        self.progress.start()
        return self

    def __exit__(self, *exc) -> None:
        self.progress.stop()

    def advance(self, amount: int = 1) -> None:
        self.progress.advance(self.task, amount)
        speed = self.progress.tasks[0].speed
        self.progress.update(self.task, rate=f"{speed:.1f}" if speed else "-")

    def track(self, items: Iterable[Any]) -> Iterator[Any]:
        """Yield ``items``, advancing the bar after each."""
        for item in items:
            self.advance()
            yield item


def versions() -> dict[str, str]:
    """Versions of Python and the libraries that shape the numbers."""
    found = {"python": platform.python_version()}
    for package in (
        "tsrkit",
        "numpy",
        "opencv-python-headless",
        "opencv-python",
        "scipy",
        "scikit-learn",
        "pycocotools",
    ):
        try:
            found[package] = metadata.version(package)
        except metadata.PackageNotFoundError:
            continue
    return found


@dataclass(frozen=True)
class RunResult:
    """A finished benchmark run: what every report writer receives.

    ``records`` are the evaluated frames in dataset order (skipped ones are listed in
    ``report["skipped"]``); ``dataset.samples[record.index]`` is a record's ground truth.
    """

    report: dict[str, Any]
    dataset: Dataset
    settings: EvalSettings
    records: tuple[FrameRecord, ...] = ()

    def pairs(self) -> Iterator[tuple[Sample, FrameRecord]]:
        """``(sample, record)`` of every evaluated frame."""
        return ((self.dataset.samples[r.index], r) for r in self.records)


def merge_sections(results: Iterable[tuple[str, Mapping[str, Any]]]) -> dict[str, Any]:
    """The report sections of several metrics, given as ``(metric name, sections)``.

    A section two metrics fill (``iou50``) is merged key by key; a key both set is an error.
    """
    merged: dict[str, Any] = {}
    for name, sections in results:
        for section, value in sections.items():
            if section not in merged:
                merged[section] = dict(value) if isinstance(value, Mapping) else value
            elif (
                isinstance(value, Mapping)
                and isinstance(merged[section], dict)
                and not value.keys() & merged[section].keys()
            ):
                merged[section].update(value)
            else:
                raise TsrkitError(
                    f"metric '{name}' writes report section '{section}', which "
                    "another metric already wrote"
                )
    return merged


def build_report(
    dataset: Dataset,
    plugins: Mapping[str, dict | None],
    settings: EvalSettings,
    sections: Mapping[str, Any],
    frames: int,
    timing: Mapping[str, Any],
    skipped: Sequence[Mapping[str, str]],
    files: Sequence[str] = (),
    notes: Sequence[str] = (),
) -> dict[str, Any]:
    """``report.json``: the run's description, the metrics' sections, timing and outputs.

    Parameters
    ----------
    plugins : mapping
        ``{"detector": identity, "classifier": identity[, "verifier": identity]}`` (identities
        from :func:`tsrkit.engine.plugin_identity`, None for a missing stage).
    sections : mapping
        The merged metric sections (:func:`merge_sections`).
    files : sequence of str
        Every file the writers write; those under ``plots/`` are listed as ``plots``.
    notes : sequence of str
        Caveats a reader must see (e.g. a dataset that is not exhaustively labelled).
    """
    report: dict[str, Any] = {
        "dataset": {
            "name": dataset.name,
            "format": dataset.format,
            "root": dataset.root,
            "samples": len(dataset),
            "box_convention": (
                dataset.info.get("box") or dataset.info.get("box_convention") or "unknown"
            ),
        },
        **dict(plugins.items()),
        "params": {kind: identity["params"] for kind, identity in plugins.items() if identity},
        "versions": versions(),
        "evaluated_box": settings.box if settings.detection else None,
        "frames": frames,
        **sections,
        "timing": dict(timing),
        "skipped": list(skipped),
        "plots": [f for f in files if f.startswith("plots/")],
        "files": sorted(f for f in files if not f.startswith("plots/")),
    }
    if notes:
        report["notes"] = list(notes)
    return report


def fmt(value: Any, spec: str = ".3f") -> str:
    """A number for a table (``spec`` for floats), or a dash for a missing value."""
    if value is None:
        return "-"
    return format(value, spec) if isinstance(value, float) else str(value)


def headline(report: dict) -> dict[str, str]:
    """The headline figures of a report, formatted."""
    return {
        label: fmt((report.get(section) or {}).get(key), spec)
        for section, key, label, spec in HEADLINE
    }


def title(report: dict) -> str:
    """``detector + verifier + classifier`` as a run's name."""
    stages = (report["detector"], report.get("verifier"), report["classifier"])
    return " + ".join(p["name"] for p in stages if p)


def markdown_table(header: list[str], rows: list[list[str]]) -> str:
    """A GitHub Markdown table."""
    lines = ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    lines += ["| " + " | ".join(row) + " |" for row in rows]
    return "\n".join(lines)


def report_table(reports: list[dict]) -> Table:
    """A rich table of the headline figures, one row per run."""
    table = Table(
        title=f"tsrkit benchmark: {reports[0]['dataset']['name']} ({reports[0]['frames']} frames)",
        box=box.SIMPLE_HEAD,
        pad_edge=False,
        caption="recall, precision, hit: Zheng 5.2.1 per-frame means; AP50 / AP "
        "(0.5:0.95): pycocotools; state: accuracy; ms: median per frame",
    )
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
