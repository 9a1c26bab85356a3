"""Run a detector (and classifier) over a dataset, in parallel, cached per frame, and evaluate it.

Frames stream through a bounded window of tasks (in this process, a process pool, or a Dask
cluster) and come back in dataset order, so memory stays flat whatever the dataset size. Each
frame's record is cached under a key made of the image's hash and the plugins' names, versions
and parameters, so a killed run resumes where it stopped.
"""
from __future__ import annotations

import hashlib
import inspect
import json
import multiprocessing
import os
import time
from collections import deque
from collections.abc import Callable, Iterable, Iterator
from concurrent.futures import ProcessPoolExecutor
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from tsrkit.atomic import atomic_open
from tsrkit.errors import TsrkitError
from tsrkit.eval.aggregate import Evaluation
from tsrkit.inputs import ImageReadError
from tsrkit.lighting import light_condition
from tsrkit.pipeline import Pipeline
from tsrkit.plugin import Classifier, Detector, Plugin, Verifier
from tsrkit.registry import PluginNotFound, get_registry
from tsrkit.types import Candidate, Dataset, Sample

ENGINES = ("local", "dask")
_NOT_DETECTION = {"note": "classifier alone on the ground-truth boxes: detection metrics do not "
                          "apply"}
#: What replaces the detection sections of a classifier-only (crop) report.
CLASSIFICATION_ONLY = {"per_frame": _NOT_DETECTION, "iou50": _NOT_DETECTION,
                       "iou": _NOT_DETECTION, "categories": [], "intervals": {}}


class BenchmarkError(TsrkitError):
    """A benchmark that cannot start: no plugin, bad engine, unreachable scheduler..."""


@dataclass(frozen=True)
class Job:
    """What every worker needs: the plugins, their cache identity and the cache folder."""

    detector: Detector | None
    classifier: Classifier | None
    identity: str
    cache_dir: str | None
    verifier: Verifier | None = None


def plugin_identity(plugin: Plugin | None) -> dict[str, Any] | None:
    """Name, version, parameters and source hash of a plugin (report and cache key)."""
    if plugin is None:
        return None
    try:
        version = get_registry().get(plugin.kind, plugin.name).version
    except PluginNotFound:
        version = plugin.version or "0"
    params = json.loads(json.dumps(plugin.params, default=str, sort_keys=True))
    return {"name": plugin.name, "version": version, "params": params,
            "source_sha256": source_hash(type(plugin))}


def source_hash(cls: type) -> str | None:
    """SHA-256 of the file defining ``cls``, so editing a plugin without a version bump does
    not reuse stale cached frames (helpers in other files are not covered)."""
    try:
        path = inspect.getsourcefile(cls)
    except TypeError:
        return None
    if path is None or not os.path.isfile(path):
        return None
    with open(path, "rb") as fh:
        return hashlib.sha256(fh.read()).hexdigest()


def image_hash(sample: Sample) -> str:
    """SHA-256 of the image file's bytes, or of the in-memory pixels and their shape."""
    digest = hashlib.sha256()
    if sample.image is not None:
        digest.update(repr(sample.image.shape).encode())
        digest.update(sample.image.tobytes())
    else:
        with open(sample.source, "rb") as fh:
            for block in iter(lambda: fh.read(1 << 20), b""):
                digest.update(block)
    return digest.hexdigest()


def process_sample(index: int, sample: Sample, job: Job) -> dict[str, Any]:
    """The record of one frame: from the cache, else computed (and cached).

    Returns a dict with ``index``, ``source`` and either ``skipped`` (the reason) or ``width``,
    ``height``, ``ms``, ``lighting``, ``detections`` and ``cached``.
    """
    try:
        key = hashlib.sha256((image_hash(sample) + job.identity).encode()).hexdigest()
    except OSError as exc:
        return {"index": index, "source": sample.source,
                "skipped": f"cannot read: {exc.strerror or exc}"}
    path = Path(job.cache_dir, key[:2], f"{key}.json") if job.cache_dir else None
    if path is not None and path.is_file():
        with open(path, encoding="utf-8") as fh:
            return {**json.load(fh), "index": index, "cached": True}
    record = _compute(sample, job)
    if path is not None and "skipped" not in record:
        with atomic_open(path) as fh:
            json.dump(record, fh)
    return {**record, "index": index, "cached": False}


def _compute(sample: Sample, job: Job) -> dict[str, Any]:
    try:
        frame = sample.load()
    except ImageReadError as exc:
        return {"source": sample.source, "skipped": str(exc)}
    lighting = sample.metadata.get("lighting") or light_condition(frame.image)
    try:
        if job.detector is not None:
            result = Pipeline(job.detector, job.classifier, verifier=job.verifier).process(frame)
            ms, detections = result.ms, result.detections
        else:
            ms, detections = _classify_annotations(job.classifier, frame, sample)
    except TsrkitError:  # a setup problem (missing model...) would recur on every frame
        raise
    except Exception as exc:  # a crashing plugin costs one frame, not the run
        return {"source": sample.source, "skipped": f"plugin error: {type(exc).__name__}: {exc}"}
    return {"source": sample.source, "width": frame.width, "height": frame.height, "ms": ms,
            "lighting": str(lighting), "detections": [d.to_record() for d in detections]}


def _classify_annotations(classifier: Classifier, frame, sample: Sample):
    """Classification benchmark: the classifier alone on the ground-truth boxes."""
    candidates = [Candidate.from_box(a.bbox, 1.0) for a in sample.annotations]
    start = time.perf_counter()
    detections = classifier.classify(frame, candidates)
    return (time.perf_counter() - start) * 1000.0, detections


_WORKER_JOB: Job | None = None


def _init_worker(job: Job) -> None:
    global _WORKER_JOB
    _WORKER_JOB = job
    _single_thread()


def _single_thread() -> None:
    import cv2

    cv2.setNumThreads(1)


def _pool_context():
    """Workers from a fork server: forking a process whose OpenCV thread pool has started can
    crash the child, so children fork from a clean server that preloads the runner."""
    context = multiprocessing.get_context("forkserver")
    context.set_forkserver_preload(["tsrkit.runner"])
    return context


def _run_in_worker(index: int, sample: Sample) -> dict[str, Any]:
    return process_sample(index, sample, _WORKER_JOB)


def ordered(submit: Callable[[int, Sample], Any], result: Callable[[Any], dict],
            samples: Iterable[Sample], window: int) -> Iterator[dict]:
    """Submit tasks with at most ``window`` in flight; yield their results in dataset order."""
    pending: deque = deque()
    for index, sample in enumerate(samples):
        pending.append(submit(index, sample))
        if len(pending) >= window:
            yield result(pending.popleft())
    while pending:
        yield result(pending.popleft())


def run_records(samples: Iterable[Sample], job: Job, workers: int = 1, engine: str = "local",
                scheduler: Any = None) -> Iterator[dict]:
    """Frame records in dataset order, computed in this process, a process pool or on Dask."""
    if engine not in ENGINES:
        raise BenchmarkError(f"unknown engine '{engine}' (choose {' or '.join(ENGINES)})")
    if workers < 1:
        raise BenchmarkError(f"workers must be at least 1; got {workers}")
    if engine == "dask":
        yield from _run_dask(samples, job, workers, scheduler)
    elif workers == 1:
        yield from (process_sample(i, s, job) for i, s in enumerate(samples))
    else:
        with ProcessPoolExecutor(workers, mp_context=_pool_context(), initializer=_init_worker,
                                 initargs=(job,)) as pool:
            yield from ordered(lambda i, s: pool.submit(_run_in_worker, i, s),
                               lambda f: f.result(), samples, 4 * workers)


def _run_dask(samples: Iterable[Sample], job: Job, workers: int,
              scheduler: Any) -> Iterator[dict]:
    from distributed import Client, LocalCluster

    cluster = None
    if scheduler is None:
        cluster = LocalCluster(n_workers=workers, threads_per_worker=1, dashboard_address=None)
        scheduler = cluster
    address = getattr(scheduler, "scheduler_address", scheduler)
    try:
        client = Client(address, timeout="20s", set_as_default=False)
    except OSError as exc:
        raise BenchmarkError(f"cannot reach Dask scheduler {address}: {exc}") from None
    try:
        shared = client.scatter(job, broadcast=True)
        window = 4 * max(workers, len(client.scheduler_info()["workers"]))
        yield from ordered(lambda i, s: client.submit(process_sample, i, s, shared, pure=False),
                           lambda f: f.result(), samples, window)
    finally:
        client.close()
        if cluster is not None:
            cluster.close()


def default_cache_dir(out: str | os.PathLike | None) -> Path:
    """``OUT/cache``, else ``$TSRKIT_CACHE_DIR/frames`` or ``~/.cache/tsrkit/frames``."""
    if out is not None:
        return Path(out) / "cache"
    base = os.environ.get("TSRKIT_CACHE_DIR") or Path.home() / ".cache" / "tsrkit"
    return Path(base) / "frames"


def evaluate(dataset: Dataset, detector: Detector | None, classifier: Classifier | None = None,
             *, workers: int = 1, engine: str = "local", scheduler: Any = None,
             out: str | os.PathLike | None = None, cache: bool = True,
             cache_dir: str | os.PathLike | None = None, progress: bool = False,
             iou_threshold: float = 0.5,
             verifier: Verifier | None = None) -> tuple[dict[str, Any], Evaluation]:
    """Run and evaluate; return the report and the :class:`Evaluation` (per-frame scores).

    Parameters are those of :func:`benchmark`.
    """
    from tsrkit.report import ProgressBar, base_report, write_outputs

    if detector is None and classifier is None:
        raise BenchmarkError("a benchmark needs a detector, a classifier, or both")
    identities = {"detector": plugin_identity(detector),
                  "classifier": plugin_identity(classifier)}
    if verifier is not None:
        identities["verifier"] = plugin_identity(verifier)
    identity = json.dumps(identities, sort_keys=True)
    folder = (Path(cache_dir) if cache_dir else default_cache_dir(out)) if cache else None
    job = Job(detector, classifier, identity, str(folder) if folder else None, verifier)
    evaluation = Evaluation(dataset.name, iou_threshold)
    skipped, counts = [], {"computed": 0, "cached": 0}
    start = time.perf_counter()
    sink_context = (atomic_open(Path(out) / "detections.jsonl") if out is not None
                    else open(os.devnull, "w", encoding="utf-8"))
    label = (detector or classifier).name
    with sink_context as sink, ProgressBar(len(dataset), progress, label) as bar:
        for record in run_records(dataset.samples, job, workers, engine, scheduler):
            bar.advance()
            if "skipped" in record:
                skipped.append({"source": record["source"], "reason": record["skipped"]})
                continue
            counts["cached" if record.pop("cached") else "computed"] += 1
            evaluation.add(record["index"] + 1, dataset.samples[record["index"]], record)
            sink.write(json.dumps(_jsonl_record(record)) + "\n")
    wall = time.perf_counter() - start
    report = base_report(dataset, plugin_identity(detector), plugin_identity(classifier))
    if verifier is not None:
        report["verifier"] = plugin_identity(verifier)
    metrics = evaluation.metrics()
    median = metrics.pop("ms_per_frame_median")
    if detector is None:
        metrics.update(CLASSIFICATION_ONLY)
    report.update(metrics)
    report["timing"] = {"ms_per_frame_median": median,
                        "frames_per_second": metrics["frames"] / wall if wall > 0 else None,
                        "wall_seconds": wall, "workers": workers, "engine": engine,
                        "frames_computed": counts["computed"], "frames_cached": counts["cached"]}
    report["skipped"] = skipped
    if out is not None:
        write_outputs(Path(out), report, evaluation)
    return report, evaluation


def _jsonl_record(record: dict) -> dict:
    """The ``tsrkit detect`` record of a frame, plus its lighting."""
    return {"source": record["source"], "frame": record["index"], "width": record["width"],
            "height": record["height"], "ms": round(record["ms"], 3),
            "lighting": record["lighting"], "detections": record["detections"]}


def benchmark(dataset: Dataset, detector: Detector | None, classifier: Classifier | None = None,
              *, workers: int = 1, engine: str = "local", scheduler: Any = None,
              out: str | os.PathLike | None = None, cache: bool = True,
              cache_dir: str | os.PathLike | None = None, progress: bool = False,
              iou_threshold: float = 0.5, verifier: Verifier | None = None) -> dict[str, Any]:
    """Run a detector (and verifier, classifier) over ``dataset`` and return the report dict.

    Parameters
    ----------
    dataset : Dataset
    detector : Detector or None
        None with a classifier benchmarks the classifier on the ground-truth boxes (crops).
    classifier : Classifier, optional
    workers : int
        Processes (``engine="local"``) or LocalCluster workers (``engine="dask"``).
    engine : {"local", "dask"}
    scheduler : str or cluster, optional
        Dask scheduler address or cluster object; a LocalCluster is started when None.
    out : path, optional
        Folder for report.json, summary.md, detections.jsonl, COCO files and plots.
    cache : bool
        Reuse and store per-frame records (``cache_dir``, default :func:`default_cache_dir`).
    progress : bool
        Show a progress bar with frames/s on stderr.
    iou_threshold : float
        Threshold of the ``iou`` section (Lee 3.6.2); ``iou50`` always uses 0.5.
    verifier : Verifier, optional
        Rescores, refines (housing box) or rejects the detector's candidates.
    """
    report, _ = evaluate(dataset, detector, classifier, workers=workers, engine=engine,
                         scheduler=scheduler, out=out, cache=cache, cache_dir=cache_dir,
                         progress=progress, iou_threshold=iou_threshold, verifier=verifier)
    return report


def compare(dataset: Dataset, detectors: list[Detector], classifier: Classifier | None = None,
            *, out: str | os.PathLike | None = None, **options: Any) -> dict[str, Any]:
    """Benchmark several detectors on the same frames and test each pair.

    Each run writes its outputs to ``OUT/<detector>/``; ``OUT/compare.json`` and
    ``OUT/compare.md`` hold the reports side by side and, for every pair, a Wilcoxon
    signed-rank test on per-frame recall over the ground-truth frames both evaluated.
    Other keyword options are those of :func:`benchmark`.
    """
    from tsrkit.eval.stats import paired_test
    from tsrkit.report import write_compare

    names = [d.name for d in detectors]
    if len(set(names)) != len(names) or len(names) < 2:
        raise BenchmarkError(f"compare needs at least two different detectors; got {names}")
    reports, recalls = [], []
    for detector in detectors:
        sub = Path(out) / detector.name if out is not None else None
        report, evaluation = evaluate(dataset, detector, classifier, out=sub, **options)
        reports.append(report)
        recalls.append({i: s.recall for i, s in evaluation.scores.items() if s.n_gt})
    tests = []
    for a in range(len(detectors)):
        for b in range(a + 1, len(detectors)):
            common = sorted(recalls[a].keys() & recalls[b].keys())
            test = paired_test([recalls[a][i] for i in common], [recalls[b][i] for i in common],
                               names[a], names[b])
            tests.append({"a": names[a], "b": names[b], "metric": "per-frame recall", **test})
    comparison = {"dataset": dataset.name, "detectors": names, "reports": reports,
                  "paired_tests": tests}
    if out is not None:
        write_compare(Path(out), comparison)
    return comparison
