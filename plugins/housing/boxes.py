"""Box sums over an integral image: the one primitive of the housing search and the lens
measurement (every mean a handful of look-ups, whatever the box's size)."""

from __future__ import annotations

import cv2
import numpy as np


def integral(gray: np.ndarray) -> np.ndarray:
    """int32 (H + 1, W + 1) integral image of a grey uint8 image (exact up to 8 MP)."""
    return cv2.integral(gray, sdepth=cv2.CV_32S)


def box_sums(table: np.ndarray, boxes: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Sums (in the table's integer type) and pixel counts of ``boxes`` (..., 4) as
    (x0, y0, x1, y1), rounded to pixels and clipped to the image."""
    height, width = table.shape[0] - 1, table.shape[1] - 1
    corners = np.rint(boxes)
    np.clip(corners, 0.0, np.array([width, height, width, height], np.float64), out=corners)
    corners = corners.astype(np.intp)
    x0, y0, x1, y1 = (corners[..., k] for k in range(4))
    np.maximum(x1, x0, out=x1)
    np.maximum(y1, y0, out=y1)
    flat, stride = table.ravel(), width + 1
    top, bottom = y0 * stride, y1 * stride
    total = flat[bottom + x1] - flat[top + x1] - flat[bottom + x0] + flat[top + x0]
    return total, ((x1 - x0) * (y1 - y0)).astype(np.float64)


def box_means(table: np.ndarray, boxes: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Mean grey levels (0 for an empty box) and pixel counts of ``boxes`` (see
    :func:`box_sums`)."""
    total, count = box_sums(table, boxes)
    return total / np.maximum(count, 1), count
