"""The car's approach to a signalised intersection from its GPS log: approach heading, stop
position, and distance to it and speed at any time (the kinematics of
:mod:`tsrkit.spatiotemporal.events`).

Positions are fixes projected to a local plane (Zheng 2016, Eq. 3.21-3.28:
:class:`tsrkit.geo.LocalProjection`) and taken along the approach: the distance to the stop
position is ``(stop - p) . h`` for the approach's unit heading ``h``. Zheng interpolates fixes
linearly to frames (4.3, Eq. 4.1-4.2); speed needs more than two fixes, so here a local
quadratic (least squares over the fixes within :data:`HALF_WINDOW_S` of each time) gives the
position and speed, and a stop is modelled where the car stands: the fixes at rest fix its
position, and the constant deceleration before it (and acceleration after it) is fitted to the
fixes around, which dates the stop and the pull-away within a fraction of the fix interval.

Stop position: an OpenStreetMap node tagged ``highway=stop``, ``highway=stop_line`` or
``traffic_signals=stop_line`` within :data:`STOP_SEARCH_M` of the intersection, before its centre
on the approach and beside the car's path, when the map has one; else :data:`STOP_OFFSET_M`
before the intersection's (merged signal nodes') centre along the approach.
"""

from __future__ import annotations

import gzip
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from defusedxml import ElementTree

from tsrkit.geo.osm import map_format
from tsrkit.spatiotemporal.events import Motion

__all__ = [
    "HALF_WINDOW_S",
    "STOP_OFFSET_M",
    "STOP_SEARCH_M",
    "STOP_TAGS",
    "Approach",
    "approach_motion",
    "approach_of",
    "stop_nodes",
]

#: Distance (m) of the stop position before the intersection's centre when the map marks none:
#: half of a four-lane road (7 m) plus a crosswalk and the stop line's setback (6 m), the
#: layout of the rendered drives (``tsrkit.synth.drive``: stop 13 m before the centre).
STOP_OFFSET_M = 13.0
#: Stop nodes are looked for within this distance (m) of the intersection's centre.
STOP_SEARCH_M = 40.0
STOP_TAGS = (("highway", "stop"), ("highway", "stop_line"), ("traffic_signals", "stop_line"))
#: Half width (s) of the local quadratic fit of the fixes.
HALF_WINDOW_S = 2.5
#: A fix whose fitted speed is below this (m/s) may be at rest; two in a row are a stop.
STILL_SPEED = 1.2


def stop_nodes(path: str) -> np.ndarray:
    """``(lat, lon)`` rows of the stop-line nodes of an ``.osm`` / ``.osm.gz`` extract (other
    map formats: none). The map has been read once by :func:`tsrkit.geo.read_signals`, which
    reports a malformed file."""
    file = Path(path)
    if map_format(file) != "xml":
        return np.zeros((0, 2))
    opener = gzip.open if file.suffix == ".gz" else open
    with opener(file, "rb") as fh:
        root = ElementTree.parse(fh).getroot()
    found = []
    for node in root.iter("node"):
        tags = {t.get("k", ""): t.get("v", "") for t in node.iter("tag")}
        if any(tags.get(key) == value for key, value in STOP_TAGS):
            try:
                found.append((float(node.get("lat", "")), float(node.get("lon", ""))))
            except ValueError:
                continue
    return np.array(found, float).reshape(-1, 2)


@dataclass(frozen=True)
class Approach:
    """An approach in local metres: the intersection's centre, the unit heading, the stop
    position and where it came from (``osm`` or ``offset``)."""

    centre: np.ndarray
    heading: np.ndarray
    stop: np.ndarray
    source: str

    def distance(self, x: np.ndarray, y: np.ndarray) -> np.ndarray:
        """Distance (m) to the stop position along the heading, positive before it."""
        return (self.stop[0] - x) * self.heading[0] + (self.stop[1] - y) * self.heading[1]


def approach_of(
    x: np.ndarray,
    y: np.ndarray,
    t: np.ndarray,
    centre: np.ndarray,
    anchor: float,
    stops: np.ndarray,
    offset: float = STOP_OFFSET_M,
) -> Approach:
    """The approach of the fixes ``(x, y)`` at times ``t`` (local metres, at least two) to
    ``centre``: the
    heading is the principal direction of the fixes before ``anchor`` and more than 14 m from
    the centre (oriented along the motion); the stop position is the stop node (rows of
    ``stops``, local metres) before the centre and nearest the path, else ``offset`` metres
    before the centre."""
    before = (t <= anchor) & (np.hypot(x - centre[0], y - centre[1]) > 14.0)
    if before.sum() < 2:
        before = t <= anchor if (t <= anchor).sum() >= 2 else np.ones(len(t), bool)
    px, py = x[before], y[before]
    points = np.column_stack([px - px.mean(), py - py.mean()])
    heading = np.linalg.svd(points, full_matrices=False)[2][0]
    if heading @ np.array((px[-1] - px[0], py[-1] - py[0])) < 0:
        heading = -heading
    lateral = np.array((-heading[1], heading[0]))
    best, source = None, "offset"
    for stop in stops:
        along = (stop - centre) @ heading
        side = abs((stop - np.array((px.mean(), py.mean()))) @ lateral)
        near = np.hypot(*(stop - centre)) <= STOP_SEARCH_M and along < 0 and side < 12.0
        if near and (best is None or side < best[1]):
            best, source = (stop, side), "osm"
    position = best[0] if best is not None else centre - offset * heading
    return Approach(np.asarray(centre, float), heading, np.asarray(position, float), source)


def _local_fit(t: np.ndarray, d: np.ndarray, at: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Distance and speed (``-d'``) at times ``at`` by a local quadratic fit of ``d(t)`` over
    the fixes within :data:`HALF_WINDOW_S` (a line where only two fixes fall there)."""
    position, speed = np.full(len(at), np.nan), np.full(len(at), np.nan)
    for k, now in enumerate(at):
        near = np.abs(t - now) <= HALF_WINDOW_S
        if near.sum() < 2:
            continue
        dt = t[near] - now
        degree = 2 if near.sum() >= 4 else 1
        coef = np.polyfit(dt, d[near], degree)
        position[k], speed[k] = coef[-1], -coef[-2]
    return position, speed


def _ramp(tau: np.ndarray, rate: float, top: float) -> tuple[np.ndarray, np.ndarray]:
    """Distance and speed ``tau`` seconds from rest under ``rate`` m/s^2 up to ``top`` m/s."""
    ramp = top / rate
    inside = tau <= ramp
    distance = np.where(inside, rate * tau**2 / 2, top * tau - top * ramp / 2)
    return distance, np.where(inside, rate * tau, top)


def _fit_rest(
    t: np.ndarray, d: np.ndarray, rest: float, top: float, sign: int
) -> tuple[float, float]:
    """The moment the car comes to rest (``sign`` -1: it arrives before ``t``; +1: it leaves
    after) at distance ``rest``, and the rate, fitted by a grid search on the fixes ``t, d``
    around it (constant deceleration or acceleration up to speed ``top``)."""
    best = (np.inf, float(t[0]), 3.0)
    for rate in np.arange(1.0, 6.01, 0.25):
        for moment in np.arange(t.min() - 1.0, t.max() + 1.0, 0.02):
            tau = np.maximum(sign * (t - moment), 0.0)
            model = rest + (-sign) * _ramp(tau, rate, top)[0]
            error = float(np.sum((model - d) ** 2))
            if error < best[0]:
                best = (error, float(moment), float(rate))
    return best[1], best[2]


def approach_motion(
    track_t: np.ndarray, d: np.ndarray, at: np.ndarray, cruise: float = 12.0
) -> Motion:
    """The kinematics at times ``at`` from the fixes' times ``track_t`` and distances ``d`` to
    the stop position (module notes); ``cruise`` bounds the speed the stop model ramps to
    when the fixes around give none."""
    position, speed = _local_fit(track_t, d, at)
    _, fix_speed = _local_fit(track_t, d, track_t)
    still = np.abs(fix_speed) < STILL_SPEED
    k = 0
    while k < len(still):
        if not still[k]:
            k += 1
            continue
        end = k
        while end + 1 < len(still) and still[end + 1]:
            end += 1
        if end - k >= 1:
            rest = float(np.median(d[k : end + 1]))
            arrive, leave = _fit_edges(track_t, d, fix_speed, k, end, rest, cruise)
            inside = (at >= arrive[0]) & (at <= leave[0])
            position[inside], speed[inside] = rest, 0.0
            for (moment, rate, top), sign in ((arrive, -1), (leave, 1)):
                tau = sign * (at - moment)
                span = (tau > 0) & (tau <= top / rate)
                gone, fast = _ramp(tau[span], rate, top)
                position[span], speed[span] = rest - sign * gone, fast
        k = end + 1
    return Motion(np.asarray(at, float), position, speed)


def _fit_edges(
    t: np.ndarray,
    d: np.ndarray,
    fix_speed: np.ndarray,
    first: int,
    last: int,
    rest: float,
    cruise: float,
) -> tuple[tuple[float, float, float], tuple[float, float, float]]:
    """The arrival and departure of a stop on fixes ``first..last``: ``(moment, rate, top)``
    each, fitted on the stop's fixes and those up to 4 s before (after) it; ``top`` is the
    fastest fitted speed there (at least 3 m/s, at most 1.5 ``cruise``)."""
    edges = []
    for sign in (-1, 1):
        lo, hi = (t[first] - 4.0, t[last]) if sign < 0 else (t[first], t[last] + 4.0)
        window = (t >= lo) & (t <= hi)
        top = float(np.clip(np.abs(fix_speed[window]).max(), 3.0, 1.5 * cruise))
        moment, rate = _fit_rest(t[window], d[window], rest, top, sign)
        edges.append((moment, rate, top))
    return edges[0], edges[1]
