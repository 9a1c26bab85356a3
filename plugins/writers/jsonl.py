"""Report writer ``jsonl``: ``detections.jsonl``, one ``tsrkit detect`` record per evaluated frame
(plus its lighting), in dataset order; a number that is not finite is written as null (JSON has
no NaN)."""

from __future__ import annotations

from pathlib import Path

from tsrkit.api import ReportWriter, RunResult, atomic_open, hookimpl, json_line


class JsonLines(ReportWriter):
    name = "jsonl"
    summary = "detections.jsonl: the per-frame records (detect's JSON Lines form)"

    def files(self, run: RunResult) -> list[str]:
        return ["detections.jsonl"] if run.dataset is not None else []

    def write(self, run: RunResult, folder: Path) -> None:
        with atomic_open(folder / "detections.jsonl") as fh:
            for record in run.records:
                fh.write(json_line(record.to_json()) + "\n")


@hookimpl
def register_report_writers(register):
    register(JsonLines)
