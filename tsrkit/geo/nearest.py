"""Nearest signalised intersection of every position (Zheng 2016, 3.4.2): the basic k-d tree
query and Zheng's "extended k-d tree" recursion with tau_min.

The extended method rests on Condition 3-1: when two positions have the same nearest
intersection and lie less than ``tau_min`` seconds apart, every position between them has it
too (a vehicle stays longer than ``tau_min`` in any intersection's Voronoi region). So the tree
is asked only for the two ends of a batch of positions; if the condition holds, the batch is
filled without a search, else the middle position is searched and the batch split in two.
Zheng's cost is O((N_T + N_Q / F(tau_min)) log N_T), F(tau_min) the positions in tau_min.

The recursion here visits its tree level by level, all batches of a level with one vectorised
query, instead of depth first: the same batches, searches and answers, without a Python call
per batch. Condition 3-1 is an assumption about the drive, not a theorem: a path that leaves
a region and re-enters it within ``tau_min`` (clipping a corner) gets the region's
intersection where the basic query would name the other; ``benchmarks/bench_vicinity.py``
counts such positions.
"""

from __future__ import annotations

import numpy as np
from scipy.spatial import cKDTree

__all__ = ["TAU_MIN", "nearest_extended", "nearest_kdtree"]

#: Zheng's conservative minimum stay in a Voronoi region (3.4.2), seconds.
TAU_MIN = 1.5


def nearest_kdtree(tree: cKDTree, points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Index of the nearest tree point to every row of ``points`` (N x 2), and its distance:
    one query per position (Zheng's basic k-d tree method)."""
    distance, index = tree.query(points)
    return np.asarray(index, np.int64), np.asarray(distance)


def nearest_extended(
    tree: cKDTree, points: np.ndarray, times: np.ndarray, tau_min: float = TAU_MIN
) -> tuple[np.ndarray, np.ndarray]:
    """:func:`nearest_kdtree`'s answer from searches at batch ends only (see the module notes).

    ``times`` (seconds, increasing) go with ``points``; a batch is filled from its ends when
    they share their intersection and lie less than ``tau_min`` apart.

    >>> tree = cKDTree([[0.0, 0.0], [100.0, 0.0]])
    >>> points = np.column_stack([np.arange(0.0, 100.0, 10.0), np.zeros(10)])
    >>> nearest_extended(tree, points, np.arange(10.0), tau_min=4.5)[0]
    array([0, 0, 0, 0, 0, 0, 1, 1, 1, 1])
    """
    points = np.asarray(points, np.float64)
    times = np.asarray(times, np.float64)
    n = len(points)
    index = np.full(n, -1, np.int64)
    if n == 0:
        return index, np.zeros(0)
    ends = np.unique([0, n - 1])
    index[ends] = tree.query(points[ends])[1]
    lo, hi = np.array([0]), np.array([n - 1])
    while len(lo):
        open_ = hi - lo > 1  # a batch with positions between its ends
        filled = (index[lo] == index[hi]) & (times[hi] - times[lo] < tau_min)
        split = open_ & ~filled
        lo, hi = lo[split], hi[split]
        middle = (lo + hi) // 2
        if len(middle):
            index[middle] = tree.query(points[middle])[1]
        lo, hi = np.concatenate([lo, middle]), np.concatenate([middle, hi])
    # every position left is inside a filled batch, whose left end is the last search before it
    index = index[np.maximum.accumulate(np.where(index >= 0, np.arange(n), 0))]
    target = tree.data[index]
    return index, np.hypot(points[:, 0] - target[:, 0], points[:, 1] - target[:, 1])
