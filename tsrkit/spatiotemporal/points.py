"""A track's candidate in one frame: detected, or projected by dense optical flow (Zheng 2016,
3.4.4, "DOF based candidate"), and the tracks they form."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any

from tsrkit.core.types import Detection

__all__ = ["COLOURS", "Point", "Track", "frame_status"]

#: The colours of Zheng's state machine (Eq. 3.35); any other state counts as ``unknown``.
COLOURS = ("red", "yellow", "green")


def frame_status(x: float, y: float, radius: float, width: int, height: int) -> str:
    """``in`` when the candidate's box lies inside the image, ``partial`` when it overlaps it,
    else ``out``: the out-of-boundary flag of a projected candidate (3.4.4, Figure 3-19).

    >>> frame_status(10, 10, 2, 100, 50), frame_status(1, 10, 2, 100, 50)
    ('in', 'partial')
    >>> frame_status(50, -5, 2, 100, 50)
    'out'
    """
    x0, y0, x1, y1 = x - radius, y - radius, x + radius, y + radius
    if x0 >= 0 and y0 >= 0 and x1 <= width and y1 <= height:
        return "in"
    if x1 <= 0 or y1 <= 0 or x0 >= width or y0 >= height:
        return "out"
    return "partial"


@dataclass(frozen=True)
class Point:
    """A candidate lens of a track in one frame.

    ``scores`` are the classification scores per colour (``cs`` of Eq. 3.38); ``origin`` is
    ``detected`` or ``dof`` (projected from a neighbouring frame); ``status`` the in-frame flag
    of :func:`frame_status`; ``score`` the detector's own score (carried by projections).
    """

    x: float
    y: float
    radius: float
    state: str
    scores: Mapping[str, float]
    origin: str = "detected"
    status: str = "in"
    score: float = 0.0

    @classmethod
    def from_detection(cls, detection: Detection, width: int, height: int) -> Point:
        """A detected point: a classifier's scores, else 1 for the state a detector gave."""
        c = detection.candidate
        scores = {k: float(v) for k, v in detection.state_scores.items() if k in COLOURS}
        if not scores and detection.state in COLOURS:
            scores = {detection.state: 1.0}
        return cls(
            c.x,
            c.y,
            c.radius,
            detection.state,
            scores,
            "detected",
            frame_status(c.x, c.y, c.radius, width, height),
            float(c.score),
        )

    @property
    def confidence(self) -> float:
        """The highest classification score (what the stability score sums, 3.4.4)."""
        return max(self.scores.values(), default=0.0)

    def to_json(self, frame: int) -> dict[str, Any]:
        return {
            "frame": frame,
            "x": round(self.x, 2),
            "y": round(self.y, 2),
            "radius": round(self.radius, 2),
            "origin": self.origin,
            "status": self.status,
            "state": self.state,
            "confidence": round(self.confidence, 4),
            "score": round(self.score, 4),
        }


@dataclass
class Track:
    """A candidate followed across frames: ``points[frame]``."""

    id: int
    points: dict[int, Point] = field(default_factory=dict)

    @property
    def stability(self) -> float:
        """Zheng's stability score: the sum of the highest classification score of the track's
        detected candidates (DOF candidates excluded), 3.4.4."""
        return sum(p.confidence for p in self.points.values() if p.origin == "detected")

    def to_json(self) -> dict[str, Any]:
        frames = sorted(self.points)
        return {
            "id": self.id,
            "stability": round(self.stability, 4),
            "first": frames[0] if frames else None,
            "last": frames[-1] if frames else None,
            "detected": sum(p.origin == "detected" for p in self.points.values()),
            "points": [self.points[f].to_json(f) for f in frames],
        }
