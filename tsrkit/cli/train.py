"""``tsrkit train``: fit a trainable plugin on a dataset and save its model."""

from __future__ import annotations

from contextlib import nullcontext

import click
from rich.console import Console

from tsrkit.cli.common import split_name
from tsrkit.cli.completion import dataset_names, plugin_names, trainable_names
from tsrkit.core.errors import TsrkitError
from tsrkit.core.outputs import reading, refuse_input, refuse_special
from tsrkit.datasets.concat import dataset_inputs
from tsrkit.plugin.models import model_paths
from tsrkit.plugin.params import parse_assignments
from tsrkit.plugin.registry import get_registry
from tsrkit.runner.outlock import locked_file
from tsrkit.runner.training import train

__all__ = ["train_command"]


@click.command("train")
@click.argument("plugin", shell_complete=trainable_names)
@click.option(
    "--dataset",
    "dataset_refs",
    required=True,
    multiple=True,
    metavar="NAME[:SPLIT]",
    shell_complete=dataset_names,
    help="Registry name or path of the training data, optionally with its split; repeatable "
    "(the datasets are concatenated).",
)
@click.option(
    "--format",
    "format_name",
    default=None,
    help="Dataset format when a path is ambiguous.",
    shell_complete=plugin_names("format"),
)
@click.option(
    "--images",
    default=None,
    type=click.Path(file_okay=False),
    help="Root that image paths inside the annotation file resolve against.",
)
@click.option(
    "--split",
    default=None,
    callback=split_name,
    help="Use only this split (e.g. train) of datasets given without one.",
)
@click.option(
    "--param",
    "-p",
    "params",
    multiple=True,
    metavar="KEY=VALUE",
    help="Plugin parameter; repeatable.",
)
@click.option(
    "--out",
    required=True,
    type=click.Path(dir_okay=False),
    help="Model path (writes MODEL.npz and MODEL.json).",
)
@click.option(
    "--detector",
    "-d",
    default=None,
    help="Detector whose candidates a trainable verifier learns on (its parameters: "
    "-p detector.KEY=VALUE).",
    shell_complete=plugin_names("detector"),
)
@click.option("--quiet", "-q", is_flag=True, help="No progress indicator.")
def train_command(
    plugin, dataset_refs, format_name, images, split, params, out, detector, quiet
) -> None:
    """Fit PLUGIN (a trainable detector, verifier or classifier) and save the model for
    --param model=.

    \b
    Examples:
      tsrkit train ab-hist --dataset udacity_mit_tl_crops:train --out models/ab
      tsrkit detect frames/ -c ab-hist -p model=models/ab.npz
      tsrkit train verifier --dataset roboflow_traffic_light_kr:valid -d lab-frst \\
          -p detector.top=15 --out models/verifier
    """
    # when the verb runs: ``tsrkit --help`` stays fast
    from tsrkit.datasets import open_datasets

    assignments = parse_assignments(params)
    detector_params = {
        k.removeprefix("detector."): v for k, v in assignments.items() if k.startswith("detector.")
    }
    own = {k: v for k, v in assignments.items() if not k.startswith("detector.")}
    if detector_params and not detector:
        raise click.UsageError("detector.KEY=VALUE parameters need --detector")
    det = get_registry().create("detector", detector, detector_params) if detector else None
    dataset = open_datasets(dataset_refs, split, format=format_name, images=images)
    if not len(dataset):
        click.echo(f"error: {', '.join(dataset_refs)}: no samples to train on", err=True)
        raise SystemExit(1)
    status = Console(stderr=True).status(
        f"training {plugin} on {len(dataset)} samples of {dataset.name}...", spinner="dots"
    )
    model = model_paths(out)
    for path in model:
        refuse_special(path, "--out")
    try:
        with reading(dataset_inputs(dataset_refs, dataset)), locked_file(model[0]):
            for path in model:
                refuse_input(path, "--out")
            with status if not quiet else nullcontext():
                path = train(plugin, dataset, out, own, det)
    except TsrkitError:
        raise
    except ValueError as exc:  # the data cannot train this plugin (a class without samples...)
        raise TsrkitError(f"cannot train {plugin} on {dataset.name}: {exc}") from None
    Console(stderr=True).print(
        f"trained {plugin} on {len(dataset)} samples of {dataset.name} -> {path}"
    )
