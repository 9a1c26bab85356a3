"""Reading images, folders and videos into frames; unusable inputs become :class:`Skipped`.

Images are returned as BGR uint8 whatever their file holds: 16-bit samples are scaled down,
alpha is dropped, grayscale is promoted to three channels. Videos are decoded with OpenCV's
FFmpeg backend.
"""

from __future__ import annotations

import os
from collections.abc import Iterable, Iterator
from pathlib import Path

import cv2

from tsrkit.images import ImageReadError, read_image, to_bgr8
from tsrkit.types import Frame, Skipped

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
    """Files named directly, and every non-hidden file below each folder, sorted."""
    for given in paths:
        path = Path(given)
        if path.is_dir():
            for root, dirs, files in os.walk(path):
                dirs[:] = sorted(d for d in dirs if not d.startswith("."))
                for name in sorted(files):
                    if not name.startswith("."):
                        yield Path(root) / name
        elif path.exists():
            yield path
        else:
            yield Skipped(str(path), "no such file or folder")


def iter_frames(
    paths: Iterable[str | os.PathLike], every: int = 1, start: int = 0, end: int | None = None
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
    """
    if every < 1 or start < 0 or (end is not None and end < start):
        raise ValueError("need every >= 1, start >= 0 and end >= start")
    for item in expand_paths(paths):
        if isinstance(item, Skipped):
            yield item
            continue
        suffix = item.suffix.lower()
        if suffix in VIDEO_EXTENSIONS:
            yield from iter_video(item, every, start, end)
        elif suffix in IMAGE_EXTENSIONS:
            try:
                yield Frame(image=read_image(item), source=str(item))
            except ImageReadError as exc:
                yield Skipped(str(item), str(exc).removeprefix(f"{item}: "))
        else:
            yield Skipped(str(item), f"not an image or video (unsupported type '{suffix}')")


def iter_video(
    path: Path, every: int = 1, start: int = 0, end: int | None = None
) -> Iterator[Frame | Skipped]:
    """Decode ``path`` frame by frame, keeping frames ``start, start+every, ...`` before ``end``."""
    capture = cv2.VideoCapture(str(path), cv2.CAP_FFMPEG)
    try:
        if not capture.isOpened():
            yield Skipped(str(path), "cannot open video")
            return
        fps = capture.get(cv2.CAP_PROP_FPS) or 0.0
        index = 0
        decoded = 0
        while end is None or index < end:
            wanted = index >= start and (index - start) % every == 0
            if not capture.grab():
                break
            if wanted:
                ok, image = capture.retrieve()
                if not ok or image is None:
                    yield Skipped(f"{path}#{index}", "frame could not be decoded")
                else:
                    decoded += 1
                    stamp = index / fps if fps > 0 else None
                    yield Frame(
                        image=to_bgr8(image), source=str(path), index=index, timestamp=stamp
                    )
            index += 1
        if decoded == 0 and index <= start:
            yield Skipped(str(path), "no frames decoded (empty or unreadable video)")
    finally:
        capture.release()
