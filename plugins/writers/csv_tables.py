"""Report writer ``csv``: the headline figures (``headline.csv``, one row) and one row per
evaluated frame (``frames.csv``: size, time, lighting, counts, Zheng 5.2.1 recall/precision)."""

from __future__ import annotations

import csv
from pathlib import Path

from tsrkit.api import HEADLINE, ReportWriter, RunResult, atomic_open, frame_score, hookimpl, title

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
        return ["frames.csv", "headline.csv"]

    def write(self, run: RunResult, folder: Path) -> None:
        report = run.report
        with atomic_open(folder / "headline.csv") as fh:
            out = csv.writer(fh)
            out.writerow(["method", "frames", "skipped"] + [f"{s}.{k}" for s, k, _, _ in HEADLINE])
            out.writerow(
                [title(report), report["frames"], len(report["skipped"])]
                + [_blank((report.get(s) or {}).get(k)) for s, k, _, _ in HEADLINE]
            )
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
