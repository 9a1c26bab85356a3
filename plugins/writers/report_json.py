"""Report writer ``json``: the run's ``report.json`` (the report dict, exactly as returned)."""

from __future__ import annotations

from pathlib import Path

from tsrkit.api import ReportWriter, RunResult, hookimpl, write_json


class JsonReport(ReportWriter):
    name = "json"
    summary = "report.json: every metric section, the plugins, timing and skipped inputs"

    def files(self, run: RunResult) -> list[str]:
        return ["report.json"]

    def write(self, run: RunResult, folder: Path) -> None:
        write_json(folder / "report.json", run.report)


@hookimpl
def register_report_writers(register):
    register(JsonReport)
