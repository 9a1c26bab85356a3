"""Box sums over an integral image: the one primitive of the housing search and the lens
measurement (every mean a handful of look-ups, whatever the box's size).

A box's sum is compiled (:func:`box_sum`), called box by box from the compiled searches of
:mod:`.fit` and :mod:`.lens` (the housing stage asks for some 60,000 boxes per frame at 50
candidates: NumPy's rounding, clipping and four gathers over them, each a temporary array,
took about 1.4 of its 3.4 ms, benchmarks/RESULTS.housing.md), or for an array of boxes at once
(:func:`box_sums`). The result is the NumPy definition's to the bit
(``tests/verifiers/test_housing_lens.py``).
"""

from __future__ import annotations

import cv2
import numpy as np
from numba import njit


def integral(gray: np.ndarray) -> np.ndarray:
    """int32 (H + 1, W + 1) integral image of a grey uint8 image (exact up to 8 MP)."""
    return cv2.integral(gray, sdepth=cv2.CV_32S)


@njit(cache=True, nogil=True, inline="always")
def pixel(value: float, limit: int) -> int:
    """``value`` rounded half to even (``np.rint``) and clipped to ``[0, limit]``; NaN gives 0
    (the compiled look-ups have no bounds check: a box a plugin got wrong must not read
    outside the table)."""
    rounded = np.rint(value)
    if not rounded > 0.0:  # also NaN
        return 0
    return limit if rounded >= limit else int(rounded)


@njit(cache=True, nogil=True, inline="always")
def box_sum(
    table: np.ndarray, x0: float, y0: float, x1: float, y1: float
) -> tuple[np.int32, float]:
    """The sum (int32) and pixel count (float64) of one box: each corner rounded and clipped
    to the image (:func:`pixel`), the far edges no nearer than the near ones, then the four
    look-ups of the int32 ``table``."""
    height, width = table.shape[0] - 1, table.shape[1] - 1
    left = pixel(x0, width)
    top = pixel(y0, height)
    right = max(pixel(x1, width), left)
    bottom = max(pixel(y1, height), top)
    total = table[bottom, right] - table[top, right] - table[bottom, left] + table[top, left]
    return np.int32(total), float((right - left) * (bottom - top))


@njit(cache=True, nogil=True, inline="always")
def box_mean(table: np.ndarray, x0: float, y0: float, x1: float, y1: float) -> float:
    """The mean grey level of one box (0 for an empty box; see :func:`box_sum`)."""
    total, count = box_sum(table, x0, y0, x1, y1)
    return total / max(count, 1.0)


@njit(cache=True, nogil=True)
def sum_boxes(table: np.ndarray, boxes: np.ndarray, total: np.ndarray, count: np.ndarray) -> None:
    """Fill ``total`` (int32) and ``count`` (float64) for the (N, 4) ``boxes``
    (:func:`box_sum` each)."""
    for i in range(boxes.shape[0]):
        total[i], count[i] = box_sum(table, boxes[i, 0], boxes[i, 1], boxes[i, 2], boxes[i, 3])


def box_sums(table: np.ndarray, boxes: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Sums (in the int32 table's type) and pixel counts of ``boxes`` (..., 4) as
    (x0, y0, x1, y1), rounded to pixels and clipped to the image."""
    flat = np.ascontiguousarray(boxes, np.float64).reshape(-1, 4)
    total = np.empty(len(flat), table.dtype)
    count = np.empty(len(flat), np.float64)
    sum_boxes(table, flat, total, count)
    shape = np.shape(boxes)[:-1]
    return total.reshape(shape), count.reshape(shape)
