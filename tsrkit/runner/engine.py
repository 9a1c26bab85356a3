"""The engine: per-frame records computed in this process, a process pool or on Dask, cached.

Frames stream through a bounded window of tasks and come back in dataset order, so memory stays
flat whatever the dataset size. Each frame's :class:`~tsrkit.core.records.FrameRecord` is cached
under
a key made of the image's hash and the plugins' names, versions and parameters, so a killed run
resumes where it stopped.
"""

from __future__ import annotations

import hashlib
import inspect
import json
import multiprocessing
import os
import re
import time
from collections import deque
from collections.abc import Callable, Iterable, Iterator
from concurrent.futures import ProcessPoolExecutor
from concurrent.futures.process import BrokenProcessPool
from dataclasses import dataclass, replace
from multiprocessing import forkserver
from pathlib import Path
from typing import Any, TypeVar

import cv2

from tsrkit.core.atomic import atomic_open, json_line
from tsrkit.core.errors import TsrkitError
from tsrkit.core.files import InputFileError, read_json
from tsrkit.core.images import ImageReadError
from tsrkit.core.records import FrameRecord
from tsrkit.core.types import Candidate, Frame, Sample
from tsrkit.eval.lighting import frame_condition
from tsrkit.plugin.base import Classifier, Detector, Plugin, Verifier
from tsrkit.plugin.pipeline import FrameResult, Pipeline
from tsrkit.plugin.registry import PluginNotFound, get_registry
from tsrkit.runner.workers import check_workers, end_with_run, pool_broke

__all__ = [
    "ENGINES",
    "BenchmarkError",
    "Item",
    "Job",
    "Result",
    "classify_annotations",
    "compute_record",
    "default_cache_dir",
    "image_hash",
    "ordered",
    "plugin_identity",
    "pool_context",
    "process_sample",
    "read_cached",
    "run_records",
    "single_thread",
    "source_hash",
    "start_pool_server",
]

ENGINES = ("local", "dask")
Item = TypeVar("Item")
Result = TypeVar("Result")


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
    lighting: str = "mascetti"


def plugin_identity(plugin: Plugin | None) -> dict[str, Any] | None:
    """Name, version, parameters and source hash of a plugin (report and cache key)."""
    if plugin is None:
        return None
    try:
        version = get_registry().get(plugin.kind, plugin.name).version
    except PluginNotFound:
        version = plugin.version or "0"
    params = json.loads(json.dumps(plugin.params, default=str, sort_keys=True))
    return {
        "name": plugin.name,
        "version": version,
        "params": params,
        "source_sha256": source_hash(type(plugin)),
    }


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
    sample.hash_into(digest)
    return digest.hexdigest()


def process_sample(index: int, sample: Sample, job: Job) -> FrameRecord:
    """The record of one frame: from the cache, else computed (and cached)."""
    try:
        key = hashlib.sha256((image_hash(sample) + job.identity).encode()).hexdigest()
    except OSError as exc:
        return FrameRecord(sample.source, index, skipped=f"cannot read: {exc.strerror or exc}")
    except ImageReadError as exc:
        reason = str(exc).removeprefix(f"{sample.source}: ")
        return FrameRecord(sample.source, index, skipped=reason)
    path = Path(job.cache_dir, key[:2], f"{key}.json") if job.cache_dir else None
    cached = read_cached(path) if path is not None else None
    if cached is not None:
        return replace(cached, index=index, cached=True)
    record = compute_record(index, sample, job)
    if path is not None and record.skipped is None:
        with atomic_open(path, sync=False) as fh:
            fh.write(json_line(record.to_json()))
    return record


#: The largest cache entry read, in bytes (a frame's record is a few kilobytes).
MAX_CACHE_ENTRY = 64 * 2**20


def read_cached(path: Path) -> FrameRecord | None:
    """The record cached at ``path``, or None when there is none or it cannot be used (not a
    regular file, too large, cut short by a crash, edited by hand, not a record): the frame is
    then computed again and the entry rewritten, so a damaged cache costs time, never the run."""
    if not path.is_file():
        return None
    try:
        return FrameRecord.from_json(read_json(path, MAX_CACHE_ENTRY))
    except (InputFileError, OSError, KeyError, TypeError, ValueError, AttributeError, IndexError):
        return None


def compute_record(index: int, sample: Sample, job: Job) -> FrameRecord:
    """Load the frame, run the plugins and time them; a failure becomes a skipped record."""
    try:
        frame = sample.load()
    except ImageReadError as exc:
        return FrameRecord(sample.source, index, skipped=str(exc))
    lighting = sample.metadata.get("lighting") or frame_condition(
        frame.image, job.lighting, sample.metadata.get("sun_elevation")
    )
    try:
        if job.detector is not None:
            result = Pipeline(job.detector, job.classifier, verifier=job.verifier).process(frame)
        elif job.classifier is not None:
            result = classify_annotations(job.classifier, frame, sample)
        else:
            raise TsrkitError("a run needs a detector or a classifier")
    except TsrkitError:  # a setup problem (missing model...) would recur on every frame
        raise
    except Exception as exc:  # a crashing plugin costs one frame, not the run
        return FrameRecord(
            sample.source, index, skipped=f"plugin error: {type(exc).__name__}: {exc}"
        )
    return replace(FrameRecord.from_result(result, str(lighting)), index=index)


def classify_annotations(classifier: Classifier, frame: Frame, sample: Sample) -> FrameResult:
    """Classification benchmark: the classifier alone on the ground-truth boxes."""
    candidates = [Candidate.from_box(a.bbox, 1.0) for a in sample.annotations]
    start = time.perf_counter()
    detections = classifier.classify(frame, candidates)
    ms = (time.perf_counter() - start) * 1000.0
    return FrameResult(
        frame.source,
        frame.index,
        frame.width,
        frame.height,
        ms,
        tuple(detections),
        classifier.notes,
    )


_WORKER_JOB: Job | None = None


def _init_worker(job: Job, run: int) -> None:
    global _WORKER_JOB
    _WORKER_JOB = job
    single_thread()
    end_with_run(run)


def single_thread() -> None:
    """One OpenCV thread per worker process: the workers are the parallelism."""
    cv2.setNumThreads(1)


def pool_context():
    """The multiprocessing context of every worker pool: workers fork from a clean fork server
    (forking a process whose OpenCV thread pool has started can crash the child) that has
    imported the engine and the plugins and initialised numba (:mod:`tsrkit.runner._preload`)."""
    context = multiprocessing.get_context("forkserver")
    context.set_forkserver_preload(["tsrkit.runner.engine", "tsrkit.runner._preload"])
    return context


def start_pool_server() -> None:
    """Start the worker pools' fork server now (if it is not running), so that its imports run
    on another core while the caller is still starting up, not after the pool is asked for."""
    pool_context()
    forkserver.ensure_running()


def _run_in_worker(index: int, sample: Sample) -> FrameRecord:
    assert _WORKER_JOB is not None, "the pool initializer sets the job"
    return process_sample(index, sample, _WORKER_JOB)


def ordered(
    submit: Callable[[int, Item], Any],
    result: Callable[[Any], Result],
    items: Iterable[Item],
    window: int,
) -> Iterator[Result]:
    """Submit tasks with at most ``window`` in flight; yield their results in input order."""
    pending: deque = deque()
    for index, item in enumerate(items):
        pending.append(submit(index, item))
        if len(pending) >= window:
            yield result(pending.popleft())
    while pending:
        yield result(pending.popleft())


def run_records(
    samples: Iterable[Sample],
    job: Job,
    workers: int = 1,
    engine: str = "local",
    scheduler: Any = None,
) -> Iterator[FrameRecord]:
    """Frame records in dataset order, computed in this process, a process pool or on Dask."""
    if engine not in ENGINES:
        raise BenchmarkError(f"unknown engine '{engine}' (choose {' or '.join(ENGINES)})")
    check_workers(workers)
    if engine == "dask":
        yield from _run_dask(samples, job, workers, scheduler)
    elif workers == 1:
        yield from (process_sample(i, s, job) for i, s in enumerate(samples))
    else:
        with ProcessPoolExecutor(
            workers,
            mp_context=pool_context(),
            initializer=_init_worker,
            initargs=(job, os.getpid()),
        ) as pool:
            try:
                yield from ordered(
                    lambda i, s: pool.submit(_run_in_worker, i, s),
                    lambda f: f.result(),
                    samples,
                    4 * workers,
                )
            except BrokenProcessPool as exc:
                raise pool_broke(exc) from None


#: A Dask scheduler address: ``protocol://...`` or ``host:port``.
SCHEDULER_ADDRESS = re.compile(r"[a-z]+://\S+|(\[[0-9a-fA-F:]+\]|[^\s:/\[\]]+):\d{1,5}")


def _run_dask(
    samples: Iterable[Sample], job: Job, workers: int, scheduler: Any
) -> Iterator[FrameRecord]:
    from distributed import Client, LocalCluster

    cluster = None
    if scheduler is None:
        cluster = LocalCluster(n_workers=workers, threads_per_worker=1, dashboard_address=None)
        scheduler = cluster
    address = getattr(scheduler, "scheduler_address", scheduler)
    if isinstance(address, str) and not SCHEDULER_ADDRESS.fullmatch(address):
        raise BenchmarkError(
            f"--scheduler {address!r}: expected HOST:PORT or PROTOCOL://HOST:PORT "
            "(e.g. tcp://10.0.0.5:8786)"
        )
    try:
        client = Client(address, timeout="20s", set_as_default=False)
    except (OSError, ValueError) as exc:
        raise BenchmarkError(f"cannot reach Dask scheduler {address}: {exc}") from None
    try:
        shared = client.scatter(job, broadcast=True)
        window = 4 * max(workers, len(client.scheduler_info()["workers"]))
        yield from ordered(
            lambda i, s: client.submit(process_sample, i, s, shared, pure=False),
            lambda f: f.result(),
            samples,
            window,
        )
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
