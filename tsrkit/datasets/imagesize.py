"""Image width and height from the file header, without decoding the pixels."""

from __future__ import annotations

import os

from PIL import Image, UnidentifiedImageError

from tsrkit.datasets.errors import DatasetError

__all__ = ["image_size"]


def image_size(path: str | os.PathLike) -> tuple[int, int]:
    """``(width, height)`` of the image at ``path``, read from its header by Pillow, upright:
    swapped when its EXIF orientation turns it by 90 degrees (as
    :func:`tsrkit.core.images.read_image` does).

    Raises
    ------
    DatasetError
        When the file is missing or not an image Pillow recognises.
    """
    try:
        with Image.open(path) as image:
            turned = image.getexif().get(0x0112) in (5, 6, 7, 8)  # 0x0112: Orientation
            size = int(image.width), int(image.height)
    except FileNotFoundError:
        raise DatasetError(path, "image not found (needed for its size)") from None
    except (UnidentifiedImageError, OSError) as exc:
        raise DatasetError(path, f"cannot read image size ({exc})") from None
    return (size[1], size[0]) if turned else size
