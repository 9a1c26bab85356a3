"""Report writer ``plots``: every result's plots as PNG files under ``plots/``, each drawn once per
run (:meth:`tsrkit.reporting.report.RunResult.plot_images`, shared with the HTML page)."""

from __future__ import annotations

from pathlib import Path

from tsrkit.api import ReportWriter, RunResult, atomic_open, hookimpl


class Plots(ReportWriter):
    name = "plots"
    summary = "plots/: every result's plots (PNG), e.g. Figure 5-1 bubbles, PR curve, confusion"

    def files(self, run: RunResult) -> list[str]:
        return [f"plots/{name}" for name in run.plot_images()]

    def write(self, run: RunResult, folder: Path) -> None:
        (folder / "plots").mkdir(parents=True, exist_ok=True)
        for name, png in run.plot_images().items():
            with atomic_open(folder / "plots" / name, "wb") as fh:
                fh.write(png)


@hookimpl
def register_report_writers(register):
    register(Plots)
