"""The true signal timelines and driving events of a rendered drive (:mod:`tsrkit.synth.drive`):
what ``tsrkit track`` should find in ``timelines.csv`` and ``events.csv``
(:mod:`tsrkit.spatiotemporal.events` defines both and derives the events by the same rules).

A traversal here is one visit of a signalised intersection, numbered in route order as
``drive.json``'s ``traversals``; its window holds the frames within :data:`TRUTH_WINDOW_M` of
the intersection's centre around the closest frame (the vicinity of Zheng 2016, 3.4.2, with
that threshold), its timeline ends where the car passes the stop position. The controlling
signal is the approach's own phase
(:func:`tsrkit.synth.drive.light_state`); the stop position is the route's stop (1 m before the
near side's mast line, :data:`tsrkit.synth.drive.HEAD_PAST` + 1 m before the centre).
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import numpy as np

from tsrkit.spatiotemporal.events import (
    EVENT_COLUMNS,
    TIMELINE_COLUMNS,
    Interval,
    Motion,
    derive_events,
    until_crossing,
    write_rows,
)
from tsrkit.synth.drive import Drive, Node, drive_profile, light_state, summary

__all__ = ["TRUTH_WINDOW_M", "true_timeline", "truth_rows", "write_truth"]

#: Distance (m) from an intersection's centre within which a traversal's truth is written.
TRUTH_WINDOW_M = 60.0


def true_timeline(drive: Drive, node: Node, t0: float, t1: float) -> list[Interval]:
    """The states ``node`` shows to its approach over video seconds ``t0..t1``, with the exact
    change times of the cycle."""
    options = drive.options
    g, y, cycle = options.green_s, options.yellow_s, options.cycle
    shift = cycle / 2 if node.into in "EW" else 0.0
    intervals: list[Interval] = []
    t = t0
    while t < t1:
        phase = (t + node.offset + shift) % cycle
        step = min((b - phase) % cycle or cycle for b in (0.0, g, g + y))
        end = min(t + step, t1)
        kind = light_state(options, node, node.into, (t + end) / 2)
        if intervals and intervals[-1].kind == kind:
            intervals[-1] = Interval(kind, intervals[-1].time, end)
        else:
            intervals.append(Interval(kind, t, end))
        t = end
    return intervals


def _window(distance: np.ndarray, closest: int, limit: float) -> tuple[int, int]:
    """The run of frames within ``limit`` around ``closest``."""
    first = last = closest
    while first > 0 and distance[first - 1] < limit:
        first -= 1
    while last + 1 < len(distance) and distance[last + 1] < limit:
        last += 1
    return first, last


def truth_rows(
    drive: Drive, window_m: float = TRUTH_WINDOW_M
) -> tuple[list[dict[str, Any]], list[dict[str, Any]]]:
    """The rows of ``truth_timelines.csv`` and ``truth_events.csv`` (columns of
    :data:`~tsrkit.spatiotemporal.events.TIMELINE_COLUMNS` and ``EVENT_COLUMNS``)."""
    options = drive.options
    start = options.start_utc
    s, _ = drive_profile(options, drive.route)
    times = drive.times
    timelines, events = [], []
    for number, visit in enumerate(summary(drive)["traversals"]):
        node = drive.route.nodes[visit["node"]]
        cx, cy = node.i * options.block, node.j * options.block
        first, last = _window(
            np.hypot(drive.x - cx, drive.y - cy), visit["closest_frame"], window_m
        )
        stop = drive.route.stops[visit["node"]]
        window = slice(first, last + 1)
        motion = Motion(
            start + times[window],
            (stop - s[window]) if math.isfinite(stop) else np.full(last + 1 - first, np.inf),
            drive.speed[window],
        )
        intervals = true_timeline(drive, node, float(times[first]), float(times[last]))
        utc = [Interval(i.kind, start + i.time, start + i.end) for i in intervals]
        for interval in until_crossing(utc, motion):
            timelines.append(
                {
                    "traversal": number,
                    "kind": interval.kind,
                    "time": round(interval.time, 3),
                    "end": round(interval.end, 3),
                    "video_start": round(interval.time - start, 3),
                    "video_end": round(interval.end - start, 3),
                    "confidence": 1.0,
                }
            )
        events += derive_events(number, utc, motion, start)
    return timelines, events


def write_truth(drive: Drive, folder: Path, window_m: float = TRUTH_WINDOW_M) -> None:
    """Write ``truth_timelines.csv`` and ``truth_events.csv`` into ``folder`` (atomically)."""
    timelines, events = truth_rows(drive, window_m)
    write_rows(folder / "truth_timelines.csv", TIMELINE_COLUMNS, timelines)
    write_rows(folder / "truth_events.csv", EVENT_COLUMNS, events)
