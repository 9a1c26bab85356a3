"""``tsrkit plugins``: what is installed, and what failed to load."""

from __future__ import annotations

import click
from rich.console import Console
from rich.table import Table

import tsrkit
from tsrkit.core.atomic import json_text
from tsrkit.plugin.registry import KINDS

__all__ = ["plugins_command"]


@click.command("plugins")
@click.option("--json", "as_json", is_flag=True, help="Print JSON (with parameter schemas).")
@click.option(
    "--kind", type=click.Choice(list(KINDS)), default=None, help="Only plugins of this kind."
)
def plugins_command(as_json: bool, kind: str | None) -> None:
    """List installed plugins: name, kind, package, version and summary.

    Plugins that failed to load are listed in red with the reason.

    \b
    Examples:
      tsrkit plugins
      tsrkit plugins --kind detector
      tsrkit plugins --json        # with every parameter's type, default, range and source
    """
    found = tsrkit.plugins(kind)
    if as_json:
        click.echo(json_text(found, indent=2))
        return
    table = Table(title="tsrkit plugins")
    for column in ("name", "kind", "package", "version", "summary"):
        table.add_column(column)
    for item in found:
        if item["kind"] == "failed":
            table.add_row(
                item["name"],
                "[red]failed[/red]",
                item["package"],
                "",
                f"[red]{item['error']}[/red]",
            )
        else:
            table.add_row(
                item["name"], item["kind"], item["package"], item["version"], item["summary"]
            )
    Console().print(table)
