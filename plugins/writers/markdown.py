"""Report writer ``markdown``: ``summary.md``, every result of the run as Markdown: the notes, the
headline figures with their 95 % intervals, the results' remarks and tables, and the plots the
run wrote with their captions."""

from __future__ import annotations

from pathlib import Path

from tsrkit.api import (
    ReportWriter,
    RunResult,
    atomic_open,
    heading,
    headline_table,
    hookimpl,
    markdown_table,
)


class MarkdownSummary(ReportWriter):
    name = "markdown"
    summary = "summary.md: notes, headline figures, every result's remarks and tables, plots"

    def files(self, run: RunResult) -> list[str]:
        return ["summary.md"]

    def write(self, run: RunResult, folder: Path) -> None:
        with atomic_open(folder / "summary.md") as fh:
            fh.write(summary_markdown(run))


def summary_markdown(run: RunResult) -> str:
    """The Markdown summary of ``run``."""
    report = run.report
    figures = run.headline()
    lines = [f"# {heading(report)}", ""]
    lines += [f"**Note:** {note}\n" for note in report.get("notes", [])]
    if figures:
        lines += [markdown_table(*headline_table(figures)), ""]
    lines += [f"{remark}\n" for remark in run.remarks()]
    for result in run.results:
        for table in result.tables():
            lines += [f"## {table.title}", "", markdown_table(table.columns, table.rows), ""]
            if table.caption:
                lines += [f"*{table.caption}*", ""]
    captions = run.captions()
    plots = [name for name in report.get("plots", []) if name.startswith("plots/")]
    if plots:
        lines += ["## Plots", ""]
        for name in plots:
            caption = captions.get(name.removeprefix("plots/"), "")
            lines += [f"![{name}]({name})", "", caption, ""]
    return "\n".join(lines)


@hookimpl
def register_report_writers(register):
    register(MarkdownSummary)
