"""``benchmark``: run methods over a dataset with the engine, evaluate every record, write the run.

The data path is one line: the engine yields :class:`~tsrkit.core.records.FrameRecord` values, each
registered :class:`~tsrkit.plugin.base.Metric` folds them in,
:func:`tsrkit.reporting.report.build_report` turns
the metrics' sections into ``report.json`` once, and each :class:`~tsrkit.plugin.base.ReportWriter`
writes its files from the finished :class:`~tsrkit.reporting.report.RunResult`.

Memory: the engine streams frames, and images are never kept; the evaluated records are (a few
hundred bytes per detection), because the writers (JSON Lines, COCO, CSV, the HTML gallery) need
them after the metrics are computed.
"""

from __future__ import annotations

import contextlib
import dataclasses
import functools
import json
import os
import shutil
import tempfile
import time
from collections.abc import Iterable, Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from tsrkit.core.outputs import refuse_input
from tsrkit.core.records import FrameRecord
from tsrkit.core.types import Dataset, Sample
from tsrkit.eval.guard import Failure, GuardedMetrics
from tsrkit.eval.runfacts import run_facts
from tsrkit.eval.settings import EvalSettings, eval_settings, lighting_note, not_exhaustive_note
from tsrkit.plugin.base import Classifier, Detector, Verifier
from tsrkit.plugin.registry import get_registry
from tsrkit.reporting.report import REPORT_KEYS, ProgressBar, RunResult, build_report, ordered
from tsrkit.reporting.runfolder import (
    refuse_foreign_report,
    remove_stale_files,
    write_run,
    writers_for,
)
from tsrkit.runner.engine import (
    BenchmarkError,
    Job,
    default_cache_dir,
    plugin_identity,
    run_records,
)
from tsrkit.runner.outlock import locked

__all__ = [
    "benchmark",
    "eval_settings",
    "evaluate",
    "metrics_for",
    "run_benchmark",
    "writers_for",
]


def metrics_for(settings: EvalSettings) -> GuardedMetrics:
    """Every registered metric, reset for a new evaluation (one that fails is left out)."""
    registry = get_registry()
    return GuardedMetrics(
        {
            info.name: functools.partial(registry.create, "metric", info.name)
            for info in registry.plugins("metric")
        },
        settings,
    )


def evaluate(
    dataset: Dataset,
    records: Iterable[FrameRecord],
    settings: EvalSettings,
    plugins: Mapping[str, dict | None],
    *,
    out: str | os.PathLike | None = None,
    writers: Sequence[str] | None = None,
    run_info: Mapping[str, Any] | None = None,
) -> RunResult:
    """Fold records into every metric, build ``report.json`` and let the writers write ``out``.

    Parameters
    ----------
    dataset : Dataset
        The ground truth: ``dataset.samples[record.index]`` belongs to ``record``.
    records : iterable of FrameRecord
        Consumed once, in order (a stream from :func:`tsrkit.runner.engine.run_records`, or records
        read back from ``detections.jsonl``); skipped ones are listed in ``skipped``.
    settings : EvalSettings
    plugins : mapping
        The report's ``detector``, ``classifier`` (and ``verifier``) identities.
    out : path, optional
        Output folder; nothing is written when None.
    writers : sequence of str, optional
        Report writers by name (default: every writer registered as a default one).
    run_info : mapping, optional
        Extra ``timing`` keys (``workers``, ``engine``).
    """
    metrics = metrics_for(settings)
    kept: list[FrameRecord] = []
    skipped: list[dict[str, str]] = []
    resized: list[str] = []
    start = time.perf_counter()
    for record in records:
        if record.skipped is not None:
            skipped.append({"source": record.source, "reason": record.skipped})
            continue
        sample = dataset.samples[record.index]
        if (
            sample.width
            and sample.height
            and (sample.width, sample.height)
            != (
                record.width,
                record.height,
            )
        ):
            resized.append(
                f"{Path(sample.source).name} declares {sample.width}x{sample.height}, "
                f"the file is {record.width}x{record.height}"
            )
        metrics.update(sample, record)
        kept.append(record)
    wall = time.perf_counter() - start
    sections, results, written = metrics.compute(REPORT_KEYS)
    cached = sum(r.cached for r in kept)
    timing = {
        "ms_per_frame_median": float(np.median([r.ms for r in kept])) if kept else None,
        "frames_per_second": len(kept) / wall if wall > 0 else None,
        "wall_seconds": wall,
        **(run_info or {}),
        "frames_computed": len(kept) - cached,
        "frames_cached": cached,
    }
    notes = [] if settings.exhaustive else [not_exhaustive_note(dataset.name)]
    notes += lighting_note(settings)
    counted = sections.get("frame_notes", {}).get("counts", {})
    notes += [f"{n} of {len(kept)} frames: {text}" for text, n in counted.items()]
    if resized:
        notes.append(
            f"{len(resized)} of {len(kept)} frames: the annotation file declares another size "
            f"than the image's (first: {resized[0]}); their boxes are evaluated as given"
        )

    def report(files: Sequence[str], failures: Sequence[Failure]) -> dict[str, Any]:
        return build_report(
            dataset,
            plugins,
            settings,
            sections,
            len(kept),
            timing,
            skipped,
            files,
            notes,
            written,
            failures,
        )

    first = report((), metrics.failures)
    shown = ordered([*run_facts(first), *results])
    run = RunResult(first, dataset, settings, tuple(kept), shown, list(metrics.failures))
    if out is None:
        return run
    folder = Path(out)
    folder.mkdir(parents=True, exist_ok=True)
    with staged(folder) as staging:
        run = write_run(run, writers_for(writers), staging, report)
        remove_stale_files(folder, {*run.report.get("files", []), *run.report.get("plots", [])})
    return run


@contextlib.contextmanager
def staged(folder: Path):
    """A hidden folder inside ``folder`` for the writers; when they are done, each file it
    holds replaces its namesake in ``folder`` (renames, no copies). When the run stops midway
    (an error, Ctrl-C), the staged files are removed and ``folder`` keeps the previous run
    whole: old and new files are never mixed. A file that would replace one of the run's
    inputs (:func:`tsrkit.core.outputs.reading`) refuses the whole move."""
    staging = Path(tempfile.mkdtemp(prefix=".writing-", dir=folder))
    try:
        yield staging
        moves = [(p, folder / p.relative_to(staging)) for p in sorted(staging.rglob("*"))]
        moves = [(source, target) for source, target in moves if source.is_file()]
        for _, target in moves:
            refuse_input(target, "a report file")  # before anything is replaced
        for source, target in moves:
            target.parent.mkdir(parents=True, exist_ok=True)
            os.replace(source, target)
    finally:
        shutil.rmtree(staging, ignore_errors=True)


def run_benchmark(
    dataset: Dataset,
    detector: Detector | None = None,
    classifier: Classifier | None = None,
    *,
    verifier: Verifier | None = None,
    workers: int = 1,
    engine: str = "local",
    scheduler: Any = None,
    out: str | os.PathLike | None = None,
    cache: bool = True,
    cache_dir: str | os.PathLike | None = None,
    progress: bool = False,
    iou_threshold: float = 0.5,
    box: str = "auto",
    writers: Sequence[str] | None = None,
    lighting: str = "mascetti",
) -> RunResult:
    """:func:`benchmark`, returning the whole :class:`~tsrkit.reporting.report.RunResult` (records
    too)."""
    if detector is None and classifier is None:
        raise BenchmarkError("a benchmark needs a detector, a classifier, or both")
    settings = eval_settings(dataset, detector is not None, iou_threshold, box, lighting)
    plugins = {"detector": plugin_identity(detector), "classifier": plugin_identity(classifier)}
    if verifier is not None:
        plugins["verifier"] = plugin_identity(verifier)
    folder = (Path(cache_dir) if cache_dir else default_cache_dir(out)) if cache else None
    # the default scheme keeps the cache keys (and every cached record) of earlier runs
    scheme = "" if lighting == "mascetti" else f" lighting={lighting}"
    job = Job(
        detector,
        classifier,
        json.dumps(plugins, sort_keys=True) + scheme,
        str(folder) if folder else None,
        verifier,
        lighting,
    )
    label = (detector or classifier).name  # type: ignore[union-attr]
    if out is not None:
        refuse_foreign_report(Path(out))
    lock = locked(out) if out is not None else contextlib.nullcontext()
    with lock, ProgressBar(len(dataset), progress, label) as bar:
        samples = with_sun_elevation(dataset.samples) if lighting == "zheng" else dataset.samples
        records = bar.track(run_records(samples, job, workers, engine, scheduler))
        return evaluate(
            dataset,
            records,
            settings,
            plugins,
            out=out,
            writers=writers,
            run_info={"workers": workers, "engine": engine},
        )


def with_sun_elevation(samples: Sequence[Sample]) -> list[Sample]:
    """The samples, each with ``sun_elevation`` in its metadata when its time and position are
    known (``utc``, ``lat``, ``lon``: :func:`tsrkit.sun.relative.sun_elevation`) and it has none
    yet, for Zheng's lighting conditions (:func:`tsrkit.eval.lighting.zheng_condition`)."""
    # only runs with --lighting zheng pay for the solar geometry's imports (pyproj)
    from tsrkit.sun.relative import sun_elevation

    out = []
    for sample in samples:
        elevation = None if "sun_elevation" in sample.metadata else sun_elevation(sample.metadata)
        if elevation is not None:
            sample = dataclasses.replace(
                sample, metadata={**sample.metadata, "sun_elevation": elevation}
            )
        out.append(sample)
    return out


def benchmark(
    dataset: Dataset,
    detector: Detector | None = None,
    classifier: Classifier | None = None,
    **options: Any,
) -> dict[str, Any]:
    """Run a detector (and verifier, classifier) over ``dataset`` and return the report dict.

    Parameters
    ----------
    dataset : Dataset
    detector : Detector or None
        None with a classifier benchmarks the classifier on the ground-truth boxes (crops).
    classifier : Classifier, optional
    verifier : Verifier, optional
        Rescores, refines (housing box) or rejects the detector's candidates.
    workers : int
        Processes (``engine="local"``) or LocalCluster workers (``engine="dask"``).
    engine : {"local", "dask"}
    scheduler : str or cluster, optional
        Dask scheduler address or cluster object; a LocalCluster is started when None.
    out : path, optional
        Folder the report writers write to: report.json, summary.md, detections.jsonl, COCO
        files, CSV tables and plots.
    cache : bool
        Reuse and store per-frame records (``cache_dir``, default
        :func:`tsrkit.runner.engine.default_cache_dir`).
    progress : bool
        Show a progress bar with frames/s on stderr.
    iou_threshold : float
        Threshold of the ``iou`` section (Lee 3.6.2); ``iou50`` always uses 0.5.
    box : {"auto", "housing", "lens"}
        The evaluated box: ``lens_bbox`` or ``bbox`` (the housing once a verifier fitted one);
        ``auto`` is ``lens`` on a dataset whose registry ``box`` is ``lens``, else ``housing``.
        ``report.json`` says which in ``evaluated_box``.
    writers : sequence of str, optional
        Report writers by name (default: the registered default writers).
    lighting : {"mascetti", "zheng"}
        Lighting categories of the lighting x size table (Zheng 5.2.1, Table 5-2): Mascetti
        3.2's mean-V classes (default) or Zheng's Figure 4-2 conditions
        (:func:`tsrkit.eval.lighting.zheng_condition`; the report's notes state the rule).
    """
    return run_benchmark(dataset, detector, classifier, **options).report
