"""Matching detections to ground-truth boxes: Zheng's centre rule and PASCAL overlap.

``centre_hits`` implements Zheng 2016, 5.2.1 (a candidate is a true positive when its centre lies
in the minimum enclosing circle of a ground-truth box of the same frame); ``greedy_match`` with
:func:`tsrkit.core.geometry.iou_matrix` implements the overlap test of Lee 3.6.2 (PASCAL,
``tau < area(o & g) / area(o | g)``). Box geometry lives in :mod:`tsrkit.core.geometry`.
"""

from __future__ import annotations

import numpy as np

from tsrkit.core.geometry import enclosing_circles

__all__ = ["centre_hits", "greedy_match"]


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
