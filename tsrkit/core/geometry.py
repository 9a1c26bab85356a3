"""Boxes and circles in pixels: conversions, areas, IoU, clipping, minimum enclosing circles.

Every box in tsrkit is ``(x_min, y_min, x_max, y_max)`` (x right, y down); COCO's
``[x, y, width, height]`` exists only at the file boundary (:func:`xyxy_to_xywh`,
:func:`xywh_to_xyxy`). Array functions take any ``(N, 4)`` array-like and return NumPy arrays.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

__all__ = [
    "Box",
    "as_boxes",
    "box_areas",
    "box_centre",
    "circle_box",
    "clip_box",
    "enclosing_circles",
    "inscribed_circle",
    "intersection_matrix",
    "iou_matrix",
    "xywh_to_xyxy",
    "xyxy_to_xywh",
]

Box = tuple[float, float, float, float]


def as_boxes(boxes) -> np.ndarray:
    """``boxes`` as a float array of shape ``(N, 4)``; a plain ``ValueError`` for inverted ones.

    Examples
    --------
    >>> as_boxes([(0, 0, 2, 3)]).tolist()
    [[0.0, 0.0, 2.0, 3.0]]
    """
    array = np.asarray(boxes, dtype=float).reshape(-1, 4)
    if np.any(array[:, 2] < array[:, 0]) or np.any(array[:, 3] < array[:, 1]):
        raise ValueError(
            "boxes must be (x_min, y_min, x_max, y_max) with x_min <= x_max and y_min <= y_max"
        )
    return array


def xyxy_to_xywh(box: Sequence[float]) -> list[float]:
    """``(x_min, y_min, x_max, y_max)`` to COCO's ``[x, y, width, height]``.

    Width and height are the shortest decimals that add back to ``x_max`` and ``y_max``
    exactly, so that a COCO box read (:func:`xywh_to_xyxy`) and written again keeps its numbers
    (``0.3 - 0.1`` is ``0.19999999999999998``; the width written is ``0.2``).

    Examples
    --------
    >>> xyxy_to_xywh((1, 2, 4, 6))
    [1.0, 2.0, 3.0, 4.0]
    >>> xyxy_to_xywh(xywh_to_xyxy(0.1, 0.7, 0.2, 0.1))
    [0.1, 0.7, 0.2, 0.1]
    """
    x0, y0, x1, y1 = (float(v) for v in box)
    return [x0, y0, _span(x0, x1), _span(y0, y1)]


def _span(start: float, end: float) -> float:
    """``end - start`` in the fewest decimals for which ``start + span == end``."""
    exact = end - start
    for digits in range(18):
        short = round(exact, digits)
        if start + short == end:
            return short
    return exact


def xywh_to_xyxy(x: float, y: float, w: float, h: float) -> Box:
    """COCO's ``[x, y, width, height]`` to ``(x_min, y_min, x_max, y_max)``.

    Examples
    --------
    >>> xywh_to_xyxy(1, 2, 3, 4)
    (1.0, 2.0, 4.0, 6.0)
    """
    return float(x), float(y), float(x) + float(w), float(y) + float(h)


def circle_box(x: float, y: float, radius: float) -> Box:
    """The box circumscribing the circle ``(x, y, radius)``.

    Examples
    --------
    >>> circle_box(5, 5, 2)
    (3.0, 3.0, 7.0, 7.0)
    """
    return float(x - radius), float(y - radius), float(x + radius), float(y + radius)


def inscribed_circle(box: Sequence[float]) -> tuple[float, float, float]:
    """Centre and radius of the largest circle centred in ``box`` (half its shorter side).

    Examples
    --------
    >>> inscribed_circle((0, 0, 4, 2))
    (2.0, 1.0, 1.0)
    """
    x0, y0, x1, y1 = (float(v) for v in box)
    return (x0 + x1) / 2, (y0 + y1) / 2, min(x1 - x0, y1 - y0) / 2


def box_centre(box: Sequence[float]) -> tuple[float, float]:
    """Centre of ``box``."""
    x0, y0, x1, y1 = box
    return (x0 + x1) / 2, (y0 + y1) / 2


def enclosing_circles(boxes) -> tuple[np.ndarray, np.ndarray]:
    """Minimum enclosing circles of axis-aligned boxes (Zheng 5.2.1).

    The smallest circle holding a rectangle is centred on it with half its diagonal as radius.

    Returns
    -------
    centres : ndarray of shape (N, 2)
    radii : ndarray of shape (N,)

    Examples
    --------
    >>> centres, radii = enclosing_circles([(0, 0, 6, 8)])
    >>> centres.tolist(), radii.tolist()
    ([[3.0, 4.0]], [5.0])
    """
    b = as_boxes(boxes)
    centres = np.column_stack([(b[:, 0] + b[:, 2]) / 2, (b[:, 1] + b[:, 3]) / 2])
    radii = np.hypot(b[:, 2] - b[:, 0], b[:, 3] - b[:, 1]) / 2
    return centres, radii


def box_areas(boxes) -> np.ndarray:
    """Areas of boxes (continuous, ``(x_max - x_min) * (y_max - y_min)``, as in COCO)."""
    b = as_boxes(boxes)
    return (b[:, 2] - b[:, 0]) * (b[:, 3] - b[:, 1])


def intersection_matrix(boxes_a, boxes_b) -> np.ndarray:
    """Area of the intersection of every pair of boxes."""
    a, b = as_boxes(boxes_a), as_boxes(boxes_b)
    width = np.minimum(a[:, None, 2], b[None, :, 2]) - np.maximum(a[:, None, 0], b[None, :, 0])
    height = np.minimum(a[:, None, 3], b[None, :, 3]) - np.maximum(a[:, None, 1], b[None, :, 1])
    return np.clip(width, 0, None) * np.clip(height, 0, None)


def iou_matrix(boxes_a, boxes_b) -> np.ndarray:
    """Intersection over union of every box of ``boxes_a`` with every box of ``boxes_b``.

    Examples
    --------
    >>> iou_matrix([(0, 0, 2, 2)], [(1, 0, 3, 2), (5, 5, 6, 6)]).round(4).tolist()
    [[0.3333, 0.0]]
    """
    inter = intersection_matrix(boxes_a, boxes_b)
    area_a, area_b = box_areas(boxes_a), box_areas(boxes_b)
    union = area_a[:, None] + area_b[None, :] - inter
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(union > 0, inter / union, 0.0)


def clip_box(box: Sequence[float], width: int, height: int) -> tuple[int, int, int, int]:
    """Integer pixel bounds of ``box`` inside a ``width`` x ``height`` image (end exclusive).

    Examples
    --------
    >>> clip_box((-2.4, 3.6, 10.2, 50), 8, 20)
    (0, 3, 8, 20)
    """
    x0, y0, x1, y1 = box
    return (
        max(0, int(np.floor(x0))),
        max(0, int(np.floor(y0))),
        min(width, int(np.ceil(x1))),
        min(height, int(np.ceil(y1))),
    )
