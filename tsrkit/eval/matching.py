"""Matching detections to ground-truth boxes: Zheng's centre rule and PASCAL overlap.

``centre_hits`` implements Zheng 2016, 5.2.1 (a candidate is a true positive when its centre lies
in the minimum enclosing circle of a ground-truth box of the same frame); ``iou_matrix`` and
``greedy_match`` implement the overlap test of Lee 3.6.2 (PASCAL, ``tau < area(o & g) / area(o | g)``).
"""
from __future__ import annotations

import numpy as np


def _boxes(boxes) -> np.ndarray:
    array = np.asarray(boxes, dtype=float).reshape(-1, 4)
    if np.any(array[:, 2] < array[:, 0]) or np.any(array[:, 3] < array[:, 1]):
        raise ValueError("boxes must be (x_min, y_min, x_max, y_max) with x_min <= x_max "
                         "and y_min <= y_max")
    return array


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
    b = _boxes(boxes)
    centres = np.column_stack([(b[:, 0] + b[:, 2]) / 2, (b[:, 1] + b[:, 3]) / 2])
    radii = np.hypot(b[:, 2] - b[:, 0], b[:, 3] - b[:, 1]) / 2
    return centres, radii


def centre_hits(points, boxes) -> np.ndarray:
    """Which candidate centres lie in which boxes' minimum enclosing circles (Zheng 5.2.1).

    Parameters
    ----------
    points : array-like of shape (M, 2)
        Candidate centres ``(x, y)``.
    boxes : array-like of shape (N, 4)
        Ground-truth boxes.

    Returns
    -------
    ndarray of bool, shape (M, N)
        ``hits[i, j]`` is True when centre ``i`` is inside (or on) circle ``j``.
    """
    pts = np.asarray(points, dtype=float).reshape(-1, 2)
    centres, radii = enclosing_circles(boxes)
    dist = np.hypot(pts[:, None, 0] - centres[None, :, 0], pts[:, None, 1] - centres[None, :, 1])
    return dist <= radii[None, :]


def iou_matrix(boxes_a, boxes_b) -> np.ndarray:
    """Intersection over union of every box of ``boxes_a`` with every box of ``boxes_b``.

    Areas are continuous (``(x_max - x_min) * (y_max - y_min)``), as in COCO.

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


def box_areas(boxes) -> np.ndarray:
    """Areas of boxes ``(x_min, y_min, x_max, y_max)``."""
    b = _boxes(boxes)
    return (b[:, 2] - b[:, 0]) * (b[:, 3] - b[:, 1])


def intersection_matrix(boxes_a, boxes_b) -> np.ndarray:
    """Area of the intersection of every pair of boxes."""
    a, b = _boxes(boxes_a), _boxes(boxes_b)
    width = np.minimum(a[:, None, 2], b[None, :, 2]) - np.maximum(a[:, None, 0], b[None, :, 0])
    height = np.minimum(a[:, None, 3], b[None, :, 3]) - np.maximum(a[:, None, 1], b[None, :, 1])
    return np.clip(width, 0, None) * np.clip(height, 0, None)


def greedy_match(scores, affinity, threshold: float, strict: bool = True) -> list[tuple[int, int]]:
    """Match detections to ground truth greedily, best score first (PASCAL / COCO style).

    Each detection, in order of decreasing score, takes the still unmatched ground-truth box
    with the highest affinity, if that affinity passes the threshold.

    Parameters
    ----------
    scores : array-like of shape (M,)
        Detection scores.
    affinity : ndarray of shape (M, N)
        IoU (or a boolean hit matrix cast to float).
    threshold : float
        Lee 3.6.2's ``tau``.
    strict : bool
        ``affinity > threshold`` when True (Lee's ``tau <`` ...), ``>=`` otherwise.

    Returns
    -------
    list of (detection index, ground-truth index)
    """
    affinity = np.asarray(affinity, dtype=float)
    order = np.argsort(-np.asarray(scores, dtype=float), kind="stable")
    free = np.ones(affinity.shape[1], dtype=bool)
    pairs = []
    for i in order:
        row = np.where(free, affinity[i], -np.inf)
        if row.size == 0:
            break
        j = int(np.argmax(row))
        if row[j] > threshold or (not strict and row[j] >= threshold):
            free[j] = False
            pairs.append((int(i), j))
    return sorted(pairs)
