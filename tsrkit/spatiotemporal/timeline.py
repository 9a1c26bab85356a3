"""The controlling signal of a traversal and its state timeline, from the tracks of ``tsrkit
track`` (Zheng 2016, 3.4.4-3.4.5) fused as Lee 2017 fuses the lights of one lane (5.3.4).

Controlling heads. The camera looks along the car's heading, so a track's image column gives
its bearing from the approach heading, and its row says it hangs above the road. The heads
controlling the car's approach face it for the whole approach (the longest, steadiest tracks:
Zheng's stability score, 3.4.4), lie ahead of it (near the image's centre column) and hang
above the camera (above the centre row of a level camera); heads of
the cross street come into view at the side near the junction, lit in the other phase. The head
of highest ``stability * (1 - |bearing share|)`` over the frames before the car passes the stop
position is chosen, and so is every other track whose states agree with it on at least
:data:`AGREEMENT` of their common frames (Lee 5.3.4: several lights dedicated to one lane).

Fusion and the "unknown" rule (Lee 5.3.4). Per frame each chosen head votes its state with its
classification confidence (a DOF candidate, which carries the state of the frame it was
projected from, with :data:`DOF_WEIGHT` of it), averaged over the heads seen in that frame:
where they agree this is the consensus, where not the most confident head wins, as Lee's rule.
A low-pass filter (here a centred moving average over ``lowpass_s``: the run is offline, so the
filter need not lag) smooths the votes, averaging over the frames of the window where a head was
seen (a missed detection neither votes nor dilutes the others); a frame whose highest smoothed
vote is below ``unknown`` is published as ``unknown`` (Lee's threshold ``t``; he gives no
value), and so is a frame with no head seen within the window.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np

from tsrkit.spatiotemporal.events import STATES, Interval

__all__ = [
    "AGREEMENT",
    "DOF_WEIGHT",
    "controlling_tracks",
    "fused_states",
    "state_intervals",
]

#: Share of common frames on which a second head must show the chosen head's state.
AGREEMENT = 0.8
#: Weight of a DOF candidate's vote against a detected one's.
DOF_WEIGHT = 0.7
VOTED = STATES[:-1]  # every state but "unknown"


def _points(track: Mapping[str, Any], until: int) -> dict[int, Mapping[str, Any]]:
    return {p["frame"]: p for p in track["points"] if p["frame"] <= until and p["status"] != "out"}


def controlling_tracks(
    tracks: Sequence[Mapping[str, Any]], size: tuple[int, int], until: int
) -> list[Mapping[str, Any]]:
    """The tracks of the heads controlling the approach, best first (module notes); ``size``
    is the frame's width and height, ``until`` the last frame before the car passes the stop
    position. A track whose median row lies below the centre row (the horizon of a level
    camera) is no head."""
    width, height = size
    scored = []
    for track in tracks:
        points = _points(track, until)
        detected = [p for p in points.values() if p["origin"] == "detected"]
        if not detected or float(np.median([p["y"] for p in detected])) > height / 2:
            continue
        bearing = float(np.median([abs(p["x"] - width / 2) for p in detected])) / (width / 2)
        stability = sum(p["confidence"] for p in detected)
        scored.append((stability * max(0.0, 1.0 - bearing), track, points))
    if not scored:
        return []
    scored.sort(key=lambda item: -item[0])
    _, best, best_points = scored[0]
    chosen = [best]
    for _, track, points in scored[1:]:
        common = [f for f in points if f in best_points]
        if len(common) >= 3:
            same = sum(points[f]["state"] == best_points[f]["state"] for f in common)
            if same >= AGREEMENT * len(common):
                chosen.append(track)
    return chosen


def fused_states(
    tracks: Sequence[Mapping[str, Any]],
    first: int,
    last: int,
    fps: float,
    lowpass_s: float = 0.5,
    unknown: float = 0.3,
) -> tuple[list[str], np.ndarray]:
    """Per frame ``first..last`` the published state and its smoothed vote (module notes)."""
    count = last - first + 1
    votes = np.zeros((count, len(VOTED)))
    seen = np.zeros(count)
    for track in tracks:
        for p in track["points"]:
            k = p["frame"] - first
            if 0 <= k < count and p["status"] != "out" and p["state"] in VOTED:
                weight = 1.0 if p["origin"] == "detected" else DOF_WEIGHT
                votes[k, VOTED.index(p["state"])] += weight * p["confidence"]
                seen[k] += 1
    votes /= np.maximum(seen, 1)[:, None]
    width = max(1, int(round(lowpass_s * fps)) | 1)
    kernel = np.ones(width)
    observed = np.convolve((seen > 0).astype(float), kernel, mode="same")
    smooth = (
        np.column_stack([np.convolve(votes[:, j], kernel, mode="same") for j in range(len(VOTED))])
        / np.maximum(observed, 1)[:, None]
    )
    top = smooth.max(axis=1)
    states = [VOTED[int(j)] if v >= unknown else "unknown" for j, v in zip(smooth.argmax(1), top)]
    return states, top


def state_intervals(
    states: Sequence[str], votes: np.ndarray, first: int, fps: float, start_utc: float
) -> list[Interval]:
    """Runs of equal state as UTC intervals: a change between frames ``k - 1`` and ``k`` is
    dated half-way, ``(k - 0.5) / fps``; the first run starts at frame ``first`` and the last
    ends at the last frame. The confidence is the run's mean smoothed vote (``unknown``: one
    minus it)."""
    intervals: list[Interval] = []
    k = 0
    while k < len(states):
        end = k
        while end + 1 < len(states) and states[end + 1] == states[k]:
            end += 1
        t0 = (first + k - (0.5 if k else 0.0)) / fps
        t1 = (first + end + (0.5 if end + 1 < len(states) else 0.0)) / fps
        mean = float(votes[k : end + 1].mean())
        confidence = 1.0 - mean if states[k] == "unknown" else mean
        intervals.append(
            Interval(states[k], start_utc + t0, start_utc + t1, round(min(1.0, confidence), 3))
        )
        k = end + 1
    return intervals
