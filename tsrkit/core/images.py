"""Reading one image file as BGR uint8; missing, empty, truncated or undecodable files raise.

16-bit samples are scaled down, alpha is dropped, grayscale is promoted to three channels
(:func:`to_bgr8`); an EXIF orientation (a phone's upright flag) is applied, as viewers and
``PIL.ImageOps.exif_transpose`` do, and a GIF gives its first frame. The error is a
:class:`ImageReadError` naming the file and the problem.
"""

from __future__ import annotations

import os
from pathlib import Path

import cv2
import numpy as np
from PIL import Image

from tsrkit.core.errors import TsrkitError
from tsrkit.core.files import InputFileError, file_size

__all__ = ["MAX_PIXELS", "ImageReadError", "max_file_bytes", "max_pixels", "read_image", "to_bgr8"]

#: Default largest image (decoded pixels) read; ``TSRKIT_MAX_PIXELS`` overrides it.
MAX_PIXELS = 100_000_000


class ImageReadError(TsrkitError):
    """A file that is missing, empty, truncated or not a decodable image."""


def read_image(path: str | os.PathLike) -> np.ndarray:
    """Read an image file as a BGR uint8 array.

    Parameters
    ----------
    path : path-like
        Any format OpenCV decodes (JPEG, PNG incl. 16-bit and RGBA, PPM, BMP, TIFF, WebP,
        GIF...).

    Returns
    -------
    ndarray of shape (H, W, 3), uint8
        Upright: turned and mirrored as the file's EXIF orientation says.

    Raises
    ------
    ImageReadError
        With the reason: missing, not a regular file (a FIFO or device would block or never
        end), a file larger than :func:`max_file_bytes` (checked before reading), empty,
        truncated, larger than :func:`max_pixels` (read from the header before decoding, so a
        decompression bomb allocates nothing), or not decodable.
    """
    path = Path(path)
    try:
        file_size(path, max_file_bytes())
    except InputFileError as exc:
        raise ImageReadError(f"{path}: {exc.problem}") from None
    try:
        data = np.fromfile(path, dtype=np.uint8)
    except OSError as exc:
        raise ImageReadError(f"{path}: cannot read ({exc.strerror or exc})") from None
    if data.size == 0:
        raise ImageReadError(f"{path}: empty file")
    problem = _truncation(data) or _too_large(path)
    if problem:
        raise ImageReadError(f"{path}: {problem}")
    try:
        # any depth and colour, with the EXIF orientation applied (IMREAD_UNCHANGED ignores it)
        image = cv2.imdecode(data, cv2.IMREAD_ANYDEPTH | cv2.IMREAD_ANYCOLOR)
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
    """Detect the truncated JPEG and PNG files that decoders would silently half-decode.

    The file's own structure is followed (PNG chunks to ``IEND``; JPEG segments to the first
    scan, then the end-of-image marker), so bytes after the end marker, which phones append
    (maker notes, depth maps, a second picture), are accepted, and the end marker of an
    embedded thumbnail does not hide a cut-off main image.
    """
    head = data[:8].tobytes()
    if head.startswith(b"\x89PNG\r\n\x1a\n"):
        return None if _png_ends(data) else "truncated PNG (no IEND chunk)"
    if head.startswith(b"\xff\xd8"):
        return None if _jpeg_ends(data) else "truncated JPEG (no end-of-image marker)"
    return None


def _png_ends(data: np.ndarray) -> bool:
    """Whether the PNG's chunk chain reaches ``IEND`` inside ``data``."""
    at = 8
    while at + 8 <= data.size:
        if data[at + 4 : at + 8].tobytes() == b"IEND":
            return True
        at += 12 + int.from_bytes(data[at : at + 4].tobytes(), "big")
    return False


def _jpeg_ends(data: np.ndarray) -> bool:
    """Whether a JPEG's marker segments lead to a scan that an end-of-image marker closes.

    Segments before the first scan (SOS) carry their length and are skipped whole, so an EXIF
    thumbnail's own end marker is not taken for the image's; inside entropy-coded data every
    0xFF byte is stuffed or a marker, so the first FF D9 after the scan header ends the image.
    """
    at = 2
    while at + 4 <= data.size:
        if data[at] != 0xFF:
            return False
        marker = int(data[at + 1])
        if marker == 0xFF:  # a fill byte before a marker
            at += 1
        elif marker == 0xD9:
            return True
        elif 0xD0 <= marker <= 0xD7 or marker == 0x01:  # markers without a length
            at += 2
        elif marker == 0xDA:
            return data[at + 2 :].tobytes().find(b"\xff\xd9") >= 0
        else:
            at += 2 + (int(data[at + 2]) << 8 | int(data[at + 3]))
    return False


def max_pixels() -> int:
    """The largest image read, in pixels: ``TSRKIT_MAX_PIXELS`` or :data:`MAX_PIXELS`.

    Raises
    ------
    TsrkitError
        When ``TSRKIT_MAX_PIXELS`` is set to something other than a positive integer.
    """
    given = os.environ.get("TSRKIT_MAX_PIXELS")
    if given is None:
        return MAX_PIXELS
    try:
        value = int(given)
    except ValueError:
        value = 0
    if value < 1:
        raise TsrkitError(f"TSRKIT_MAX_PIXELS must be a positive integer; got {given!r}")
    return value


def max_file_bytes() -> int:
    """The largest image file read, in bytes: an uncompressed image of :func:`max_pixels`
    pixels at 16 bits and four channels, plus 64 MiB of metadata."""
    return 8 * max_pixels() + 64 * 2**20


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
