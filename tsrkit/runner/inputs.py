"""Reading images, folders and videos into frames; unusable inputs become :class:`Skipped`.

Images are returned as BGR uint8 whatever their file holds: 16-bit samples are scaled down,
alpha is dropped, grayscale is promoted to three channels. Videos are decoded with OpenCV's
FFmpeg backend.
"""

from __future__ import annotations

import os
from collections.abc import Iterable, Iterator, Mapping
from dataclasses import dataclass
from pathlib import Path

import cv2

from tsrkit.core.errors import TsrkitError
from tsrkit.core.files import not_regular
from tsrkit.core.images import ImageReadError, read_image, to_bgr8
from tsrkit.core.outputs import is_output
from tsrkit.core.types import Frame, Skipped

__all__ = [
    "IMAGE_EXTENSIONS",
    "VIDEO_EXTENSIONS",
    "Work",
    "check_range",
    "expand_paths",
    "iter_frames",
    "iter_video",
    "plan_work",
    "read_work",
    "video_frame_count",
]

IMAGE_EXTENSIONS = {
    ".jpg",
    ".jpeg",
    ".jpe",
    ".png",
    ".ppm",
    ".pgm",
    ".pbm",
    ".pnm",
    ".bmp",
    ".dib",
    ".tif",
    ".tiff",
    ".webp",
    ".jp2",
    ".sr",
    ".ras",
    ".exr",
    ".hdr",
    ".gif",  # its first frame
}
VIDEO_EXTENSIONS = {
    ".mp4",
    ".avi",
    ".mov",
    ".mkv",
    ".webm",
    ".m4v",
    ".mpg",
    ".mpeg",
    ".wmv",
    ".flv",
    ".ts",
    ".mts",
    ".3gp",
}


def expand_paths(paths: Iterable[str | os.PathLike]) -> Iterator[Path | Skipped]:
    """Files named directly, and every non-hidden file below each folder, sorted.

    What is not a regular file (a FIFO, device or socket, which would block or never end) is
    skipped with its reason; the run's own outputs (:func:`tsrkit.core.outputs.writing`) are left
    out, so an output written inside an input folder is not read back as an input.
    """
    for given in paths:
        path = Path(given)
        if path.is_dir():
            for root, dirs, files in os.walk(path):
                dirs[:] = sorted(
                    d for d in dirs if not d.startswith(".") and not is_output(Path(root) / d)
                )
                for name in sorted(files):
                    if not name.startswith(".") and not is_output(Path(root) / name):
                        yield _regular(Path(root) / name)
        elif path.exists() or path.is_symlink():
            yield _regular(path)
        else:
            yield Skipped(str(path), "no such file or folder")


def _regular(path: Path) -> Path | Skipped:
    problem = not_regular(path)
    return path if problem is None else Skipped(str(path), problem)


def check_range(every: int, start: int, end: int | None) -> None:
    """Refuse a video frame selection that keeps nothing or is not one.

    Raises
    ------
    TsrkitError
        Naming the options, e.g. ``--end 1 is before --start 3``.
    """
    if every < 1:
        raise TsrkitError(f"--every {every}: must be at least 1")
    if start < 0:
        raise TsrkitError(f"--start {start}: must be at least 0")
    if end is not None and end < start:
        raise TsrkitError(f"--end {end} is before --start {start}")
    if end is not None and end == start:
        raise TsrkitError(f"--start {start} --end {end} is an empty range of frames")


@dataclass(frozen=True)
class Work:
    """A unit of input one reader handles: an image file, or a run of a video's frames
    (``start`` to ``end``, none before ``after``: those were done by an earlier run)."""

    path: str
    video: bool = False
    start: int = 0
    end: int | None = None
    after: int = 0


def plan_work(
    paths: Iterable[str | os.PathLike],
    every: int = 1,
    start: int = 0,
    end: int | None = None,
    chunk: int | None = None,
    done: Mapping[str, int] | None = None,
) -> Iterator[Work | Skipped]:
    """The units of work of ``paths``: one per image, one per video or, with ``chunk``, one per
    ``chunk`` kept frames of a video whose container declares its frame count (so that workers
    each decode their own part); unusable paths as :class:`Skipped`.

    ``done`` maps each input an earlier run finished frames of to its last frame done
    (``detect --resume``): those images are left out, those videos go on after that frame.
    """
    check_range(every, start, end)
    done = done or {}
    for item in expand_paths(paths):
        if isinstance(item, Skipped):
            yield item
            continue
        suffix = item.suffix.lower()
        after = done[str(item)] + 1 if str(item) in done else 0
        if suffix in VIDEO_EXTENSIONS:
            count = video_frame_count(item) if chunk else 0
            if not count:
                yield Work(str(item), True, start, end, after)
                continue
            stop = count if end is None else min(end, count)
            step = chunk * every if chunk else stop
            for first in range(start, max(stop, start + 1), step):
                if first + step > after:
                    yield Work(str(item), True, first, min(first + step, stop), after)
        elif suffix in IMAGE_EXTENSIONS:
            if not after:
                yield Work(str(item))
        else:
            yield Skipped(str(item), f"not an image or video (unsupported type '{suffix}')")


def read_work(work: Work, every: int = 1) -> Iterator[Frame | Skipped]:
    """The frames of one unit of :func:`plan_work` (videos: every ``every``-th frame)."""
    if work.video:
        yield from iter_video(Path(work.path), every, work.start, work.end, work.after)
        return
    try:
        yield Frame(image=read_image(work.path), source=work.path)
    except ImageReadError as exc:
        yield Skipped(work.path, str(exc).removeprefix(f"{work.path}: "))


def iter_frames(
    paths: Iterable[str | os.PathLike],
    every: int = 1,
    start: int = 0,
    end: int | None = None,
    done: Mapping[str, int] | None = None,
) -> Iterator[Frame | Skipped]:
    """Yield the frames of images, folders and videos; unusable inputs as :class:`Skipped`.

    Parameters
    ----------
    paths : iterable of path-like
        Image files, video files or folders (searched recursively, sorted by path).
    every : int
        Keep every N-th video frame.
    start, end : int
        Video frame numbers: the first kept and the one to stop before (None: to the end).
    done : mapping of str to int, optional
        The frames an earlier run finished, left out (see :func:`plan_work`).
    """
    for work in plan_work(paths, every, start, end, done=done):
        if isinstance(work, Skipped):
            yield work
        else:
            yield from read_work(work, every)


#: Consecutive frames a video may fail to decode before its reader takes the rest as lost too
#: and stops (a damaged stretch is usually a few frames; a truncated file fails on every grab).
MAX_LOST_RUN = 250


def iter_video(
    path: Path, every: int = 1, start: int = 0, end: int | None = None, after: int = 0
) -> Iterator[Frame | Skipped]:
    """Decode ``path`` frame by frame, keeping frames ``start, start+every, ...`` before ``end``
    and none before ``after`` (the frames an earlier run did).

    A frame FFmpeg cannot decode (a damaged stretch of the file) is lost, not the end of the
    video: each kept frame lost is yielded as :class:`Skipped` (``PATH#INDEX``) and decoding
    goes on past it. A failed grab counts as one lost frame when it lies before the frame count
    the container declares, or when a later frame decodes; the reader stops at a failure at or
    past the declared count, or after :data:`MAX_LOST_RUN` failures in a row.
    """
    capture = cv2.VideoCapture(str(path), cv2.CAP_FFMPEG)
    try:
        if not capture.isOpened():
            yield Skipped(str(path), "cannot open video")
            return
        fps = capture.get(cv2.CAP_PROP_FPS) or 0.0
        declared = int(capture.get(cv2.CAP_PROP_FRAME_COUNT) or 0)
        first = max(start, after)
        index = _seek(capture, first)
        decoded = 0
        failed: list[int] = []  # kept frames whose grab failed since the last decoded frame
        run = 0  # grabs failed in a row
        while end is None or index < end:
            wanted = index >= first and (index - start) % every == 0
            if not capture.grab():
                if run >= MAX_LOST_RUN or (declared and index >= declared):
                    break
                run += 1
                failed += [index] if wanted else []
                index += 1
                continue
            run = 0
            yield from (_lost(path, k) for k in failed)
            failed = []
            if wanted:
                ok, image = capture.retrieve()
                if not ok or image is None:
                    yield _lost(path, index)
                else:
                    decoded += 1
                    stamp = index / fps if fps > 0 else None
                    yield Frame(
                        image=to_bgr8(image), source=str(path), index=index, timestamp=stamp
                    )
            index += 1
        failed = [k for k in failed if k < declared]
        yield from (_lost(path, k) for k in failed)
        index -= run  # the frames after the last one decoded may not exist
        if decoded == 0 and 0 < index <= start:
            yield Skipped(
                str(path), f"--start {start} is past the end: the video has {index} frames"
            )
        elif decoded == 0 and index <= start and not failed:
            yield Skipped(str(path), "no frames decoded (empty or unreadable video)")
    finally:
        capture.release()


def _lost(path: Path, index: int) -> Skipped:
    """Frame ``index`` of ``path``, which FFmpeg could not decode, as skipped."""
    return Skipped(f"{path}#{index}", "frame could not be decoded (damaged video data)")


def _seek(capture: cv2.VideoCapture, start: int) -> int:
    """Jump to frame ``start`` when the backend can (FFmpeg seeks to the key frame before it and
    decodes forward); returns the index of the next frame to grab: ``start``, or 0 when the
    backend cannot seek and the frames before ``start`` are grabbed and dropped instead."""
    if start <= 0 or int(capture.get(cv2.CAP_PROP_FRAME_COUNT) or 0) <= start:
        return 0
    if capture.set(cv2.CAP_PROP_POS_FRAMES, start) and (
        int(capture.get(cv2.CAP_PROP_POS_FRAMES)) == start
    ):
        return start
    capture.set(cv2.CAP_PROP_POS_FRAMES, 0)
    return 0


def video_frame_count(path: str | os.PathLike) -> int:
    """The frame count a video's container declares (0 when it declares none)."""
    capture = cv2.VideoCapture(str(path), cv2.CAP_FFMPEG)
    try:
        return int(capture.get(cv2.CAP_PROP_FRAME_COUNT) or 0) if capture.isOpened() else 0
    finally:
        capture.release()
