"""Following a signal head, not a lamp, over a whole traversal clip: the timeline pass that
extends the controlling tracks of Zheng 2016's framework (3.4.4-3.4.5) across state changes.

Zheng's long-range pass (Algorithm 3-4) looks for the next candidate within twice the lens
radius of the flow-projected one, so a track ends where the lit lamp moves to another lens of
the head (RESULTS.track.md, "Limits"), and the passes start from the short range around the
closest frame: the approach, where amber and red onsets and stops happen, is mostly untracked.
This pass follows the head's housing instead. From each end of a chosen track it projects the
housing's centre to the next frame by Farneback flow (Eq. 3.30-3.34), detects in a region that
holds all three lamps (Algorithms 3-3 / 3-4 with the region widened to the housing), and keeps
the candidate whose position fits its state's lamp (:data:`LAMP_PITCH` radii apart, red on
top: the layout of a vertical head); it stops after :data:`PATIENCE` frames without one.
"""

from __future__ import annotations

import math
from dataclasses import replace

from tsrkit.spatiotemporal.clip import Clip
from tsrkit.spatiotemporal.points import Point, Track

__all__ = ["LAMP_PITCH", "PATIENCE", "follow_head", "lamp_offset"]

#: Distance between neighbouring lamps of a head, in lens radii (a 300 mm lens in a 1 m head;
#: ``tsrkit.synth.heads.render_head`` draws 2.8).
LAMP_PITCH = 2.8
#: Frames without a fitting candidate after which the pass stops in that direction.
PATIENCE = 5
#: How far (radii) a candidate may lie from its state's lamp position to be kept.
FIT_RADII = 1.2
_LAMP = {"red": -1, "yellow": 0, "green": 1}


def lamp_offset(state: str, radius: float) -> float:
    """Image rows from the housing's centre down to the lamp of ``state`` (red on top).

    >>> lamp_offset("red", 2.0), lamp_offset("green", 2.0)
    (-5.6, 5.6)
    """
    return _LAMP[state] * LAMP_PITCH * radius


def _fit(candidate: Point, centre: Point, radius: float) -> float:
    """The candidate's distance (radii) from its state's lamp position, inf when it cannot
    be a lamp of this head."""
    if candidate.state not in _LAMP or not 0.4 * radius <= candidate.radius <= 2.5 * radius:
        return math.inf
    dy = candidate.y - (centre.y + lamp_offset(candidate.state, radius))
    return math.hypot(candidate.x - centre.x, dy) / radius


def follow_head(clip: Clip, track: Track) -> Track:
    """A copy of ``track`` extended over the clip in both directions (module notes)."""
    points = dict(track.points)
    frames = sorted(points)
    if not frames:
        return Track(track.id, points)
    for start, step, stop in ((frames[0], -1, clip.first), (frames[-1], 1, clip.last)):
        lamp = points[start]
        radius = max(lamp.radius, 0.8)
        centre = (
            replace(lamp, y=lamp.y - lamp_offset(lamp.state, radius))
            if lamp.state in _LAMP
            else None
        )
        if centre is None:
            continue
        i, missed = start, 0
        while i != stop and missed < PATIENCE:
            j = i + step
            centre = clip.project(replace(centre, radius=radius), i, j)
            if centre.status == "out":
                break
            region = replace(centre, radius=(LAMP_PITCH + 1.0) * radius / 2)
            found = [(_fit(p, centre, radius), p) for p in clip.detect_near(j, region)]
            score, best = min(found, key=lambda item: item[0], default=(math.inf, None))
            if best is not None and score <= FIT_RADII:
                points.setdefault(j, best)
                radius = 0.7 * radius + 0.3 * best.radius
                centre = replace(centre, x=best.x, y=best.y - lamp_offset(best.state, radius))
                missed = 0
            else:
                missed += 1
            i = j
    return Track(track.id, points)
