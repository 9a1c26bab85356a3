"""``tsrkit benchmark`` and ``tsrkit compare``: evaluate methods on a dataset, side by side.

Both stream the frames through the runner (:mod:`tsrkit.runner`), print a rich table on stdout
and write report.json, summary.md, COCO files and plots to ``--out``. Bare ``tsrkit`` runs
``run_default``: the three built-in detectors compared on the bundled synthetic sample.
"""
from __future__ import annotations

import os
from collections.abc import Sequence

import click

from tsrkit.cli.common import UserError, plugin_options, route_params, selected_plugins
from tsrkit.params import load_config, parse_assignments
from tsrkit.registry import get_registry
from tsrkit.report import print_table

DEFAULT_OUT = "tsrkit-out"
DEFAULT_COMPARE = ("conspicuity", "gray-tophat", "lab-frst")


def dataset_options(func):
    """``--dataset``, ``--format``, ``--images`` and ``--split``."""
    options = [
        click.option("--dataset", "dataset_ref", default="sample", show_default=True,
                     help="Registry name, path, or 'sample' (the bundled synthetic sample)."),
        click.option("--format", "format_name", default=None,
                     help="Dataset format when the path is ambiguous."),
        click.option("--images", default=None, type=click.Path(file_okay=False),
                     help="Root that image paths inside the annotation file resolve against."),
        click.option("--split", default=None, help="Use only this split (e.g. test)."),
    ]
    for option in reversed(options):
        func = option(func)
    return func


def run_options(func):
    """``--workers``, ``--engine``, ``--scheduler``, ``--out``, ``--no-cache``, ``--iou``."""
    options = [
        click.option("--workers", "-w", type=click.IntRange(min=1), default=None,
                     help="Worker processes (default: all cores)."),
        click.option("--engine", type=click.Choice(["local", "dask"]), default="local",
                     show_default=True, help="Process pool on this machine, or Dask."),
        click.option("--scheduler", default=None,
                     help="Dask scheduler address (default: a LocalCluster)."),
        click.option("--out", "-o", type=click.Path(file_okay=False), default=DEFAULT_OUT,
                     show_default=True, help="Output folder."),
        click.option("--no-cache", is_flag=True, help="Recompute every frame."),
        click.option("--iou", "iou_threshold", type=click.FloatRange(0, 1, max_open=True),
                     default=0.5, show_default=True,
                     help="IoU threshold of the report's 'iou' section (Lee 3.6.2)."),
        click.option("--quiet", "-q", is_flag=True, help="No progress bar."),
    ]
    for option in reversed(options):
        func = option(func)
    return func


def load_dataset(ref: str, format_name: str | None, images: str | None, split: str | None):
    """Open the dataset and keep one split if asked."""
    from tsrkit.datasets import open_dataset

    dataset = open_dataset(ref, format=format_name, images=images)
    if split:
        dataset = dataset.split(split)
        if not len(dataset):
            raise UserError(f"dataset '{ref}' has no samples in split '{split}'")
    return dataset


def build_plugins(detector: str | None, classifier: str | None, params: Sequence[str],
                  config_path: str | None, verifier: str | None = None):
    """The detector (None for a classifier-only run on crops), classifier and verifier."""
    config = load_config(config_path) if config_path else None
    chosen = selected_plugins(detector, classifier, None, config, verifier)
    if classifier and not detector and not (config or {}).get("detector"):
        del chosen["detector"]
    registry = get_registry()
    for kind, name in chosen.items():
        registry.get(kind, name)
    routed = route_params(chosen, params, config)
    plugins = {kind: registry.create(kind, name, routed[kind]) for kind, name in chosen.items()}
    return plugins.get("detector"), plugins.get("classifier"), plugins.get("verifier")


def _run_kwargs(workers, engine, scheduler, no_cache, iou_threshold, quiet) -> dict:
    return {"workers": workers or os.cpu_count() or 1, "engine": engine,
            "scheduler": scheduler, "cache": not no_cache, "iou_threshold": iou_threshold,
            "progress": not quiet}


@click.command("benchmark")
@dataset_options
@plugin_options
@run_options
def benchmark_command(dataset_ref, format_name, images, split, detector, verifier, classifier,
                      tracker, params, config, workers, engine, scheduler, out, no_cache, iou_threshold,
                      quiet) -> None:
    """Run a detector (and classifier) over a dataset and write an evaluated report.

    With --classifier alone, classifies the ground-truth boxes (crop datasets) and reports
    accuracy, per-class figures and the confusion matrix. Writes OUT/report.json, summary.md,
    detections.jsonl, detections.coco.json, ground_truth.coco.json and plots/.
    """
    from tsrkit.runner import benchmark

    if tracker:
        raise UserError("benchmark evaluates frames independently; --tracker is not supported")
    det, cls, ver = build_plugins(detector, classifier, params, config, verifier)
    dataset = load_dataset(dataset_ref, format_name, images, split)
    report = benchmark(dataset, det, cls, out=out, verifier=ver,
                       **_run_kwargs(workers, engine, scheduler, no_cache, iou_threshold, quiet))
    print_table([report])
    click.echo(f"report: {os.path.join(out, 'report.json')}", err=True)


@click.command("compare")
@dataset_options
@click.option("--detectors", "detector_names", default=",".join(DEFAULT_COMPARE),
              show_default=True, help="Comma-separated detector plugins.")
@click.option("--classifier", "-c", default=None, help="Classifier plugin for every run.")
@click.option("--param", "-p", "params", multiple=True, metavar="NAME.KEY=VALUE",
              help="Parameter for one detector (prefix with its name) or classifier.KEY=VALUE.")
@run_options
def compare_command(dataset_ref, format_name, images, split, detector_names, classifier, params,
                    workers, engine, scheduler, out, no_cache, iou_threshold, quiet) -> None:
    """Benchmark several detectors on the same frames; one report side by side.

    Writes OUT/<detector>/ for each run plus OUT/compare.json and OUT/compare.md with a paired
    test (Wilcoxon signed-rank on per-frame recall) for every pair.
    """
    run_compare(dataset_ref, format_name, images, split, detector_names, classifier, params,
                out, _run_kwargs(workers, engine, scheduler, no_cache, iou_threshold, quiet))


def run_compare(dataset_ref, format_name, images, split, detector_names: str,
                classifier: str | None, params: Sequence[str], out: str, options: dict) -> None:
    """Build every detector, compare them, print the table and the paired verdicts."""
    from tsrkit.runner import compare

    registry = get_registry()
    names = [n.strip() for n in detector_names.split(",") if n.strip()]
    detectors = [registry.create("detector", name, parse_assignments(_params_for(name, params)))
                 for name in names]
    cls = (registry.create("classifier", classifier,
                           parse_assignments(_params_for("classifier", params)))
           if classifier else None)
    dataset = load_dataset(dataset_ref, format_name, images, split)
    comparison = compare(dataset, detectors, cls, out=out, **options)
    print_table(comparison["reports"])
    for test in comparison["paired_tests"]:
        click.echo(f"{test['a']} vs {test['b']}: {test['verdict']} "
                   f"(p = {test['p_value']:.3g}, {test['frames']} frames)")
    click.echo(f"report: {os.path.join(out, 'compare.md')}", err=True)


def _params_for(prefix: str, params: Sequence[str]) -> list[str]:
    """The ``prefix.key=value`` assignments with the prefix removed."""
    return [p.split(".", 1)[1] for p in params if p.startswith(prefix + ".")]


@click.command("default", hidden=True)
def run_default() -> None:
    """Compare the built-in detectors on the bundled sample, writing to ./tsrkit-out."""
    run_compare("sample", None, None, None, ",".join(DEFAULT_COMPARE), None, (), DEFAULT_OUT,
                {"workers": os.cpu_count() or 1, "progress": True})


COMMANDS = [benchmark_command, compare_command]
