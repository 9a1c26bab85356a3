"""A pipeline over images and videos, in this process or in worker processes, in input order.

With workers, each unit of :func:`tsrkit.runner.inputs.plan_work` (an image, or a chunk of
:data:`CHUNK_FRAMES` kept frames of a video) is read by the worker that processes it: the worker
opens the video, seeks to the chunk's first frame and decodes only its chunk, so the main process
neither decodes nor ships pixels. At most ``4 x workers`` units are in flight
(:func:`tsrkit.runner.engine.ordered`) and results come back in input order, so memory stays flat
however long the video.
"""

from __future__ import annotations

import os
from collections.abc import Iterable, Iterator, Mapping
from concurrent.futures import ProcessPoolExecutor
from concurrent.futures.process import BrokenProcessPool

from tsrkit.core.errors import TsrkitError
from tsrkit.core.types import Frame, Skipped
from tsrkit.plugin.pipeline import FrameResult, Pipeline
from tsrkit.runner.engine import ordered, pool_context, single_thread
from tsrkit.runner.follow import Follower
from tsrkit.runner.inputs import Work, iter_frames, plan_work, read_work
from tsrkit.runner.workers import check_workers, end_with_run, pool_broke

__all__ = ["CHUNK_FRAMES", "Runner", "chunk_frames", "process_frame", "run_pipeline"]

#: What runs on each frame: a pipeline, or a follower sharing work between video frames.
Runner = Pipeline | Follower

#: Kept frames of a video per unit of work: long enough that the seek to a chunk's key frame is
#: a small share of its decoding, short enough to spread a short clip over the workers.
CHUNK_FRAMES = 64


def process_frame(pipeline: Runner, frame: Frame) -> FrameResult | Skipped:
    """The pipeline's result on ``frame``, or the frame skipped with the reason its plugin crashed.

    A :class:`~tsrkit.core.errors.TsrkitError` (a setup problem, such as a mismatched model, that
    would recur on every frame) propagates.
    """
    try:
        return pipeline.process(frame)
    except TsrkitError:
        raise
    except Exception as exc:  # a crashing plugin costs one frame, not the run
        label = f"{frame.source}#{frame.index}" if frame.index else frame.source
        return Skipped(label, f"plugin error: {type(exc).__name__}: {exc}")


def run_pipeline(
    pipeline: Runner,
    paths: Iterable[str | os.PathLike],
    *,
    every: int = 1,
    start: int = 0,
    end: int | None = None,
    workers: int = 1,
    done: Mapping[str, int] | None = None,
) -> Iterator[tuple[FrameResult | Skipped, Frame | None]]:
    """Each frame's result (or skip) in input order, with the frame itself when ``workers`` is 1.

    Parameters
    ----------
    pipeline : Pipeline or Follower
    paths : iterable of path-like
        Images, videos and folders, as :func:`tsrkit.runner.inputs.iter_frames` reads them.
    every, start, end : int
        Video frame selection (see :func:`tsrkit.runner.inputs.iter_frames`).
    workers : int
        Worker processes; 1 runs here. A tracker follows a video frame by frame, so a pipeline
        with one runs here only. A follower's chunks are a multiple of its key-frame interval,
        so that its records do not depend on ``workers``.
    done : mapping of str to int, optional
        The frames an earlier run finished, left out (see :func:`tsrkit.runner.inputs.plan_work`).
    """
    check_workers(workers)
    if workers == 1:
        for item in iter_frames(paths, every, start, end, done):
            yield (
                (item, None) if isinstance(item, Skipped) else (process_frame(pipeline, item), item)
            )
        return
    if isinstance(pipeline, Pipeline) and pipeline.tracker is not None:
        raise TsrkitError("a tracker follows a video frame by frame: run it with one worker")
    units = plan_work(paths, every, start, end, chunk=chunk_frames(pipeline), done=done)
    with ProcessPoolExecutor(
        workers,
        mp_context=pool_context(),
        initializer=_init_worker,
        initargs=(pipeline, every, os.getpid()),
    ) as pool:
        try:
            for results in ordered(
                lambda _, unit: (
                    unit if isinstance(unit, Skipped) else pool.submit(_process_work, unit)
                ),
                lambda done: [done] if isinstance(done, Skipped) else done.result(),
                units,
                4 * workers,
            ):
                for result in results:
                    yield result, None
        except BrokenProcessPool as exc:
            raise pool_broke(exc) from None


def chunk_frames(pipeline: Runner) -> int:
    """Kept frames per unit of work: :data:`CHUNK_FRAMES`, rounded down to a multiple of a
    follower's key-frame interval (each chunk then starts on one of its key frames).

    >>> from tsrkit.plugin.pipeline import Pipeline
    >>> chunk_frames(Follower(Pipeline(None), key_every=5)), chunk_frames(Pipeline(None))
    (60, 64)
    """
    if isinstance(pipeline, Follower):
        k = pipeline.key_every
        return max(k, CHUNK_FRAMES // k * k)
    return CHUNK_FRAMES


_WORKER: tuple[Runner, int] | None = None


def _init_worker(pipeline: Runner, every: int, run: int) -> None:
    global _WORKER
    _WORKER = (pipeline, every)
    single_thread()
    end_with_run(run)


def _process_work(unit: Work) -> list[FrameResult | Skipped]:
    assert _WORKER is not None, "the pool initializer sets the pipeline"
    pipeline, every = _WORKER
    return [
        item if isinstance(item, Skipped) else process_frame(pipeline, item)
        for item in read_work(unit, every)
    ]
