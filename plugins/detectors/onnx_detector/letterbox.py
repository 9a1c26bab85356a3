"""Letterbox preprocessing, its exact inverse, and the tiles of a large frame.

The letterbox is Ultralytics' (``ultralytics.data.augment.LetterBox`` at inference): the
frame is resized by ``r = min(H / h, W / w)`` to ``round(w r) x round(h r)`` pixels
(``cv2.INTER_LINEAR``), padded with grey 114 to the model's ``W x H``, ``round(d - 0.1)``
pixels before and ``round(d + 0.1)`` after on each axis (``d`` half the axis' slack), turned
from BGR to RGB, scaled by 1/255 and laid out NCHW in float32.

Boxes come back to the frame by the inverse of that map in the continuous pixel convention
(an edge at ``x`` in the frame lands at ``x * w' / w + left`` in the model's input, ``w'``
the resized width): ``x = (x' - left) * w / w'``, with each axis' own exact factor rather than
``1 / r`` (the two differ by the rounding of ``w r``).
"""

from __future__ import annotations

from dataclasses import dataclass

import cv2
import numpy as np

#: The grey the letterbox pads with (Ultralytics' value).
PAD_GREY = 114


@dataclass(frozen=True)
class Letterbox:
    """Where a letterboxed image sits in the model's input.

    Parameters
    ----------
    left, top : int
        Padding before the image, in input pixels.
    scale_x, scale_y : float
        Resized size over original size, per axis (``w' / w``, ``h' / h``).
    """

    left: int
    top: int
    scale_x: float
    scale_y: float

    def to_image(self, boxes: np.ndarray) -> np.ndarray:
        """``(N, 4)`` xyxy boxes in input pixels mapped to the letterboxed image's pixels.

        Examples
        --------
        >>> box = Letterbox(left=0, top=80, scale_x=0.5, scale_y=0.5)
        >>> box.to_image(np.array([[10.0, 90.0, 20.0, 100.0]])).tolist()
        [[20.0, 20.0, 40.0, 40.0]]
        """
        offset = np.array([self.left, self.top, self.left, self.top], np.float64)
        scale = np.array([self.scale_x, self.scale_y, self.scale_x, self.scale_y], np.float64)
        return (np.asarray(boxes, np.float64) - offset) / scale


def letterbox(image: np.ndarray, size: tuple[int, int]) -> tuple[np.ndarray, Letterbox]:
    """The ``(1, 3, H, W)`` float32 RGB input in [0, 1] of a BGR ``image`` for a model of
    input ``size = (H, W)``, and where the image sits in it.

    Examples
    --------
    >>> tensor, box = letterbox(np.zeros((100, 200, 3), np.uint8), (64, 64))
    >>> tensor.shape, box
    ((1, 3, 64, 64), Letterbox(left=0, top=16, scale_x=0.32, scale_y=0.32))
    >>> round(float(tensor[0, 0, 0, 0]) * 255, 3)  # the grey padding
    114.0
    """
    height, width = image.shape[:2]
    target_h, target_w = size
    ratio = min(target_h / height, target_w / width)
    new_w, new_h = round(width * ratio), round(height * ratio)
    if (new_w, new_h) != (width, height):
        image = cv2.resize(image, (new_w, new_h), interpolation=cv2.INTER_LINEAR)
    dw, dh = (target_w - new_w) / 2, (target_h - new_h) / 2
    top, bottom = round(dh - 0.1), round(dh + 0.1)
    left, right = round(dw - 0.1), round(dw + 0.1)
    padded = cv2.copyMakeBorder(
        image, top, bottom, left, right, cv2.BORDER_CONSTANT, value=(PAD_GREY,) * 3
    )
    rgb = padded[:, :, ::-1].transpose(2, 0, 1)[None]
    tensor = np.ascontiguousarray(rgb, dtype=np.float32) / np.float32(255)
    return tensor, Letterbox(left, top, new_w / width, new_h / height)


def tile_origins(length: int, tile: int, overlap: float) -> list[int]:
    """Start offsets of tiles of ``tile`` pixels covering ``length`` pixels, overlapping by at
    least ``overlap`` of a tile; the last tile ends at the edge.

    Examples
    --------
    >>> tile_origins(1000, 400, 0.25)
    [0, 300, 600]
    >>> tile_origins(300, 400, 0.25)
    [0]
    """
    if length <= tile:
        return [0]
    stride = max(1, int(tile * (1 - overlap)))
    starts = list(range(0, length - tile, stride))
    return [*starts, length - tile]


def tiles(width: int, height: int, tile: int, overlap: float) -> list[tuple[int, int, int, int]]:
    """The ``(x0, y0, x1, y1)`` tiles of a ``width x height`` frame (row by row).

    Examples
    --------
    >>> tiles(700, 300, 400, 0.25)
    [(0, 0, 400, 300), (300, 0, 700, 300)]
    """
    return [
        (x, y, min(x + tile, width), min(y + tile, height))
        for y in tile_origins(height, tile, overlap)
        for x in tile_origins(width, tile, overlap)
    ]
