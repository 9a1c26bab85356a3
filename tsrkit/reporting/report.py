"""report.json built in one place (:func:`build_report`), the finished run writers receive, its
results rebuilt from a report (:func:`run_results`), and the headline figures as tables (rich on
the terminal, Markdown for the writers).

The files of a run's folder are written by report writers (``register_report_writers``; the
built-in ones are in ``tsrkit_plugins.writers``), each atomically (:mod:`tsrkit.core.atomic`);
:mod:`tsrkit.reporting.runfolder` runs them.
"""

from __future__ import annotations

import platform
import sys
from collections.abc import Iterable, Iterator, Mapping, Sequence
from dataclasses import dataclass, field
from importlib import metadata
from typing import Any

from rich import box
from rich.console import Console
from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn, TimeRemainingColumn
from rich.table import Table

from tsrkit.core.records import FrameRecord
from tsrkit.core.results import Figure, MetricResult, fmt
from tsrkit.core.types import Dataset, Sample
from tsrkit.eval.guard import Failure
from tsrkit.eval.runfacts import run_facts
from tsrkit.eval.settings import EvalSettings
from tsrkit.plugin.base import Metric
from tsrkit.plugin.registry import PluginNotFound, get_registry

__all__ = [
    "LEGACY_METRICS",
    "REPORT_KEYS",
    "DrawnPlots",
    "ProgressBar",
    "RunResult",
    "build_report",
    "figure_notes",
    "fmt",
    "heading",
    "headline",
    "headline_rows",
    "headline_table",
    "legacy_metrics",
    "markdown_cell",
    "markdown_table",
    "ordered",
    "print_table",
    "report_table",
    "run_results",
    "title",
    "versions",
    "with_outputs",
]

#: The keys of ``report.json`` the core writes; no metric may write a section of these names.
REPORT_KEYS = frozenset(
    {
        "dataset",
        "detector",
        "verifier",
        "classifier",
        "params",
        "versions",
        "evaluated_box",
        "frames",
        "timing",
        "skipped",
        "plots",
        "files",
        "metrics",
        "notes",
        "failures",
    }
)


class ProgressBar:
    """A rich progress bar with frames/s on stderr; does nothing when disabled or when stderr
    is not a terminal (a redirected log gets no bar lines)."""

    def __init__(self, total: int, enabled: bool, label: str = "benchmark"):
        console = Console(stderr=True)
        self.progress = Progress(
            TextColumn(f"[bold]{label}"),
            BarColumn(),
            MofNCompleteColumn(),
            TextColumn("{task.fields[rate]} frames/s"),
            TimeRemainingColumn(),
            console=console,
            disable=not (enabled and console.is_terminal),
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
    """A finished run: what every report writer receives.

    ``results`` are what the report shows, in order (the run's description, every metric's
    result, the timing); ``report`` is ``report.json``. A benchmark run also has its ground
    truth: ``records`` are the evaluated frames in dataset order (skipped ones are listed in
    ``report["skipped"]``) and ``dataset.samples[record.index]`` is a record's ground truth;
    a run without a dataset (``tsrkit track``) has no records.
    ``failures`` collects the plugins that failed while the run was written (a plot that
    cannot be drawn, a writer that raised); :func:`tsrkit.reporting.runfolder.write_run` puts them
    in
    the report.
    """

    report: dict[str, Any]
    dataset: Dataset | None = None
    settings: EvalSettings | None = None
    records: tuple[FrameRecord, ...] = ()
    results: tuple[MetricResult, ...] = ()
    failures: list[Failure] = field(default_factory=list, compare=False)
    drawn: DrawnPlots = field(default_factory=lambda: DrawnPlots(), compare=False, repr=False)

    def pairs(self) -> Iterator[tuple[Sample, FrameRecord]]:
        """``(sample, record)`` of every evaluated frame (none without a dataset)."""
        samples = self.dataset.samples if self.dataset is not None else ()
        return ((samples[r.index], r) for r in self.records)

    def headline(self) -> list[Figure]:
        """Every result's headline figures, in order."""
        return [figure for result in self.results for figure in result.headline()]

    def remarks(self) -> list[str]:
        """Every result's remarks, in order, each once (two metrics may say the same)."""
        return list(dict.fromkeys(r for result in self.results for r in result.remarks()))

    def plot_images(self) -> dict[str, bytes]:
        """Every result's plots as PNG bytes, by file name, drawn once; a plot that cannot be
        drawn is left out and added to :attr:`failures`."""
        if self.drawn.images is None:
            images: dict[str, bytes] = {}
            for result in self.results:
                for plot in result.plots():
                    try:
                        images.setdefault(plot.name, plot.png())
                    except Exception as exc:
                        where = f"plot '{plot.name}' of '{result.metric}'"
                        self.failures.append(Failure.of(where, exc))
            self.drawn.images = images
        return self.drawn.images

    def captions(self) -> dict[str, str]:
        """Every plot's caption, by file name."""
        return {p.name: p.caption for r in self.results for p in r.plots()}


@dataclass
class DrawnPlots:
    """The plots of a run once drawn (shared by the writers that show them)."""

    images: dict[str, bytes] | None = None


def run_results(report: Mapping[str, Any]) -> tuple[MetricResult, ...]:
    """The results a benchmark report shows, rebuilt from it alone (``tsrkit report``, tables
    of several reports): the run's facts, each metric's result of the class its registered
    metric declares (the generic one when that metric is no longer installed), the timing and
    skipped inputs, in their display order."""
    facts = run_facts(report)
    results = []
    written = report["metrics"] if "metrics" in report else legacy_metrics(report)
    for name, entries in written.items():
        try:
            cls = get_registry().get("metric", name).cls
        except PluginNotFound:
            cls = Metric
        kind = cls.result_type if issubclass(cls, Metric) else MetricResult
        sections: dict[str, Any] = {}
        for entry in entries:
            section, _, key = entry.partition(".")
            if key:
                sections.setdefault(section, {})[key] = report[section][key]
            else:
                sections[section] = report[section]
        results.append(kind(sections, name))
    return ordered([*facts, *results])


#: The entries of the built-in metrics in a report written before reports listed them
#: (``metrics``); a renderer reads only the keys of its own metric.
LEGACY_METRICS = {
    "per-frame": ("per_frame", "intervals"),
    "iou-overlap": ("iou50", "iou"),
    "coco-ap": ("iou50",),
    "state": ("state",),
    "categories": ("categories",),
    "frame-notes": ("frame_notes",),
}


def legacy_metrics(report: Mapping[str, Any]) -> dict[str, list[str]]:
    """The ``metrics`` entry of a report written before reports had one."""
    return {name: [s for s in sections if s in report] for name, sections in LEGACY_METRICS.items()}


def ordered(results: Iterable[MetricResult]) -> tuple[MetricResult, ...]:
    """``results`` in display order: by ``order``, then as given."""
    return tuple(sorted(results, key=lambda r: r.order))


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
    metrics: Mapping[str, Sequence[str]] | None = None,
    failures: Sequence[Failure] = (),
) -> dict[str, Any]:
    """``report.json``: the run's description, the metrics' sections, timing and outputs.

    Parameters
    ----------
    plugins : mapping
        ``{"detector": identity, "classifier": identity[, "verifier": identity]}`` (identities
        from :func:`tsrkit.runner.engine.plugin_identity`, None for a missing stage).
    sections : mapping
        The merged metric sections (:meth:`tsrkit.eval.guard.GuardedMetrics.compute`).
    files : sequence of str
        Every file the writers write; those under ``plots/`` are listed as ``plots``.
    notes : sequence of str
        Caveats a reader must see (e.g. a dataset that is not exhaustively labelled).
    metrics : mapping, optional
        Which entries of the report each metric wrote (``metrics``: how :func:`run_results`
        rebuilds their results).
    failures : sequence of Failure
        Plugins that failed and were left out (``failures``, and one note each).
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
            "opened_as": dataset.info.get("opened_as"),
        },
        **dict(plugins.items()),
        "params": {kind: identity["params"] for kind, identity in plugins.items() if identity},
        "versions": versions(),
        "evaluated_box": settings.box if settings.detection else None,
        "frames": frames,
        **sections,
        "timing": dict(timing),
        "skipped": list(skipped),
        "metrics": {name: list(entries) for name, entries in (metrics or {}).items()},
    }
    return with_outputs(report, files, notes, failures)


def with_outputs(
    report: Mapping[str, Any],
    files: Sequence[str],
    notes: Sequence[str] = (),
    failures: Sequence[Failure] = (),
) -> dict[str, Any]:
    """``report`` with the run folder's files (``plots``: those under ``plots/``; ``files``: the
    others), its ``notes`` and one more note per failure (and the ``failures``)."""
    out = {
        **report,
        "plots": [f for f in files if f.startswith("plots/")],
        "files": sorted(f for f in files if not f.startswith("plots/")),
    }
    notes = [*notes, *(f.note for f in failures)]
    if notes:
        out["notes"] = notes
    if failures:
        out["failures"] = [f.to_json() for f in failures]
    return out


def headline(report: Mapping[str, Any]) -> dict[str, str]:
    """The headline figures of a report, formatted, by label."""
    results = run_results(report)
    return {f.label: f.text for r in results for f in r.headline()}


def headline_rows(reports: Sequence[Mapping[str, Any]]) -> tuple[list[Figure], list[list[str]]]:
    """A table of several reports' headline figures: the columns (every figure any report has,
    in order of first appearance) and one row of formatted values per report ("-" where a
    report lacks a figure)."""
    figures = [{f.key: f for r in run_results(report) for f in r.headline()} for report in reports]
    columns: dict[str, Figure] = {}
    for row in figures:
        for key, figure in row.items():
            columns.setdefault(key, figure)
    rows = [[row[k].text if k in row else "-" for k in columns] for row in figures]
    return list(columns.values()), rows


def headline_table(figures: Sequence[Figure]) -> tuple[list[str], list[list[str]]]:
    """One run's headline figures as a table: figure, value and, when any figure has one, its
    95 % interval."""
    if any(f.interval for f in figures):
        return ["figure", "value", "95 % interval"], [
            [f.label, f.text, f.interval_text] for f in figures
        ]
    return ["figure", "value"], [[f.label, f.text] for f in figures]


def title(report: Mapping[str, Any]) -> str:
    """``detector + verifier + classifier`` as a run's name (a track run's plugins are under
    ``plugins``)."""
    plugins = report.get("plugins") or report
    stages = (plugins.get("detector"), plugins.get("verifier"), plugins.get("classifier"))
    return " + ".join(p["name"] for p in stages if p)


def heading(report: Mapping[str, Any]) -> str:
    """A run's heading: ``METHOD on DATASET`` (on ``VIDEO`` for a track run)."""
    subject = (report.get("dataset") or {}).get("name") or report.get("video") or "-"
    return f"{title(report) or '-'} on {subject}"


def markdown_cell(text: str) -> str:
    """``text`` safe in a Markdown table cell (pipes escaped, lines joined)."""
    return " ".join(str(text).split()).replace("|", "\\|")


def markdown_table(header: Sequence[str], rows: Iterable[Sequence[str]]) -> str:
    """A GitHub Markdown table."""
    lines = [
        "| " + " | ".join(markdown_cell(h) for h in header) + " |",
        "|" + "---|" * len(header),
    ]
    lines += ["| " + " | ".join(markdown_cell(c) for c in row) + " |" for row in rows]
    return "\n".join(lines)


def figure_notes(figures: Sequence[Figure]) -> str:
    """What the figures are, grouped: ``recall, prec., hit: Zheng 5.2.1 per-frame means; ...``."""
    groups: dict[str, list[str]] = {}
    for figure in figures:
        if figure.about:
            groups.setdefault(figure.about, []).append(figure.label)
    return "; ".join(f"{', '.join(labels)}: {about}" for about, labels in groups.items())


def report_table(reports: list[dict]) -> Table:
    """A rich table of the headline figures, one row per run."""
    columns, rows = headline_rows(reports)
    table = Table(
        title=f"tsrkit benchmark: {reports[0]['dataset']['name']} ({reports[0]['frames']} frames)",
        box=box.SIMPLE_HEAD,
        pad_edge=False,
        caption=figure_notes(columns) or None,
    )
    table.add_column("method", overflow="fold")
    for figure in columns:
        table.add_column(figure.label, justify="right", min_width=5, no_wrap=True)
    table.add_column("skip", justify="right")
    for report, row in zip(reports, rows):
        table.add_row(title(report), *row, str(len(report["skipped"])))
    return table


def print_table(reports: list[dict], file=None) -> None:
    """Print the headline table to stdout (or ``file``), and the plugins that failed."""
    console = Console(file=file or sys.stdout)
    console.print(report_table(reports))
    for report in reports:
        for failure in report.get("failures", []):
            console.print(f"note: {failure['plugin']} failed and was left out", markup=False)
