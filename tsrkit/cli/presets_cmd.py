"""``tsrkit presets``: the named run configurations shipped with tsrkit (``--config NAME``)."""

from __future__ import annotations

import click
from rich.console import Console
from rich.table import Table

from tsrkit.cli.completion import preset_names_only
from tsrkit.plugin.presets import describe, preset_names, preset_path

__all__ = ["presets_command"]


@click.command("presets")
@click.option(
    "--show",
    "show",
    default=None,
    metavar="NAME",
    help="Print the preset's YAML.",
    shell_complete=preset_names_only,
)
def presets_command(show: str | None) -> None:
    """List the shipped presets; use one with --config NAME on detect, benchmark or compare.

    \b
    Examples:
      tsrkit presets
      tsrkit presets --show recommended > my-run.yaml
      tsrkit detect frames/ --config recommended
    """
    if show is not None:
        click.echo(preset_path(show).read_text(encoding="utf-8"), nl=False)
        return
    table = Table(title="tsrkit presets (--config NAME)")
    table.add_column("name")
    table.add_column("description")
    for name in preset_names():
        table.add_row(name, describe(name))
    Console().print(table)
