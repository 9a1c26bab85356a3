"""Reading one image file as BGR uint8; missing, empty, truncated or undecodable files raise.

16-bit samples are scaled down, alpha is dropped, grayscale is promoted to three channels
(:func:`to_bgr8`). The error is a :class:`ImageReadError` naming the file and the problem.
"""

from __future__ import annotations

import os
from pathlib import Path

import cv2
import numpy as np
from PIL import Image

from tsrkit.errors import TsrkitError

__all__ = ["MAX_PIXELS", "ImageReadError", "max_pixels", "read_image", "to_bgr8"]

#: Default largest image (decoded pixels) read; ``TSRKIT_MAX_PIXELS`` overrides it.
MAX_PIXELS = 100_000_000


class ImageReadError(TsrkitError):
    """A file that is missing, empty, truncated or not a decodable image."""


def read_image(path: str | os.PathLike) -> np.ndarray:
    """Read an image file as a BGR uint8 array.

    Parameters
    ----------
    path : path-like
        Any format OpenCV decodes (JPEG, PNG incl. 16-bit and RGBA, PPM, BMP, TIFF, WebP...).

    Returns
    -------
    ndarray of shape (H, W, 3), uint8

    Raises
    ------
    ImageReadError
        With the reason: missing, empty, truncated, larger than :func:`max_pixels` (read from
        the header before decoding, so a decompression bomb allocates nothing), or not
        decodable.
    """
    path = Path(path)
    try:
        data = np.fromfile(path, dtype=np.uint8)
    except FileNotFoundError:
        raise ImageReadError(f"{path}: no such file") from None
    except OSError as exc:
        raise ImageReadError(f"{path}: cannot read ({exc.strerror or exc})") from None
    if data.size == 0:
        raise ImageReadError(f"{path}: empty file")
    problem = _truncation(data) or _too_large(path)
    if problem:
        raise ImageReadError(f"{path}: {problem}")
    try:
        image = cv2.imdecode(data, cv2.IMREAD_UNCHANGED)
    except cv2.error as exc:
        raise ImageReadError(
            f"{path}: not decodable ({str(exc).strip().splitlines()[-1]})"
        ) from None
    if image is None or image.size == 0:
        raise ImageReadError(f"{path}: not a decodable image")
    return to_bgr8(image)


def to_bgr8(image: np.ndarray) -> np.ndarray:
    """Convert a decoded image of any depth and channel count to BGR uint8.

    Examples
    --------
    >>> to_bgr8(np.full((1, 1), 65535, np.uint16)).tolist()
    [[[255, 255, 255]]]
    """
    if image.dtype == np.uint16:
        image = (image.astype(np.uint32) * 255 + 32767) // 65535
    elif image.dtype in (np.float32, np.float64):
        image = np.clip(image, 0.0, 1.0) * 255.0 + 0.5
    elif image.dtype != np.uint8:
        raise ImageReadError(f"unsupported sample type {image.dtype}")
    image = image.astype(np.uint8, copy=False)
    if image.ndim == 2:
        return cv2.cvtColor(image, cv2.COLOR_GRAY2BGR)
    channels = image.shape[2]
    if channels == 1:
        return cv2.cvtColor(image[:, :, 0], cv2.COLOR_GRAY2BGR)
    if channels == 4:
        return np.ascontiguousarray(image[:, :, :3])
    return image


def _truncation(data: np.ndarray) -> str | None:
    """Detect the truncated JPEG and PNG files that decoders would silently half-decode."""
    head = data[:8].tobytes()
    tail = data[-4096:].tobytes()
    if head.startswith(b"\xff\xd8") and b"\xff\xd9" not in tail:
        return "truncated JPEG (no end-of-image marker)"
    if head.startswith(b"\x89PNG") and b"IEND" not in tail:
        return "truncated PNG (no IEND chunk)"
    return None


def max_pixels() -> int:
    """The largest image read, in pixels: ``TSRKIT_MAX_PIXELS`` or :data:`MAX_PIXELS`."""
    try:
        return int(os.environ.get("TSRKIT_MAX_PIXELS", MAX_PIXELS))
    except ValueError:
        return MAX_PIXELS


def _too_large(path: Path) -> str | None:
    """The refusal of an image whose header declares more than :func:`max_pixels` pixels."""
    try:
        with Image.open(path) as image:
            width, height = image.size
    except Image.DecompressionBombError as exc:
        return f"refused: {exc}"
    except Exception:  # a header Pillow cannot read: OpenCV decides below
        return None
    if width * height > max_pixels():
        return (
            f"refused: the header declares {width}x{height} = {width * height:,} pixels, more "
            f"than the limit of {max_pixels():,} (TSRKIT_MAX_PIXELS)"
        )
    return None
