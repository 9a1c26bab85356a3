"""``tsrkit benchmark`` and ``tsrkit compare``: evaluate methods on a dataset, side by side.

Both run :func:`tsrkit.reporting.benchmarking.benchmark` /
:func:`tsrkit.reporting.comparison.compare`, print a rich
table on stdout and let the report writers fill ``--out``. Bare ``tsrkit`` runs
``run_default``: the three built-in detectors compared on the bundled synthetic sample.
"""

from __future__ import annotations

import os
from collections.abc import Sequence

import click

from tsrkit.cli.common import FiniteFloatRange, plugin_options, split_name
from tsrkit.cli.completion import dataset_names, plugin_list, plugin_names, preset_or_file
from tsrkit.cli.errors import UserError
from tsrkit.core.outputs import reading
from tsrkit.datasets.concat import dataset_inputs
from tsrkit.eval.lighting import LIGHTING_SCHEMES
from tsrkit.eval.settings import BOX_OPTIONS
from tsrkit.plugin.selection import build, build_compare
from tsrkit.reporting.report import print_table

__all__ = [
    "DEFAULT_COMPARE",
    "DEFAULT_OUT",
    "benchmark_command",
    "compare_command",
    "dataset_options",
    "default_writers",
    "load_dataset",
    "run_compare",
    "run_default",
    "run_options",
]

DEFAULT_OUT = "tsrkit-out"
DEFAULT_COMPARE = ("conspicuity", "gray-tophat", "lab-frst")


def dataset_options(func):
    """``--dataset``, ``--format``, ``--images`` and ``--split``."""
    options = [
        click.option(
            "--dataset",
            "dataset_ref",
            default="sample",
            show_default=True,
            help="Registry name, path, or 'sample' (the bundled synthetic sample).",
            shell_complete=dataset_names,
        ),
        click.option(
            "--format",
            "format_name",
            default=None,
            help="Dataset format when the path is ambiguous.",
            shell_complete=plugin_names("format"),
        ),
        click.option(
            "--images",
            default=None,
            type=click.Path(file_okay=False),
            help="Root that image paths inside the annotation file resolve against.",
        ),
        click.option(
            "--split", default=None, callback=split_name, help="Use only this split (e.g. test)."
        ),
    ]
    for option in reversed(options):
        func = option(func)
    return func


def run_options(func):
    """``--workers``, ``--engine``, ``--scheduler``, ``--out``, ``--no-cache``, ``--iou``,
    ``--quiet``, ``--eval-box``, ``--writer``, ``--no-plots``, ``--lighting``."""
    options = [
        click.option(
            "--workers",
            "-w",
            type=click.IntRange(min=1),
            default=None,
            help="Worker processes (default: all cores).",
        ),
        click.option(
            "--engine",
            type=click.Choice(["local", "dask"]),
            default="local",
            show_default=True,
            help="Process pool on this machine, or Dask.",
        ),
        click.option(
            "--scheduler", default=None, help="Dask scheduler address (default: a LocalCluster)."
        ),
        click.option(
            "--out",
            "-o",
            type=click.Path(file_okay=False),
            default=DEFAULT_OUT,
            show_default=True,
            help="Output folder.",
        ),
        click.option("--no-cache", is_flag=True, help="Recompute every frame."),
        click.option(
            "--iou",
            "iou_threshold",
            type=FiniteFloatRange(0, 1, max_open=True),
            default=0.5,
            show_default=True,
            help="IoU threshold of the report's 'iou' section (Lee 3.6.2).",
        ),
        click.option("--quiet", "-q", is_flag=True, help="No progress bar."),
        click.option(
            "--eval-box",
            type=click.Choice(BOX_OPTIONS),
            default="auto",
            show_default=True,
            help="Box evaluated: the lens box, the housing (bbox), or auto (lens on "
            "lens-boxed datasets, else housing).",
        ),
        click.option(
            "--writer",
            "writers",
            multiple=True,
            metavar="NAME",
            help="Report writer to run (repeatable; default: every default writer).",
            shell_complete=plugin_names("writer"),
        ),
        click.option(
            "--no-plots",
            is_flag=True,
            help="Write no plot files (skips the plots writer; report.html still embeds them).",
        ),
        click.option(
            "--lighting",
            type=click.Choice(LIGHTING_SCHEMES),
            default=LIGHTING_SCHEMES[0],
            show_default=True,
            help="Lighting categories of the lighting x size table: Mascetti's four mean-V "
            "classes (Table 4) or Zheng's five conditions (Figure 4-2: sunny, cloudy, "
            "dawn_dusk, dark_lit, dark_unlit).",
        ),
    ]
    for option in reversed(options):
        func = option(func)
    return func


def load_dataset(ref: str, format_name: str | None, images: str | None, split: str | None):
    """Open the dataset and keep one split if asked; a dataset without a sample ends the run
    with exit status 1 (nothing found, as for ``detect``)."""
    # when the verb runs: ``tsrkit --help`` stays fast
    from tsrkit.datasets import open_dataset

    dataset = open_dataset(ref, format=format_name, images=images)
    if split:
        dataset = dataset.split(split)
        if not len(dataset):
            raise UserError(f"dataset '{ref}' has no samples in split '{split}'")
    if not len(dataset):
        click.echo(f"error: dataset '{ref}' has no samples", err=True)
        raise SystemExit(1)
    return dataset


def check_engine(engine: str, scheduler: str | None) -> None:
    """Refuse ``--scheduler`` without ``--engine dask`` (it would be ignored)."""
    if scheduler is not None and engine != "dask":
        raise UserError(f"--scheduler {scheduler} needs --engine dask")


def _run_kwargs(
    workers,
    engine,
    scheduler,
    no_cache,
    iou_threshold,
    quiet,
    eval_box,
    writers,
    no_plots,
    lighting,
) -> dict:
    if no_plots:
        writers = [name for name in writers or default_writers() if name != "plots"]
    return {
        "workers": workers or os.cpu_count() or 1,
        "engine": engine,
        "scheduler": scheduler,
        "cache": not no_cache,
        "iou_threshold": iou_threshold,
        "progress": not quiet,
        "box": eval_box,
        "writers": list(writers) or None,
        "lighting": lighting,
    }


def start_pool_early(workers: int | None, engine: str) -> None:
    """Start the worker pools' fork server before the plugins and the dataset are loaded, when
    the run will use a pool (:func:`tsrkit.runner.engine.start_pool_server`)."""
    if engine == "local" and (workers or os.cpu_count() or 1) > 1:
        # when the verb runs: ``tsrkit --help`` stays fast
        from tsrkit.runner.engine import start_pool_server

        start_pool_server()


def default_writers() -> list[str]:
    """The report writers that run when ``--writer`` is not given."""
    # when the verb runs: ``tsrkit --help`` stays fast
    from tsrkit.plugin.registry import get_registry

    return [i.name for i in get_registry().plugins("writer") if getattr(i.cls, "default", False)]


@click.command("benchmark")
@dataset_options
@plugin_options(tracker=False)
@run_options
def benchmark_command(
    dataset_ref,
    format_name,
    images,
    split,
    detector,
    verifier,
    classifier,
    params,
    config,
    workers,
    engine,
    scheduler,
    out,
    no_cache,
    iou_threshold,
    quiet,
    eval_box,
    writers,
    no_plots,
    lighting,
) -> None:
    """Run a detector (and classifier) over a dataset and write an evaluated report.

    With --classifier alone, classifies the ground-truth boxes (crop datasets) and reports
    accuracy, per-class figures and the confusion matrix. The report writers write
    OUT/report.json, summary.md, detections.jsonl, the COCO files, CSV tables (headline.csv,
    frames.csv) and plots/. Frames are evaluated independently (no --tracker).

    \b
    Examples:
      tsrkit benchmark                                   # conspicuity on the bundled sample
      tsrkit benchmark --dataset roboflow_traffic_light_kr --split test -d lab-frst -o out/kr
      tsrkit benchmark --dataset gtsrb_test_35px_subset -c logpolar-svm   # classifier alone
      tsrkit benchmark --dataset frames/coco.json --images frames/ --config recommended
    """
    # when the verb runs: ``tsrkit --help`` stays fast
    from tsrkit.reporting.benchmarking import benchmark

    check_engine(engine, scheduler)
    start_pool_early(workers, engine)
    chosen = build(
        detector,
        verifier,
        classifier,
        None,
        params,
        config,
        classifier_alone=True,
        with_tracker=False,
    )
    dataset = load_dataset(dataset_ref, format_name, images, split)
    with reading(dataset_inputs([dataset_ref], dataset)):
        report = benchmark(
            dataset,
            chosen.detector,
            chosen.classifier,
            out=out,
            verifier=chosen.verifier,
            **_run_kwargs(
                workers,
                engine,
                scheduler,
                no_cache,
                iou_threshold,
                quiet,
                eval_box,
                writers,
                no_plots,
                lighting,
            ),
        )
    print_table([report])
    for note in report.get("notes", []):
        click.echo(f"note: {note}", err=True)
    click.echo(f"report: {os.path.join(out, 'report.json')}", err=True)
    if report["frames"] == 0 and report["skipped"]:
        click.echo(f"error: all {len(report['skipped'])} inputs were skipped", err=True)
        raise SystemExit(1)


@click.command("compare")
@dataset_options
@click.option(
    "--detectors",
    "detector_names",
    default=",".join(DEFAULT_COMPARE),
    show_default=True,
    help="Comma-separated detector plugins.",
    shell_complete=plugin_list("detector"),
)
@click.option(
    "--verifier",
    "-V",
    default=None,
    help="Verifier plugin for every run.",
    shell_complete=plugin_names("verifier"),
)
@click.option(
    "--without-verifier",
    is_flag=True,
    help="Also run every detector without the verifier (paired tests show what it adds).",
)
@click.option(
    "--classifier",
    "-c",
    default=None,
    help="Classifier plugin for every run.",
    shell_complete=plugin_names("classifier"),
)
@click.option(
    "--param",
    "-p",
    "params",
    multiple=True,
    metavar="NAME.KEY=VALUE",
    help="Parameter for one detector (prefix with its name), for classifier. or "
    "verifier.; unprefixed, for every chosen plugin that declares the key.",
)
@click.option(
    "--config",
    type=click.Path(dir_okay=False),
    default=None,
    help="YAML run configuration or preset name (tsrkit presets): its verifier, classifier "
    "and their params.",
    shell_complete=preset_or_file,
)
@click.option(
    "--configs",
    default=None,
    help="Comma-separated run configurations or presets, each a whole pipeline (detector, "
    "verifier, classifier) run side by side instead of --detectors (e.g. "
    "recommended,recommended-forest); -p parameters go to each.",
    shell_complete=preset_or_file,
)
@click.option(
    "--html",
    is_flag=True,
    help="Also write OUT/compare.html (as `tsrkit report OUT` does).",
)
@run_options
@click.pass_context
def compare_command(
    ctx,
    dataset_ref,
    format_name,
    images,
    split,
    detector_names,
    verifier,
    without_verifier,
    classifier,
    params,
    config,
    workers,
    engine,
    scheduler,
    out,
    no_cache,
    iou_threshold,
    quiet,
    eval_box,
    writers,
    no_plots,
    lighting,
    configs,
    html,
) -> None:
    """Benchmark several detectors (or whole pipelines: --configs) on the same frames; one
    report side by side.

    Writes OUT/<run>/ for each run plus OUT/compare.json and OUT/compare.md with a paired
    test (Wilcoxon signed-rank on per-frame recall) for every pair and each run's AP50 on the
    lens box and on the housing box.

    \b
    Examples:
      tsrkit compare                                   # the three built-ins on the sample
      tsrkit compare --dataset roboflow_cinta_v2_id --split test --detectors lab-frst,gray-tophat
      tsrkit compare --config recommended --without-verifier --html -o out/verifier
      tsrkit compare -p conspicuity.weights=1,1,2 -p gray-tophat.h_peak=0.8
      tsrkit compare --dataset roboflow_cinta_v2_id --configs recommended,recommended-forest
    """
    check_engine(engine, scheduler)
    options = {
        "detector_names": "--detectors",
        "verifier": "--verifier",
        "classifier": "--classifier",
        "config": "--config",
        "without_verifier": "--without-verifier",
    }
    given = [
        flag
        for name, flag in options.items()
        if ctx.get_parameter_source(name) != click.core.ParameterSource.DEFAULT
    ]
    if configs is not None and given:
        raise click.UsageError(f"--configs names whole pipelines; {given[0]} goes with it")
    start_pool_early(workers, engine)
    run = _run_kwargs(
        workers,
        engine,
        scheduler,
        no_cache,
        iou_threshold,
        quiet,
        eval_box,
        writers,
        no_plots,
        lighting,
    )
    if configs is not None:
        compare_configs(dataset_ref, format_name, images, split, configs, params, out, run)
    else:
        run_compare(
            dataset_ref,
            format_name,
            images,
            split,
            detector_names,
            classifier,
            params,
            out,
            run,
            verifier,
            config=config,
            without_verifier=without_verifier,
        )
    if html:
        # when the verb runs: ``tsrkit --help`` stays fast
        from tsrkit.cli.report import report_command

        ctx.invoke(report_command, run_dir=out)


def run_compare(
    dataset_ref,
    format_name,
    images,
    split,
    detector_names: str,
    classifier: str | None,
    params: Sequence[str],
    out: str,
    options: dict,
    verifier: str | None = None,
    config: str | None = None,
    without_verifier: bool = False,
) -> None:
    """Build every detector, compare them, print the table and the paired verdicts."""
    # when the verb runs: ``tsrkit --help`` stays fast
    from tsrkit.reporting.comparison import compare

    names = [n.strip() for n in detector_names.split(",") if n.strip()]
    if not names:
        raise UserError(
            f"--detectors {detector_names!r} names no detector (e.g. lab-frst,conspicuity)"
        )
    runs = build_compare(names, classifier, verifier, params, config)
    if without_verifier and runs[0].verifier is None:
        raise click.UsageError("--without-verifier needs a verifier (--verifier or --config)")
    dataset = load_dataset(dataset_ref, format_name, images, split)
    detectors = [run.detector for run in runs if run.detector is not None]
    with reading(dataset_inputs([dataset_ref], dataset)):
        comparison = compare(
            dataset,
            detectors,
            runs[0].classifier,
            out=out,
            verifier=runs[0].verifier,
            without_verifier=without_verifier,
            **options,
        )
    print_verdicts(comparison, out)


def compare_configs(
    dataset_ref,
    format_name,
    images,
    split,
    configs: str,
    params: Sequence[str],
    out: str,
    options: dict,
) -> None:
    """Run each configuration's whole pipeline, compare them, print the table and the paired
    verdicts."""
    from pathlib import Path

    from tsrkit.reporting.comparison import compare_runs

    names = [n.strip() for n in configs.split(",") if n.strip()]
    if len(names) < 2:
        raise UserError(
            f"--configs {configs!r}: name at least two (e.g. recommended,recommended-forest)"
        )
    plan = []
    for name in names:
        chosen = build(params=params, config=name)
        if chosen.detector is None:
            raise UserError(f"--configs: {name} names no detector")
        plan.append((Path(name).stem, chosen.detector, chosen.verifier, chosen.classifier))
    dataset = load_dataset(dataset_ref, format_name, images, split)
    with reading(dataset_inputs([dataset_ref], dataset)):
        comparison = compare_runs(dataset, plan, out=out, **options)
    print_verdicts(comparison, out)


def print_verdicts(comparison: dict, out: str) -> None:
    """The side-by-side table, each paired test's verdict, and where the report is."""
    print_table(comparison["reports"])
    for test in comparison["paired_tests"] + comparison.get("verifier_tests", []):
        click.echo(
            f"{test['a']} vs {test['b']}, {test['metric']}: {test['verdict']} "
            f"(p = {test['p_value']:.3g}, {test['frames']} frames)"
        )
    click.echo(f"report: {os.path.join(out, 'compare.md')}", err=True)


@click.command("default", hidden=True)
def run_default() -> None:
    """Compare the built-in detectors on the bundled sample, writing to ./tsrkit-out."""
    run_compare(
        "sample",
        None,
        None,
        None,
        ",".join(DEFAULT_COMPARE),
        None,
        (),
        DEFAULT_OUT,
        {"workers": os.cpu_count() or 1, "progress": True},
    )
