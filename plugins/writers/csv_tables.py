"""Report writer ``csv``: the headline figures of every result (``headline.csv``, one row, a
column per figure named by where it is in ``report.json``) and, for a benchmark, one row per
evaluated frame (``frames.csv``: size, time, lighting, counts, Zheng 5.2.1 recall/precision)."""

from __future__ import annotations

import csv
from pathlib import Path

from tsrkit.api import ReportWriter, RunResult, atomic_open, frame_score, hookimpl, title

FRAME_COLUMNS = (
    "frame",
    "source",
    "width",
    "height",
    "ms",
    "lighting",
    "detections",
    "ground_truth",
    "recall",
    "precision",
)


class CsvTables(ReportWriter):
    name = "csv"
    summary = "headline.csv (the headline figures) and frames.csv (one row per frame)"

    def files(self, run: RunResult) -> list[str]:
        return ["frames.csv", "headline.csv"] if run.dataset is not None else ["headline.csv"]

    def write(self, run: RunResult, folder: Path) -> None:
        report, figures = run.report, run.headline()
        with atomic_open(folder / "headline.csv") as fh:
            out = csv.writer(fh)
            out.writerow(["method", "frames", "skipped"] + [f.key for f in figures])
            out.writerow(
                [title(report), report.get("frames"), len(report.get("skipped", []))]
                + [_blank(f.value) for f in figures]
            )
        if run.dataset is None or run.settings is None:
            return
        with atomic_open(folder / "frames.csv") as fh:
            out = csv.writer(fh)
            out.writerow(FRAME_COLUMNS)
            for sample, record in run.pairs():
                score = frame_score(sample, record)
                out.writerow(
                    [
                        record.index,
                        record.source,
                        record.width,
                        record.height,
                        record.ms,
                        record.lighting,
                        score.n_det,
                        score.n_gt,
                        _blank(score.recall),
                        _blank(run.settings.false_positive_figure(score.precision)),
                    ]
                )


def _blank(value):
    return "" if value is None else value


@hookimpl
def register_report_writers(register):
    register(CsvTables)
