"""Frames as one MPEG-4 video: a synthetic dataset's (``detect VIDEO``) or a rendered drive's,
streamed to the file and published atomically."""

from __future__ import annotations

import contextlib
import os
import tempfile
from collections.abc import Callable, Iterator
from pathlib import Path

import cv2
import numpy as np

from tsrkit.core.errors import TsrkitError
from tsrkit.core.types import Dataset

__all__ = ["video_writer", "write_video"]


@contextlib.contextmanager
def video_writer(
    path: str | os.PathLike, fps: float, size: tuple[int, int]
) -> Iterator[Callable[[np.ndarray], None]]:
    """Yield a function that appends one BGR frame of ``size`` (width, height) to an MPEG-4
    video; the file appears at ``path`` only when the block ends without an exception.

    Raises
    ------
    TsrkitError
        When OpenCV cannot write the file or a frame has another size.
    """
    path = Path(path)
    width, height = size
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(
        prefix=f".{path.stem}.", suffix=path.suffix or ".mp4", dir=path.parent
    )
    os.close(fd)
    writer = cv2.VideoWriter(tmp, cv2.VideoWriter.fourcc(*"mp4v"), fps, (width, height))

    def write(image: np.ndarray) -> None:
        if image.shape[:2] != (height, width):
            raise TsrkitError(f"{path}: a frame is not {width}x{height}")
        writer.write(image)

    try:
        if not writer.isOpened():
            raise TsrkitError(f"{path}: OpenCV cannot write an MPEG-4 video here")
        yield write
        writer.release()
        os.replace(tmp, path)
    except BaseException:
        writer.release()
        with contextlib.suppress(FileNotFoundError):
            os.unlink(tmp)
        raise


def write_video(dataset: Dataset, path: str | os.PathLike, fps: float = 10.0) -> Path:
    """Write every frame of ``dataset``, in order, as an MPEG-4 video at ``path`` (atomically).

    Raises
    ------
    TsrkitError
        When the dataset is empty, frames differ in size, or OpenCV cannot write the file.
    """
    path = Path(path)
    if not len(dataset):
        raise TsrkitError(f"{path}: no frames to write")
    first = dataset.samples[0].load().image
    height, width = first.shape[:2]
    with video_writer(path, fps, (width, height)) as write:
        for sample in dataset:
            image = sample.load().image
            if image.shape[:2] != (height, width):
                raise TsrkitError(f"{path}: frame {sample.source} is not {width}x{height}")
            write(image)
    return path
