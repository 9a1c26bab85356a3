"""From a traversal's signal timeline and the car's kinematics to driving events: amber and red
onset with the car's speed, distance and time to the stop position, the stop-or-go decision,
the state when the car crosses the stop position (a red-light crossing is flagged with its
evidence) and the dilemma-zone class at amber onset.

The same rules make the true events of a rendered drive (:mod:`tsrkit.synth.behaviour`, from the
simulated state and motion) and the estimated ones of ``tsrkit track`` (from the recognised
timeline and the GPS log, :mod:`tsrkit.spatiotemporal.study`), so the two can be compared.

Dilemma zone (at amber onset, speed ``v``, distance ``x`` to the stop position): the car can
stop when ``x >= x_c = v * delta + v**2 / (2 * a)`` (the critical stopping distance, Gazis,
Herman and Maradudin 1960, "The problem of the amber signal light in traffic flow", Operations
Research 8(1), Eq. 1; with ITE's perception-reaction time ``delta`` = 1 s and comfortable
deceleration ``a`` = 3.0 m/s^2 (10 ft/s^2) of the kinematic change-interval formula, ITE
Traffic Engineering Handbook) and can clear it when ``x <= x_0 = v * tau - (w + L)`` (the
maximum clearing distance at constant speed over the amber time ``tau``, GHM Eq. 2 with no
acceleration; ``w + L`` the intersection width plus the car's length). Both: ``option``; neither:
``dilemma`` (the Type I dilemma zone); one: ``can_stop`` or ``can_clear``. The class is given
only where the formulas apply: a complete amber interval (known ``tau``) and a moving car.
"""

from __future__ import annotations

import csv
import math
import os
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from tsrkit.core.atomic import atomic_open

__all__ = [
    "CROSS_M",
    "EVENT_COLUMNS",
    "EVENT_KINDS",
    "GAP_S",
    "RED_MARGIN_S",
    "STATES",
    "STOP_SPEED",
    "TIMELINE_COLUMNS",
    "Dilemma",
    "Interval",
    "Motion",
    "crossing_time",
    "derive_events",
    "state_at",
    "until_crossing",
    "write_rows",
]

#: The states of a timeline interval (``red_yellow``: the red-plus-amber phase of some countries).
STATES = ("red", "yellow", "green", "red_yellow", "unknown")
EVENT_KINDS = ("amber_onset", "red_onset", "stop", "go", "red_crossing")
#: Below this speed (m/s) the car is at rest (``stop`` / ``go``).
STOP_SPEED = 0.1
#: The car has passed the stop position once it is this far (m) beyond it.
CROSS_M = 2.0
#: An "unknown" interval this short (s) between two states does not hide a change between them.
GAP_S = 0.5
#: Least time (s) a red crossing must lie inside the red interval, at either end.
RED_MARGIN_S = 0.2

TIMELINE_COLUMNS = (
    "traversal",
    "kind",
    "time",
    "end",
    "video_start",
    "video_end",
    "confidence",
)
EVENT_COLUMNS = (
    "traversal",
    "kind",
    "time",
    "video_s",
    "speed",
    "distance",
    "time_to_stop",
    "state",
    "zone",
    "evidence",
)


@dataclass(frozen=True)
class Interval:
    """One run of a timeline's state: UTC seconds ``time..end`` and a confidence in 0..1."""

    kind: str
    time: float
    end: float
    confidence: float = 1.0


@dataclass(frozen=True)
class Motion:
    """The car's kinematics on one approach, sampled (usually at the video's frames):
    UTC seconds, distance to the stop position along the approach (m, positive before it)
    and speed (m/s)."""

    time: np.ndarray
    distance: np.ndarray
    speed: np.ndarray


@dataclass(frozen=True)
class Dilemma:
    """The constants of the dilemma-zone formulas (module notes): perception-reaction time
    (s), deceleration (m/s^2) and the distance to clear past the stop position (m: the
    intersection's width plus the car's length)."""

    reaction_s: float = 1.0
    decel: float = 3.0
    clear_m: float = 25.0

    def zone(self, speed: float, distance: float, amber_s: float | None) -> str:
        """``can_stop``, ``can_clear``, ``option``, ``dilemma``, or ``""`` where the formulas
        do not apply (no amber duration, a car at rest).

        >>> Dilemma().zone(12.0, 50.0, 3.0), Dilemma().zone(12.0, 10.0, 3.0)
        ('can_stop', 'can_clear')
        >>> Dilemma().zone(12.0, 30.0, 3.0), Dilemma().zone(12.0, 40.0, 6.0)
        ('dilemma', 'option')
        """
        if amber_s is None or not speed > STOP_SPEED or not math.isfinite(distance):
            return ""
        stop = distance >= speed * self.reaction_s + speed * speed / (2 * self.decel)
        clear = distance <= speed * amber_s - self.clear_m
        return {(True, True): "option", (True, False): "can_stop", (False, True): "can_clear"}.get(
            (stop, clear), "dilemma"
        )


def until_crossing(intervals: Sequence[Interval], motion: Motion) -> list[Interval]:
    """``intervals`` cut where the car passes the stop position (the approach: the signal
    governs the car until then); all of them when it does not pass it."""
    crossed = crossing_time(motion)
    if crossed is None:
        return list(intervals)
    return [
        Interval(i.kind, i.time, min(i.end, crossed), i.confidence)
        for i in intervals
        if i.time < crossed or i.time == intervals[0].time
    ]


def state_at(intervals: Sequence[Interval], t: float) -> Interval | None:
    """The interval holding ``t`` (the later one at a shared boundary)."""
    found = None
    for interval in intervals:
        if interval.time <= t <= interval.end:
            found = interval
    return found


def crossing_time(motion: Motion) -> float | None:
    """When the car passes the stop position, or None when it does not get
    :data:`CROSS_M` beyond it. A car that comes to rest at (or, by position noise, just past)
    the stop position crosses when it pulls away, not when it halted there; else the moment
    the distance reaches zero (linear between samples)."""
    d, speed = motion.distance, motion.speed
    beyond = np.flatnonzero(d <= -CROSS_M)
    if not len(beyond):
        return None
    k = int(beyond[0])
    while k > 0 and d[k - 1] <= 0 and speed[k - 1] >= STOP_SPEED:
        k -= 1
    if k == 0 or d[k - 1] <= 0:  # at rest past the line, or past it from the start
        return float(motion.time[k])
    share = d[k - 1] / (d[k - 1] - d[k])
    return float(motion.time[k - 1] + share * (motion.time[k] - motion.time[k - 1]))


def _at(motion: Motion, t: float) -> tuple[float, float]:
    speed = float(np.interp(t, motion.time, motion.speed))
    return speed, float(np.interp(t, motion.time, motion.distance))


def _event(
    traversal: int,
    kind: str,
    t: float,
    start: float,
    motion: Motion,
    state: Interval | None,
    zone: str = "",
    evidence: str = "",
) -> dict[str, Any]:
    speed, distance = _at(motion, t)
    return {
        "traversal": traversal,
        "kind": kind,
        "time": round(t, 3),
        "video_s": round(t - start, 3),
        "speed": round(speed, 2),
        "distance": round(distance, 2),
        "time_to_stop": round(distance / speed, 2) if speed > STOP_SPEED else "",
        "state": state.kind if state else "unknown",
        "zone": zone,
        "evidence": evidence,
    }


def derive_events(
    traversal: int,
    intervals: Sequence[Interval],
    motion: Motion,
    video_start: float,
    dilemma: Dilemma = Dilemma(),
    position_m: float = 0.0,
) -> list[dict[str, Any]]:
    """The events of one approach, in time order (module notes).

    ``amber_onset`` is a yellow interval that follows a green one, ``red_onset`` a red one that
    follows a yellow one (across an ``unknown`` of at most :data:`GAP_S`), both before the car
    passes the stop position; ``stop`` the first sample below :data:`STOP_SPEED` before it and
    ``go`` the first sample above it after a stop; ``red_crossing`` the moment the car passes
    the stop position while the timeline shows red, with the interval that says so as
    evidence. The crossing must lie inside the
    red interval by ``max(RED_MARGIN_S, position_m / speed)`` at both ends, so that an error
    of ``position_m`` metres in the car's position cannot turn a crossing on amber or green
    into a red one (0 for exact kinematics: any crossing on red). ``video_start`` is the UTC
    time of the video's first frame (for ``video_s``).
    """
    crossed = crossing_time(motion)
    until = crossed if crossed is not None else float(motion.time[-1])
    events = []
    for k in range(1, len(intervals)):
        interval, b = intervals[k], k - 1
        while (
            b > 0
            and intervals[b].kind == "unknown"
            and intervals[b].end - intervals[b].time <= GAP_S
        ):
            b -= 1  # a blink of "unknown" between two states
        before = intervals[b]
        if not interval.time < until:
            continue
        if interval.kind == "yellow" and before.kind == "green":
            complete = k + 1 < len(intervals) and intervals[k + 1].kind != "unknown"
            amber = interval.end - interval.time if complete else None
            speed, distance = _at(motion, interval.time)
            zone = dilemma.zone(speed, distance, amber)
            events.append(
                _event(traversal, "amber_onset", interval.time, video_start, motion, interval, zone)
            )
        elif interval.kind == "red" and before.kind == "yellow":
            events.append(
                _event(traversal, "red_onset", interval.time, video_start, motion, interval)
            )
    moving = motion.speed >= STOP_SPEED
    for k in range(1, len(moving)):
        t = float(motion.time[k])
        if moving[k - 1] == moving[k] or (t > until and not moving[k]):
            continue
        kind = "go" if moving[k] else "stop"
        if kind == "go" and not any(e["kind"] == "stop" for e in events):
            continue
        events.append(_event(traversal, kind, t, video_start, motion, state_at(intervals, t)))
    shown = state_at(intervals, crossed) if crossed is not None else None
    if crossed is not None and shown is not None and shown.kind == "red":
        speed = max(_at(motion, crossed)[0], STOP_SPEED)
        margin = max(RED_MARGIN_S, position_m / speed) if position_m else 0.0
        if shown.time + margin <= crossed <= shown.end - margin:
            evidence = (
                f"red since {crossed - shown.time:.2f} s before the stop position, "
                f"{shown.end - crossed:.2f} s more (interval confidence {shown.confidence:.2f}, "
                f"margin {margin:.2f} s)"
            )
            events.append(
                _event(traversal, "red_crossing", crossed, video_start, motion, shown, "", evidence)
            )
    return sorted(events, key=lambda e: e["time"])


def write_rows(
    path: str | os.PathLike, columns: Sequence[str], rows: Iterable[Mapping[str, Any]]
) -> None:
    """Write ``rows`` as CSV with ``columns``, atomically (:func:`tsrkit.atomic.atomic_open`)."""
    with atomic_open(path) as fh:
        writer = csv.DictWriter(fh, columns, extrasaction="ignore", lineterminator="\n")
        writer.writeheader()
        writer.writerows(rows)
