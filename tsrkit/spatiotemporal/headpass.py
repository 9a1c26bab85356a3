"""Following a signal head, not a lamp, over a whole traversal clip: the timeline pass that
extends the controlling tracks of Zheng 2016's framework (3.4.4-3.4.5) across state changes.

Zheng's long-range pass (Algorithm 3-4) looks for the next candidate within twice the lens
radius of the flow-projected one, so a track ends where the lit lamp moves to another lens of
the head (RESULTS.track.md, "Limits"), and the passes start from the short range around the
closest frame: the approach, where amber and red onsets and stops happen, is mostly untracked.
This pass follows the head instead. From each end of a chosen track it projects the lit lamp
to the next frame by the Farneback flow of the whole head around it (Eq. 3.30-3.34 on a circle
that spans the head: the flow at the lamp itself is wrong where the lit lamp changes), detects
in a region that reaches the other lamps (Algorithms 3-3 / 3-4 with the region widened to the
head), and keeps the candidate whose position fits its state's lamp (:func:`lamp_fit`:
:data:`LAMP_PITCH` radii apart, red on top, the layout of a vertical head; after a change
of lamp the pass follows the new lamp from where the head's layout puts it, since the first
detection of a lamp switching on is often its glow off the lens); it stops after
:data:`PATIENCE` frames without one.
"""

from __future__ import annotations

import math
from dataclasses import replace

from tsrkit.spatiotemporal.clip import Clip
from tsrkit.spatiotemporal.points import Point, Track

__all__ = ["LAMP_PITCH", "PATIENCE", "follow_head", "lamp_fit"]

#: Distance between neighbouring lamps of a head, in lens radii (a 300 mm lens in a 1 m head;
#: ``tsrkit.synth.heads.render_head`` draws 2.8).
LAMP_PITCH = 2.8
#: Frames without a fitting candidate after which the pass stops in that direction.
PATIENCE = 5
#: How far (radii) along the head's axis, beyond the lamp spacing's slack, a candidate may lie
#: from where its state's lamp should be (a lamp's glow is often detected off its centre).
ALONG_RADII = 2.5
#: Share of the lamp spacing by which a lamp change may differ from it (detected radii are
#: integers, and a glowing lamp looks larger than its lens).
PITCH_SLACK = 0.45
#: How far (radii) across the head's axis a candidate may lie from the projected lamp.
ACROSS_RADII = 2.0
#: The changes of state a signal head makes (Zheng's colour state machine, Eq. 3.35).
CYCLE = {("green", "yellow"), ("yellow", "red"), ("red", "green")}
_LAMP = {"red": -1, "yellow": 0, "green": 1}


def lamp_fit(candidate: Point, lamp: Point, radius: float, later: bool = True) -> float:
    """How well ``candidate`` fits as the lit lamp of the head whose lamp ``lamp`` was lit
    (projected to the candidate's frame): 0 is perfect, above 1 no fit (inf when it cannot be
    a lamp of this head, or when the change of state is not one of the signal cycle's:
    green -> yellow -> red -> green, Zheng's colour state machine, Eq. 3.35-3.37; ``later``
    says the candidate's frame follows the lamp's). The expected shift along the axis is the
    lamp spacing times the number of lamps between the two states.

    >>> lamp = Point(10.0, 20.0, 2.0, "green", {})
    >>> lamp_fit(Point(10.5, 30.0, 2.0, "red", {}), lamp, 2.0, later=False) > 1  # below
    True
    >>> lamp_fit(Point(10.5, 9.0, 2.0, "red", {}), lamp, 2.0, later=False)  # red, then green
    0.125
    >>> lamp_fit(Point(10.5, 9.0, 2.0, "red", {}), lamp, 2.0)  # green, then red: no amber
    inf
    """
    if candidate.state not in _LAMP or not 0.4 * radius <= candidate.radius <= 2.5 * radius:
        return math.inf
    change = (lamp.state, candidate.state) if later else (candidate.state, lamp.state)
    if change[0] != change[1] and change not in CYCLE:
        return math.inf
    steps = _LAMP[candidate.state] - _LAMP[lamp.state]
    expected = steps * LAMP_PITCH * radius
    along = abs(candidate.y - lamp.y - expected) / max(
        ALONG_RADII * radius, PITCH_SLACK * abs(expected)
    )
    across = abs(candidate.x - lamp.x) / (ACROSS_RADII * radius)
    return max(along, across)


def _steady(points: dict[int, Point], frames: list[int]) -> int:
    """Of ``frames``, the one whose point lies nearest the median position of their points
    (a track's first or last point is often a stray one)."""
    x = sorted(points[f].x for f in frames)[len(frames) // 2]
    y = sorted(points[f].y for f in frames)[len(frames) // 2]
    return min(frames, key=lambda f: math.hypot(points[f].x - x, points[f].y - y))


def follow_head(clip: Clip, track: Track) -> Track:
    """A copy of ``track`` extended over the clip in both directions (module notes), from the
    steadiest of its first and of its last five points."""
    points = dict(track.points)
    frames = sorted(points)
    ends = (
        (_steady(points, frames[:5]), -1, clip.first),
        (_steady(points, frames[-5:]), 1, clip.last),
    )
    for start, step, stop in ends if frames else ():
        lamp = points[start]
        if lamp.state not in _LAMP:
            continue
        radius = max(lamp.radius, 0.8)
        reach = (2 * LAMP_PITCH + ALONG_RADII) * radius
        i, missed = start, 0
        while i != stop and missed < PATIENCE:
            j = i + step
            moved = clip.project(replace(lamp, radius=reach / 2), i, j)
            if moved.status == "out":
                break
            lamp = replace(moved, radius=radius)
            found = [
                (lamp_fit(p, lamp, radius, step > 0), p)
                for p in clip.detect_near(j, replace(lamp, radius=reach / 2))
            ]
            score, best = min(found, key=lambda item: item[0], default=(math.inf, None))
            if best is not None and score <= 1.0:
                points.setdefault(j, best)
                if best.state != lamp.state:  # the lit lamp moved: where the head puts it
                    steps = _LAMP[best.state] - _LAMP[lamp.state]
                    best = replace(best, y=lamp.y + steps * LAMP_PITCH * radius)
                radius = 0.7 * radius + 0.3 * best.radius
                reach = (2 * LAMP_PITCH + ALONG_RADII) * radius
                lamp = best
                missed = 0
            else:
                missed += 1
            i = j
    return Track(track.id, points)
