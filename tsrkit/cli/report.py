"""``tsrkit report RUN_DIR``: the report writers run again on a finished run (or a compare
folder) from the files it left, without recomputing anything."""

from __future__ import annotations

from pathlib import Path

import click

from tsrkit.cli.completion import plugin_names

__all__ = ["report_command"]


@click.command("report")
@click.argument("run_dir", type=click.Path(exists=True, file_okay=False))
@click.option(
    "--writer",
    "writers",
    multiple=True,
    default=("html",),
    show_default=True,
    shell_complete=plugin_names("writer"),
    help="Report writer to run (repeatable).",
)
def report_command(run_dir, writers) -> None:
    """Write RUN_DIR/report.html (a benchmark folder) or RUN_DIR/compare.html (a compare
    folder) from the files the run left, without recomputing.

    \b
    Examples:
      tsrkit report tsrkit-out/conspicuity     # one benchmark run: report.html
      tsrkit report tsrkit-out                 # a compare folder: compare.html
      tsrkit report runs/kr --writer markdown --writer html
    """
    from tsrkit.registry import get_registry
    from tsrkit.report import load_run

    folder = Path(run_dir)
    chosen = [get_registry().create("writer", name) for name in writers]
    if (folder / "compare.json").is_file():
        written = [name for writer in chosen for name in writer.write_comparison(folder)]
    else:
        run = load_run(folder)
        for writer in chosen:
            writer.write(run, folder)
        written = [name for writer in chosen for name in writer.files(run)]
    for name in written:
        click.echo(f"-> {folder / name}")
