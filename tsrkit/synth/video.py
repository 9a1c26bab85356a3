"""A synthetic dataset's frames as one video, for trying video commands (``detect VIDEO``)."""

from __future__ import annotations

import contextlib
import os
import tempfile
from pathlib import Path

import cv2

from tsrkit.errors import TsrkitError
from tsrkit.types import Dataset


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
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(
        prefix=f".{path.stem}.", suffix=path.suffix or ".mp4", dir=path.parent
    )
    os.close(fd)
    writer = cv2.VideoWriter(tmp, cv2.VideoWriter.fourcc(*"mp4v"), fps, (width, height))
    try:
        if not writer.isOpened():
            raise TsrkitError(f"{path}: OpenCV cannot write an MPEG-4 video here")
        for sample in dataset:
            image = sample.load().image
            if image.shape[:2] != (height, width):
                raise TsrkitError(f"{path}: frame {sample.source} is not {width}x{height}")
            writer.write(image)
        writer.release()
        os.replace(tmp, path)
    except BaseException:
        writer.release()
        with contextlib.suppress(FileNotFoundError):
            os.unlink(tmp)
        raise
    return path
