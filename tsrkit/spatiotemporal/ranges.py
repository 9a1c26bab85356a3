"""Frames of a traversal: positions at frame times, the clip and the short range (Zheng 2016,
3.4.2 and 3.4.4 "Determine Short Range")."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from tsrkit.geo import Signals, Track, Traversal, traversals
from tsrkit.geo.projection import LocalProjection
from tsrkit.geo.vicinity import vicinity_profile

__all__ = [
    "DOWNSTREAM_M",
    "UPSTREAM_M",
    "FrameTraversal",
    "frame_positions",
    "frame_profile",
    "frame_traversals",
    "short_range",
    "trajectory_distance",
]

#: Zheng's default short range: trajectory metres upstream and downstream of the anchor frame.
UPSTREAM_M, DOWNSTREAM_M = 10.0, 5.0


def trajectory_distance(x: np.ndarray, y: np.ndarray, anchor: int) -> np.ndarray:
    """Per frame, the cumulative trajectory distance to ``anchor``: the sum of the straight-line
    steps between successive frames in between (3.4.4).

    >>> trajectory_distance(np.array([0.0, 3.0, 3.0, 3.0]), np.array([0.0, 0.0, 4.0, 5.0]), 1)
    array([3., 0., 4., 5.])
    """
    step = np.concatenate([[0.0], np.hypot(np.diff(x), np.diff(y))])
    along = np.cumsum(step)
    return np.abs(along - along[anchor])


def short_range(
    x: np.ndarray,
    y: np.ndarray,
    anchor: int,
    first: int,
    last: int,
    upstream: float = UPSTREAM_M,
    downstream: float = DOWNSTREAM_M,
) -> tuple[int, int]:
    """``(i_u, i_d)``: the furthest frames within ``upstream`` metres before and ``downstream``
    metres after ``anchor`` by trajectory distance, inside the clip ``first..last``.

    >>> x = np.arange(0.0, 40.0, 2.0); y = np.zeros(20)
    >>> short_range(x, y, 10, 0, 19)
    (5, 12)
    """
    distance = trajectory_distance(x, y, anchor)
    frames = np.arange(len(x))
    up = frames[(frames >= first) & (frames <= anchor) & (distance <= upstream)]
    down = frames[(frames >= anchor) & (frames <= last) & (distance <= downstream)]
    return int(up.min()), int(down.max())


@dataclass(frozen=True)
class FrameTraversal:
    """A traversal in frame numbers: the clip ``first..last``, its anchor and short range."""

    traversal: Traversal
    first: int
    last: int
    anchor: int
    upstream: int
    downstream: int


def frame_positions(
    track: Track, start: float, fps: float, frames: int, max_gap: float = 5.0
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Frame times (UTC seconds) and the latitude / longitude of every frame interpolated from
    the GPS fixes (Zheng 4.3, Eq. 4.1-4.2: ``Track.at``; NaN in gaps)."""
    times = start + np.arange(frames) / fps
    lat, lon = track.at(times, max_gap)
    return times, lat, lon


def frame_profile(
    track: Track, signals: Signals, start: float, fps: float, frames: int
) -> tuple[np.ndarray, np.ndarray]:
    """The vicinity profile (3.4.2): frames with a position and their distance (m) to the
    nearest intersection."""
    times, lat, lon = frame_positions(track, start, fps, frames)
    known = np.flatnonzero(np.isfinite(lat))
    if not len(known) or not len(signals):
        return known, np.zeros(len(known))
    per_frame = Track(track.source, times[known], lat[known], lon[known])
    _, distance, _ = vicinity_profile(per_frame, signals)
    return known, distance


def frame_traversals(
    track: Track,
    signals: Signals,
    start: float,
    fps: float,
    frames: int,
    vicinity: float,
    upstream: float = UPSTREAM_M,
    downstream: float = DOWNSTREAM_M,
) -> list[FrameTraversal]:
    """The traversals of the video: the vicinity profile of every frame position (3.4.2), each
    valley a clip with its anchor (the closest frame) and short range (3.4.4)."""
    times, lat, lon = frame_positions(track, start, fps, frames)
    known = np.flatnonzero(np.isfinite(lat))
    if not len(known) or not len(signals):
        return []
    per_frame = Track(track.source, times[known], lat[known], lon[known])
    projection = LocalProjection(float(np.mean(per_frame.lat)), float(np.mean(per_frame.lon)))
    x, y = projection(per_frame.lat, per_frame.lon)
    out = []
    for traversal in traversals(per_frame, signals, vicinity):
        first, last, anchor = (
            int(np.searchsorted(per_frame.time, t))
            for t in (traversal.entry, traversal.exit, traversal.anchor)
        )
        up, down = short_range(x, y, anchor, first, last, upstream, downstream)
        out.append(
            FrameTraversal(traversal, *(int(known[k]) for k in (first, last, anchor, up, down)))
        )
    return out
