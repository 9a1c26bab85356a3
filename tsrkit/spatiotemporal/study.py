"""From the traversals of ``tsrkit track`` to answers: per traversal the controlling signal's
state timeline (:mod:`tsrkit.spatiotemporal.timeline`, Lee 2017 5.3.4) and the driving events
(:mod:`tsrkit.spatiotemporal.events`) from it and the GPS kinematics
(:mod:`tsrkit.spatiotemporal.kinematics`; stops dated by the video's image motion,
:mod:`tsrkit.spatiotemporal.egomotion`), written as ``timelines.csv`` and ``events.csv``.

``timelines.csv`` (the approach: until the car passes the stop position): ``traversal``
(the record's index in ``traversals.jsonl``), ``kind`` (red, yellow, green, red_yellow or
unknown), ``time`` / ``end`` (UTC epoch seconds), ``video_start`` / ``video_end`` (seconds into
the video) and ``confidence``. ``events.csv``: ``traversal``, ``kind`` (amber_onset, red_onset,
stop, go, red_crossing), ``time`` (UTC), ``video_s``, the car's ``speed`` (m/s), ``distance``
(m, to the stop position, positive before it) and ``time_to_stop`` (s, at the current speed) at
that moment, the timeline's ``state`` then, the dilemma-zone class at amber onset (``zone``),
for a red-light crossing its ``evidence``, where the stop position came from (``stop_source``:
``osm`` or ``offset``) and the ids of the fused heads (``heads``).
"""

from __future__ import annotations

import os
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import cv2
import numpy as np

from tsrkit.geo import LocalProjection, Signals, Track
from tsrkit.spatiotemporal.egomotion import dated_rest
from tsrkit.spatiotemporal.events import (
    EVENT_COLUMNS,
    TIMELINE_COLUMNS,
    Dilemma,
    Motion,
    crossing_time,
    derive_events,
    until_crossing,
    write_rows,
)
from tsrkit.spatiotemporal.kinematics import (
    STOP_OFFSET_M,
    approach_motion,
    approach_of,
    stop_nodes,
)
from tsrkit.spatiotemporal.timeline import controlling_tracks, fused_states, state_intervals

__all__ = ["STUDY_EVENT_COLUMNS", "StudySettings", "frame_size", "study_traversal", "write_study"]

#: The columns of ``events.csv``.
STUDY_EVENT_COLUMNS = (*EVENT_COLUMNS, "stop_source", "heads")
#: The error (m) of a smoothed GPS position the red-crossing margin allows for (about twice the
#: spread of a consumer receiver's fix after the local fit).
POSITION_M = 2.0
#: Fixes this many seconds beyond a traversal's entry and exit feed its kinematics.
FIX_MARGIN_S = 20.0


@dataclass(frozen=True)
class StudySettings:
    """Stop offset (m, where the map marks no stop line), the low-pass window (s) and the
    "unknown" threshold of Lee 5.3.4, the position error the red-crossing margin allows for
    (:func:`~tsrkit.spatiotemporal.events.derive_events`) and the dilemma-zone constants."""

    stop_offset: float = STOP_OFFSET_M
    lowpass_s: float = 0.5
    unknown: float = 0.3
    position_m: float = POSITION_M
    dilemma: Dilemma = field(default_factory=Dilemma)


def frame_size(video: str | os.PathLike) -> tuple[int, int]:
    """The video's frame width and height in pixels (a track's bearing is a share of the
    width)."""
    capture = cv2.VideoCapture(str(video), cv2.CAP_FFMPEG)
    try:
        return (
            int(capture.get(cv2.CAP_PROP_FRAME_WIDTH) or 0),
            int(capture.get(cv2.CAP_PROP_FRAME_HEIGHT) or 0),
        )
    finally:
        capture.release()


def study_traversal(
    record: Mapping[str, Any],
    track: Track,
    signals: Signals,
    stops: np.ndarray,
    size: tuple[int, int],
    settings: StudySettings = StudySettings(),
) -> tuple[list[dict[str, Any]], list[dict[str, Any]]]:
    """The timeline rows and event rows of one traversal record of ``tsrkit track``
    (``stops``: ``(lat, lon)`` rows of the map's stop-line nodes; ``size``: the frame's width
    and height). The heads are the record's ``heads`` (followed over the clip,
    :mod:`tsrkit.spatiotemporal.headpass`), else its ``tracks``."""
    number, fps, start = record["traversal"], float(record["fps"]), float(record["start_utc"])
    first, last = int(record["first_frame"]), int(record["last_frame"])
    node = record["intersection"]
    projection = LocalProjection(float(signals.lat[node]), float(signals.lon[node]))
    near = (track.time >= record["entry"] - FIX_MARGIN_S) & (
        track.time <= record["exit"] + FIX_MARGIN_S
    )
    x, y = projection(track.lat[near], track.lon[near])
    t = track.time[near]
    frames = np.arange(first, last + 1)
    if len(t) >= 2:
        stop_xy = np.column_stack(projection(stops[:, 0], stops[:, 1])) if len(stops) else stops
        approach = approach_of(
            x, y, t, np.zeros(2), float(record["anchor"]), stop_xy, settings.stop_offset
        )
        motion = approach_motion(t, approach.distance(x, y), start + frames / fps)
        source = approach.source
    else:  # no fixes around the traversal: no kinematics, no event but from the timeline
        unknown = np.full(len(frames), np.nan)
        motion, source = Motion(start + frames / fps, unknown, unknown), "none"
    measure = {int(k): float(v) for k, v in (record.get("image_motion") or {}).items()}
    if measure:
        motion = dated_rest(motion, frames.tolist(), measure, fps)
    crossed = crossing_time(motion)
    until = last if crossed is None else int(np.floor((crossed - start) * fps))
    heads = controlling_tracks(record.get("heads") or record["tracks"], size, until)
    states, votes = fused_states(heads, first, last, fps, settings.lowpass_s, settings.unknown)
    intervals = state_intervals(states, votes, first, fps, start)
    timeline = [
        {
            "traversal": number,
            "kind": i.kind,
            "time": round(i.time, 3),
            "end": round(i.end, 3),
            "video_start": round(i.time - start, 3),
            "video_end": round(i.end - start, 3),
            "confidence": i.confidence,
        }
        for i in until_crossing(intervals, motion)
    ]
    events = derive_events(number, intervals, motion, start, settings.dilemma, settings.position_m)
    for event in events:
        event["stop_source"] = source
        event["heads"] = ";".join(str(h["id"]) for h in heads)
    return timeline, events


def write_study(
    out: Path,
    records: Sequence[Mapping[str, Any]],
    track: Track,
    signals: Signals,
    video: str | os.PathLike,
    settings: StudySettings = StudySettings(),
) -> tuple[int, int]:
    """Write ``timelines.csv`` and ``events.csv`` of the traversal records into ``out``
    (atomically); returns the counts of intervals and events."""
    stops = stop_nodes(signals.source)
    size = frame_size(video)
    timelines, events = [], []
    for record in records:
        rows, found = study_traversal(record, track, signals, stops, size, settings)
        timelines += rows
        events += found
    write_rows(out / "timelines.csv", TIMELINE_COLUMNS, timelines)
    write_rows(out / "events.csv", STUDY_EVENT_COLUMNS, events)
    return len(timelines), len(events)
