"""``tsrkit report RUN_DIR``: the report writers run again on a finished run (or a compare
folder) from the files it left, without recomputing anything."""

from __future__ import annotations

from pathlib import Path

import click

from tsrkit.cli.completion import plugin_names
from tsrkit.cli.errors import UserError

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
    """Write RUN_DIR/report.html (a benchmark or `track VIDEO --out` folder) or
    RUN_DIR/compare.html (a compare folder) from the files the run left, without recomputing.

    \b
    Examples:
      tsrkit report tsrkit-out/conspicuity     # one benchmark run: report.html
      tsrkit report tsrkit-out                 # a compare folder: compare.html
      tsrkit report runs/drive                 # a track run: report.html
      tsrkit report runs/kr --writer markdown --writer html
    """
    # when the verb runs: ``tsrkit --help`` stays fast
    from tsrkit.eval.guard import Failure
    from tsrkit.plugin.registry import get_registry
    from tsrkit.reporting.runfolder import load_run, read_comparison

    folder = Path(run_dir)
    chosen = [get_registry().create("writer", name) for name in writers]
    failures: list[Failure] = []
    written: list[str] = []
    if (folder / "compare.json").exists():
        read_comparison(folder)  # one clear line when it is not a compare.json
        for writer in chosen:
            try:
                written += writer.write_comparison(folder)
            except Exception as exc:
                failures.append(Failure.of(f"writer '{writer.name}'", exc))
        if not written and not failures:
            names = ", ".join(w.name for w in chosen)
            raise UserError(
                f"{folder}: a compare folder; {names} write nothing for one (html does)"
            )
    else:
        run = load_run(folder)
        for writer in chosen:
            try:
                writer.write(run, folder)
                written += writer.files(run)
            except Exception as exc:
                failures.append(Failure.of(f"writer '{writer.name}'", exc))
        failures = [*run.failures, *failures]
    for name in written:
        click.echo(f"-> {folder / name}")
    for failure in failures:
        click.echo(f"error: {failure.note}", err=True)
    if failures:
        raise SystemExit(1)
