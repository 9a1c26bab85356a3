"""The vicinity profile and traversals (Zheng 2016, 3.4.2-3.4.3).

Every fix gets its nearest intersection and distance (scipy's cKDTree on locally projected
metres); a traversal is a maximal run of fixes within ``vicinity`` metres of the same
intersection. Its anchor is the closest fix (the latest of equally close ones: a car waiting at
the light); its movement compares the heading before entering
with the heading after leaving (Eq. 3.29): a turn of more than ``theta_min`` degrees to the left
or right, else through.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.spatial import cKDTree

from tsrkit.geo.gps import Track
from tsrkit.geo.nearest import nearest_extended, nearest_kdtree
from tsrkit.geo.osm import Signals
from tsrkit.geo.projection import LocalProjection

__all__ = [
    "THETA_MIN",
    "Traversal",
    "latest_minimum",
    "movement",
    "traversals",
    "vicinity_profile",
]

#: Zheng's minimum heading change of a turn (3.4.3), degrees.
THETA_MIN = 20.0


@dataclass(frozen=True)
class Traversal:
    """One pass of the track through an intersection's vicinity."""

    intersection: int
    entry: float
    exit: float
    anchor: float
    closest_m: float
    movement: str
    turn_deg: float

    def to_json(self, signals: Signals) -> dict:
        """The JSON Lines record of ``tsrkit track``."""
        return {
            "intersection": self.intersection,
            "osm_ids": list(signals.ids[self.intersection]),
            "lat": float(signals.lat[self.intersection]),
            "lon": float(signals.lon[self.intersection]),
            "entry": self.entry,
            "exit": self.exit,
            "anchor": self.anchor,
            "closest_m": round(self.closest_m, 2),
            "movement": self.movement,
            "turn_deg": round(self.turn_deg, 1),
        }


def vicinity_profile(
    track: Track, signals: Signals, tau_min: float | None = None
) -> tuple[np.ndarray, np.ndarray, LocalProjection]:
    """Per fix: the index of the nearest intersection and its distance in metres, by the basic
    k-d tree query, or by Zheng's extended k-d tree recursion when ``tau_min`` (seconds) is
    given (:mod:`tsrkit.geo.nearest`)."""
    projection = LocalProjection(float(np.mean(track.lat)), float(np.mean(track.lon)))
    sx, sy = projection(signals.lat, signals.lon)
    tx, ty = projection(track.lat, track.lon)
    tree, points = cKDTree(np.column_stack([sx, sy])), np.column_stack([tx, ty])
    if tau_min is None:
        nearest, distance = nearest_kdtree(tree, points)
    else:
        nearest, distance = nearest_extended(tree, points, track.time, tau_min)
    return nearest, distance, projection


def movement(
    heading_in: float, heading_out: float, theta_min: float = THETA_MIN
) -> tuple[str, float]:
    """Eq. 3.29: ``left``, ``right`` or ``through`` from the headings (degrees, counter-clockwise
    from east) before and after the intersection, and the signed turn (left positive).

    >>> movement(90.0, 180.0)
    ('left', 90.0)
    >>> movement(90.0, 80.0)
    ('through', -10.0)
    """
    turn = (heading_out - heading_in + 180.0) % 360.0 - 180.0
    if turn > theta_min:
        return "left", turn
    if turn < -theta_min:
        return "right", turn
    return "through", turn


def _heading(x: np.ndarray, y: np.ndarray, a: int, b: int) -> float:
    return float(np.degrees(np.arctan2(y[b] - y[a], x[b] - x[a])))


def latest_minimum(values: np.ndarray) -> int:
    """Index of the valley bottom of a vicinity profile: "when the valley bottom is flat, the
    latest bottom frame is chosen as the anchor frame" (Zheng 2016, 3.4.2).

    >>> latest_minimum(np.array([9.0, 4.0, 4.0, 7.0]))
    2
    """
    return len(values) - 1 - int(np.argmin(values[::-1]))


def traversals(
    track: Track, signals: Signals, vicinity: float = 30.0, lead: int = 3
) -> list[Traversal]:
    """The traversals of ``track`` through ``signals`` (see the module notes).

    ``lead`` fixes before the entry and after the exit give the headings of Eq. 3.29 (clipped to
    the track's ends).
    """
    if not len(signals) or not len(track):
        return []
    nearest, distance, projection = vicinity_profile(track, signals)
    x, y = projection(track.lat, track.lon)
    inside = distance <= vicinity
    out = []
    i, n = 0, len(track)
    while i < n:
        if not inside[i]:
            i += 1
            continue
        j = i
        while j + 1 < n and inside[j + 1] and nearest[j + 1] == nearest[i]:
            j += 1
        anchor = latest_minimum(distance[i : j + 1]) + i
        before, after = max(i - lead, 0), min(j + lead, n - 1)
        heading_in = (
            _heading(x, y, before, anchor) if anchor > before else _heading(x, y, anchor, after)
        )
        heading_out = _heading(x, y, anchor, after) if after > anchor else heading_in
        kind, turn = movement(heading_in, heading_out)
        out.append(
            Traversal(
                int(nearest[i]),
                float(track.time[i]),
                float(track.time[j]),
                float(track.time[anchor]),
                float(distance[anchor]),
                kind,
                turn,
            )
        )
        i = j + 1
    return out
