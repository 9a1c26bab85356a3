"""A synthetic city and drive in local metres, for testing and timing the vicinity methods
(Zheng 2016, 3.4.2) at scales no real drive here reaches.

The city is a square grid of signalised intersections; the drive follows the streets, turning at
random, waiting at some intersections; its 1 Hz GPS fixes carry Gaussian noise and are
interpolated linearly to frame times (Eq. 4.2), as the framework does with a real log.
"""

from __future__ import annotations

import numpy as np

__all__ = ["grid_city", "grid_drive"]

_STEPS = np.array([[1, 0], [0, 1], [-1, 0], [0, -1]])


def grid_city(side: int, spacing: float = 200.0, jitter: float = 10.0, seed: int = 0) -> np.ndarray:
    """``side`` x ``side`` intersections ``spacing`` metres apart, each moved by up to
    ``jitter`` metres (mapped signal nodes are rarely at the junction's centre): (N, 2) x, y.

    >>> grid_city(3, jitter=0.0)[4]
    array([200., 200.])
    """
    rng = np.random.default_rng(seed)
    i, j = np.meshgrid(np.arange(side), np.arange(side), indexing="ij")
    grid = np.column_stack([i.ravel(), j.ravel()]) * spacing
    return grid + rng.uniform(-jitter, jitter, grid.shape)


def grid_drive(
    side: int,
    frames: int,
    fps: float = 14.0,
    spacing: float = 200.0,
    noise: float = 2.0,
    seed: int = 0,
) -> tuple[np.ndarray, np.ndarray]:
    """Frame times (seconds) and positions (``frames`` x 2, metres) of a drive through
    :func:`grid_city`'s streets: 8-18 m/s per block, a 0-40 s wait at a third of the
    intersections, no U-turns."""
    rng = np.random.default_rng(seed)
    seconds = frames / fps + 2
    node, heading = np.array([side // 2, side // 2]), 0
    corners, times, clock = [node * spacing], [0.0], 0.0
    while clock < seconds:
        if rng.random() < 1 / 3:
            clock += rng.uniform(0, 40)
            corners.append(node * spacing)
            times.append(clock)
        choices = [h for h in range(4) if h != (heading + 2) % 4]
        choices = [
            h for h in choices if np.all((node + _STEPS[h] >= 0) & (node + _STEPS[h] < side))
        ]
        heading = int(rng.choice(choices))
        node = node + _STEPS[heading]
        clock += spacing / rng.uniform(8, 18)
        corners.append(node * spacing)
        times.append(clock)
    path, stamps = np.array(corners, np.float64), np.array(times)
    fix_times = np.arange(0.0, seconds)
    fixes = np.column_stack([np.interp(fix_times, stamps, path[:, k]) for k in (0, 1)])
    fixes += rng.normal(0, noise, fixes.shape)
    frame_times = np.arange(frames) / fps
    points = np.column_stack([np.interp(frame_times, fix_times, fixes[:, k]) for k in (0, 1)])
    return frame_times, points
