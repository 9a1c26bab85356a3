"""Consecutive video frames that share work: the whole pipeline on key frames, and in between a
search around each light of the frame before.

A lit lens moves a few pixels from one video frame to the next. :class:`Follower` runs its
pipeline (detector, verifier, classifier) on the whole frame every ``key_every``-th frame (a key
frame), and on each frame in between only on a region around every light the frame before
reported: centred where the light's last step would carry it (constant velocity), of radius
``reach`` lens radii (at least :data:`MIN_REACH_PX`), plus the context the detector and the
housing fit need around a lens (:func:`region`). The nearest detection in reach is the light on
this frame; a light not found there is dropped, and a light that appears between key frames is
found at the next key frame, at most ``key_every - 1`` frames late.

Each key frame starts afresh (no light carried into it), so a run of frames after a key frame
depends on that run alone: a video cut into chunks of a multiple of ``key_every`` frames gives
the same records whichever process handles each chunk (:func:`tsrkit.streams.run_pipeline`).
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, replace

import numpy as np

from tsrkit.pipeline import FrameResult, Pipeline, check_detection
from tsrkit.types import Candidate, Detection, Frame

__all__ = [
    "CONTEXT_PX",
    "CONTEXT_RADII",
    "MIN_REACH_PX",
    "Follower",
    "Light",
    "light_of",
    "region",
    "shifted",
]

#: The smallest search radius around a light's predicted centre, pixels.
MIN_REACH_PX = 4.0
#: Context around the searched disc, in lens radii: a three-lens head reaches about 7 radii
#: from its lit lens, which the housing stage of a verifier fits.
CONTEXT_RADII = 8.0
#: Context around the searched disc at least, pixels (the detectors' filters need some).
CONTEXT_PX = 12


@dataclass(frozen=True)
class Light:
    """A light reported on the previous frame: centre, lens radius and last step (pixels)."""

    x: float
    y: float
    radius: float
    dx: float = 0.0
    dy: float = 0.0

    def predicted(self) -> tuple[float, float]:
        """Where the light's last step carries it on the next frame."""
        return self.x + self.dx, self.y + self.dy

    def moved_to(self, candidate: Candidate) -> Light:
        """The light found at ``candidate`` on the next frame."""
        return Light(
            candidate.x, candidate.y, candidate.radius, candidate.x - self.x, candidate.y - self.y
        )


def region(
    x: float, y: float, reach: float, radius: float, width: int, height: int
) -> tuple[int, int, int, int]:
    """The crop ``(x0, y0, x1, y1)`` searched for a light predicted at ``(x, y)``: the disc of
    radius ``reach`` plus :data:`CONTEXT_RADII` lens radii (at least :data:`CONTEXT_PX`) of
    context, inside the image.

    >>> region(100.0, 50.0, 6.0, 2.0, 640, 480)
    (78, 28, 122, 72)
    >>> region(3.0, 3.0, 6.0, 2.0, 640, 480)
    (0, 0, 25, 25)
    """
    pad = reach + max(CONTEXT_RADII * radius, CONTEXT_PX)
    x0, y0 = max(int(x - pad), 0), max(int(y - pad), 0)
    x1, y1 = min(int(math.ceil(x + pad)), width), min(int(math.ceil(y + pad)), height)
    return x0, y0, x1, y1


def shifted(detection: Detection, dx: float, dy: float) -> Detection:
    """``detection`` moved by ``(dx, dy)`` pixels (from a crop's coordinates to the frame's)."""
    c = detection.candidate

    def move(box):
        return None if box is None else (box[0] + dx, box[1] + dy, box[2] + dx, box[3] + dy)

    moved = replace(c, x=c.x + dx, y=c.y + dy, bbox=move(c.bbox), housing=move(c.housing))
    return replace(detection, candidate=moved)


class Follower:
    """A pipeline run over one or more videos frame by frame, sharing work between frames.

    Parameters
    ----------
    pipeline : Pipeline
        Detector, verifier and classifier (no tracker: this class is what follows the lights).
    key_every : int
        The whole pipeline runs on every ``key_every``-th frame; 1 runs it on every frame.
    reach : float
        Search radius around a light's predicted centre, in its lens radii.
    """

    def __init__(self, pipeline: Pipeline, key_every: int = 4, reach: float = 3.0):
        if pipeline.tracker is not None:
            raise ValueError("a follower replaces the tracker: give a pipeline without one")
        if key_every < 1 or not reach > 0:
            raise ValueError(f"need key_every >= 1 and reach > 0; got {key_every}, {reach}")
        self.pipeline = pipeline
        self.key_every = key_every
        self.reach = reach
        self._lights: list[Light] = []
        self._last: tuple[str, int] | None = None
        self._since_key = 0
        self.calls = {"key": 0, "followed": 0, "regions": 0}

    def process(self, frame: Frame) -> FrameResult:
        """The frame's result: the whole pipeline on a key frame, else the regional searches.

        A frame that does not follow the previous one of the same source (another video, a
        jump) is a key frame.
        """
        start = time.perf_counter()
        follows = (
            self._last is not None and self._last[0] == frame.source and frame.index > self._last[1]
        )
        self._last = (frame.source, frame.index)
        if not follows or self._since_key + 1 >= self.key_every:
            result = self.pipeline.process(frame)
            self._since_key = 0
            self.calls["key"] += 1
            self._lights = [light_of(d.candidate) for d in result.detections]
            return result
        self._since_key += 1
        self.calls["followed"] += 1
        detections, lights, notes = [], [], []
        for light in self._lights:
            found = self._search(frame, light, notes)
            if found is not None:
                detections.append(found)
                lights.append(light.moved_to(found.candidate))
        self._lights = lights
        ms = (time.perf_counter() - start) * 1000.0
        return FrameResult(
            frame.source,
            frame.index,
            frame.width,
            frame.height,
            ms,
            tuple(detections),
            tuple(dict.fromkeys(notes)),
        )

    def _search(self, frame: Frame, light: Light, notes: list[str]) -> Detection | None:
        """The detection nearest to ``light``'s predicted centre within reach, or None."""
        x, y = light.predicted()
        reach = max(self.reach * light.radius, MIN_REACH_PX)
        x0, y0, x1, y1 = region(x, y, reach, light.radius, frame.width, frame.height)
        if x1 - x0 < 4 or y1 - y0 < 4:  # predicted outside the frame
            return None
        crop = np.ascontiguousarray(frame.image[y0:y1, x0:x1])
        result = self.pipeline.process(Frame(crop, frame.source, frame.index, frame.timestamp))
        self.calls["regions"] += 1
        notes.extend(result.notes)
        best, best_distance = None, reach
        for detection in result.detections:
            moved = shifted(detection, x0, y0)
            distance = math.hypot(moved.candidate.x - x, moved.candidate.y - y)
            if distance <= best_distance:
                best, best_distance = moved, distance
        if best is not None:
            check_detection(best)
        return best


def light_of(candidate: Candidate) -> Light:
    """A light first seen at ``candidate`` (no step yet)."""
    return Light(candidate.x, candidate.y, candidate.radius)
