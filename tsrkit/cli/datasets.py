"""``tsrkit datasets``: the registry in ``datasets.yaml`` — list, info, verify, convert."""

from __future__ import annotations

from collections import Counter
from contextlib import nullcontext
from pathlib import Path

import click
from rich.console import Console
from rich.table import Table

from tsrkit.cli.completion import dataset_names, plugin_names
from tsrkit.cli.drive import drive_command
from tsrkit.cli.synth import synth_command
from tsrkit.core.atomic import json_text
from tsrkit.core.errors import TsrkitError
from tsrkit.core.outputs import reading, refuse_input, refuse_special
from tsrkit.core.types import Dataset
from tsrkit.datasets import (
    DatasetError,
    load_registry,
    open_dataset,
    registry_path,
    verify_manifest,
    write_dataset,
)
from tsrkit.datasets.concat import dataset_inputs
from tsrkit.datasets.registry import GENERATED_SAMPLE
from tsrkit.runner.outlock import locked_file

__all__ = [
    "convert_command",
    "datasets_group",
    "info_command",
    "list_command",
    "state_changes",
    "verify_command",
]


@click.group("datasets")
def datasets_group() -> None:
    """The dataset registry (datasets.yaml): list, info NAME, verify NAME, convert SRC.

    \b
    Examples:
      tsrkit datasets list
      tsrkit datasets info roboflow_traffic_light_kr
      tsrkit datasets convert roboflow_traffic_light_kr --to yolo --out kr-yolo/
      tsrkit datasets synth --out synth/ --frames 100
      tsrkit datasets drive --out city/          # video, GPS log and map for tsrkit track
    """


@datasets_group.command("list")
@click.option("--json", "as_json", is_flag=True, help="Print JSON.")
def list_command(as_json: bool) -> None:
    """Registered datasets: name, format, task, box convention, licence, and whether present.

    \b
    Examples:
      tsrkit datasets list
      tsrkit datasets list --json
    """
    rows = []
    for entry in load_registry().values():
        rows.append({**entry.to_info(), "present": _present(entry)})
    if as_json:
        click.echo(json_text(rows, indent=2))
        return
    table = Table(title=f"tsrkit datasets ({registry_path()})")
    for column in ("name", "format", "task", "box", "licence", "present"):
        table.add_column(column)
    for row in rows:
        table.add_row(
            row["name"],
            row["format"],
            row["task"],
            row["box"],
            row["licence"],
            row["present"] if row["present"] != "no" else "[red]no[/red]",
        )
    Console().print(table)


@datasets_group.command("info")
@click.argument("name", shell_complete=dataset_names)
@click.option("--json", "as_json", is_flag=True, help="Print JSON.")
def info_command(name: str, as_json: bool) -> None:
    """Registry facts of NAME plus counts of samples, boxes, splits and states.

    NAME is a registered dataset, 'sample', or a path (format detected).

    \b
    Examples:
      tsrkit datasets info dtld_fridtjofs
      tsrkit datasets info my-export/coco.json --json
    """
    dataset = open_dataset(name)
    states = Counter(a.state for s in dataset for a in s.annotations)
    labels = Counter(a.attributes.get("label", a.state) for s in dataset for a in s.annotations)
    facts = {
        **dataset.info,
        "name": dataset.name,
        "format": dataset.format,
        "samples": len(dataset),
        "annotations": sum(states.values()),
        "splits": dict(Counter(s.split or "-" for s in dataset)),
        "states": dict(states.most_common()),
        "labels": dict(labels.most_common()),
    }
    if as_json:
        click.echo(json_text(facts, indent=2, default=str))
        return
    table = Table(title=f"dataset {dataset.name}", show_header=False)
    for key, value in facts.items():
        if value not in (None, "", [], {}):
            table.add_row(
                key,
                ", ".join(f"{k}: {v}" for k, v in value.items())
                if isinstance(value, dict)
                else str(value),
            )
    Console().print(table)


@datasets_group.command("verify")
@click.argument("name", shell_complete=dataset_names)
@click.pass_context
def verify_command(ctx: click.Context, name: str) -> None:
    """Check every file of NAME against its sha256 manifest; exit 1 if any is missing/altered.

    \b
    Examples:
      tsrkit datasets verify roboflow_traffic_light_kr
    """
    registry = load_registry()
    if name not in registry:
        raise TsrkitError(f"no registered dataset '{name}' (known: {', '.join(registry)})")
    entry = registry[name]
    if not entry.manifest:
        raise TsrkitError(f"dataset '{name}' has no checksum manifest to verify against")
    root = entry.annotation_path() if entry.path == "." else entry.root_path()
    result = verify_manifest(root, root / entry.manifest)
    for label, files in (("missing", result.missing), ("altered", result.altered)):
        for file in files:
            click.echo(f"{label}: {file}")
    summary = (
        f"{name}: {result.checked} files checked, {len(result.missing)} missing, "
        f"{len(result.altered)} altered, {len(result.unlisted)} not in the manifest"
    )
    click.echo(summary)
    if not result.ok:
        ctx.exit(1)


@datasets_group.command("convert")
@click.argument("src", shell_complete=dataset_names)
@click.option(
    "--to",
    "to_format",
    required=True,
    help="Format plugin to write (coco, normalized, voc, yolo).",
    shell_complete=plugin_names("format"),
)
@click.option(
    "--out",
    required=True,
    type=click.Path(path_type=Path),
    help="Output file (coco, normalized) or folder (yolo, voc).",
)
@click.option(
    "--format",
    "src_format",
    default=None,
    help="Format of SRC (detected when unambiguous).",
    shell_complete=plugin_names("format"),
)
@click.option(
    "--images",
    type=click.Path(path_type=Path),
    default=None,
    help="Folder that image paths in SRC resolve against.",
)
@click.option("--quiet", "-q", is_flag=True, help="No progress indicator.")
def convert_command(
    src: str, to_format: str, out: Path, src_format: str | None, images: Path | None, quiet: bool
) -> None:
    """Read SRC (registry name or path) and write it in another format at --out.

    The written files are read back: a state the target format cannot hold (a raw label
    that the source's states: mapping gave another state, e.g. KR's left arrows) is reported
    as a warning with the counts before and after.

    \b
    Examples:
      tsrkit datasets convert roboflow_traffic_light_kr --to coco --out kr.coco.json
      tsrkit datasets convert labels/ --format voc --images JPEGImages/ --to yolo --out yolo/
    """
    console = Console(stderr=True, soft_wrap=True)
    with console.status(f"converting {src} to {to_format}...") if not quiet else nullcontext():
        dataset = open_dataset(src, format=src_format, images=images)
        refuse_special(out, "--out")
        with reading(dataset_inputs([src], dataset)), locked_file(out):
            refuse_input(out, "--out")
            write_dataset(dataset, to_format, out)
        changes = state_changes(dataset, open_dataset(out, format=to_format))
    boxes = sum(len(s.annotations) for s in dataset)
    click.echo(f"wrote {len(dataset)} images, {boxes} boxes as {to_format} to {out}")
    if changes:
        console.print(
            f"warning: {to_format} cannot hold every state of {dataset.name}; read back, "
            + ", ".join(changes),
            markup=False,
        )


def state_changes(before: Dataset, after: Dataset) -> list[str]:
    """``"STATE n -> m"`` for each state whose box count differs between two datasets.

    Examples
    --------
    >>> from tsrkit.core.types import Annotation, Sample
    >>> def one(state):
    ...     return Dataset("d", (Sample("a.png", (Annotation((0, 0, 1, 1), state),)),))
    >>> state_changes(one("green"), one("unknown"))
    ['green 1 -> 0', 'unknown 0 -> 1']
    """
    counts = [Counter(a.state for s in d for a in s.annotations) for d in (before, after)]
    return [
        f"{state} {counts[0][state]} -> {counts[1][state]}"
        for state in sorted(set(counts[0]) | set(counts[1]))
        if counts[0][state] != counts[1][state]
    ]


def _present(entry) -> str:
    """``yes``, ``no`` or ``generated`` (made on first use), without generating anything."""
    if entry.root == GENERATED_SAMPLE:
        return "generated"
    try:
        return "yes" if entry.annotation_path().exists() else "no"
    except DatasetError:
        return "no"


datasets_group.add_command(synth_command)
datasets_group.add_command(drive_command)
