"""Consecutive video frames that share work: the whole pipeline on key frames, and in between a
search around each light already found.

A lit lens moves a few pixels from one video frame to the next. :class:`Follower` runs its
pipeline (detector, verifier, classifier) on the whole frame every ``key_every``-th frame (a key
frame), and on each frame in between re-detects every followed light in a window around it with
the same detector and verifier: centred where the light's last step would carry it (constant
velocity), of radius ``reach`` lens radii (at least :data:`MIN_REACH_PX`), plus the context the
detector and the housing fit need around a lens (:func:`region`); windows that overlap are
searched as one (:func:`windows`). The detector sees each window as a window of the frame
(``metadata["window"]``, :data:`WINDOW`), so a rule about the frame's rows (the union's band
above the horizon) holds as on the whole frame. Each detection is matched to the nearest light
within reach, closest pairs first. A light not found on a frame is dropped (following it on,
along its last step, until the next key frame found no more lights and more false ones:
``benchmarks/RESULTS.video.md``); a light that appears between key frames is found at the next
key frame, at most ``key_every - 1`` frames late.

Each key frame starts afresh (no light carried into it), so a run of frames after a key frame
depends on that run alone: a video cut into chunks of a multiple of ``key_every`` frames gives
the same records whichever process handles each chunk (:func:`tsrkit.runner.streams.run_pipeline`).
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, replace

import numpy as np

from tsrkit.core.types import WINDOW, Candidate, Frame
from tsrkit.plugin.pipeline import FrameResult, Pipeline

__all__ = [
    "CONTEXT_PX",
    "CONTEXT_RADII",
    "MIN_REACH_PX",
    "Follower",
    "Light",
    "light_of",
    "region",
    "shifted",
    "windows",
]

#: The smallest search radius around a light's predicted centre, pixels.
MIN_REACH_PX = 4.0
#: Context around the searched disc, in lens radii (the detectors' filters reach a few radii
#: around a lens; the verifier and classifier read the whole frame).
CONTEXT_RADII = 3.0
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
        moved = light_of(candidate)
        return replace(moved, dx=moved.x - self.x, dy=moved.y - self.y)


def region(
    x: float, y: float, reach: float, radius: float, width: int, height: int
) -> tuple[int, int, int, int]:
    """The crop ``(x0, y0, x1, y1)`` searched for a light predicted at ``(x, y)``: the disc of
    radius ``reach`` plus :data:`CONTEXT_RADII` lens radii (at least :data:`CONTEXT_PX`) of
    context, inside the image.

    >>> region(100.0, 50.0, 6.0, 2.0, 640, 480)
    (82, 32, 118, 68)
    >>> region(3.0, 3.0, 6.0, 2.0, 640, 480)
    (0, 0, 21, 21)
    """
    pad = reach + max(CONTEXT_RADII * radius, CONTEXT_PX)
    x0, y0 = max(int(x - pad), 0), max(int(y - pad), 0)
    x1, y1 = min(int(math.ceil(x + pad)), width), min(int(math.ceil(y + pad)), height)
    return x0, y0, x1, y1


def shifted(candidate: Candidate, dx: float, dy: float) -> Candidate:
    """``candidate`` moved by ``(dx, dy)`` pixels (from a crop's coordinates to the frame's)."""

    def move(box):
        return None if box is None else (box[0] + dx, box[1] + dy, box[2] + dx, box[3] + dy)

    c = candidate
    return replace(c, x=c.x + dx, y=c.y + dy, bbox=move(c.bbox), housing=move(c.housing))


Box = tuple[int, int, int, int]


def windows(boxes: list[Box]) -> list[Box]:
    """``boxes`` with every group of boxes that overlap (or touch) replaced by the box holding
    the group, in sorted order.

    >>> windows([(8, 8, 20, 20), (40, 0, 50, 10), (0, 0, 10, 10)])
    [(0, 0, 20, 20), (40, 0, 50, 10)]
    """
    merged = sorted(boxes)
    changed = True
    while changed:
        changed = False
        out: list[Box] = []
        for box in merged:
            for k, o in enumerate(out):
                if box[0] <= o[2] and o[0] <= box[2] and box[1] <= o[3] and o[1] <= box[3]:
                    out[k] = (
                        min(box[0], o[0]),
                        min(box[1], o[1]),
                        max(box[2], o[2]),
                        max(box[3], o[3]),
                    )
                    changed = True
                    break
            else:
                out.append(box)
        merged = sorted(out)
    return merged


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
        """The frame's result: the whole pipeline on a key frame, else the windowed searches.

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
        result = self.pipeline.finish(frame, self._search(frame), start)
        pairs = sorted(
            (math.dist(light.predicted(), (d.candidate.x, d.candidate.y)), j, k)
            for j, light in enumerate(self._lights)
            for k, d in enumerate(result.detections)
        )
        found: dict[int, int] = {}  # light -> detection
        for distance, j, k in pairs:
            if (
                distance <= self._reach(self._lights[j])
                and j not in found
                and k not in found.values()
            ):
                found[j] = k
        detections = tuple(result.detections[k] for _, k in sorted(found.items()))
        self._lights = [
            self._lights[j].moved_to(d.candidate) for j, d in zip(sorted(found), detections)
        ]
        ms = (time.perf_counter() - start) * 1000.0
        return replace(result, ms=ms, detections=detections)

    def _reach(self, light: Light) -> float:
        return max(self.reach * light.radius, MIN_REACH_PX)

    def _search(self, frame: Frame) -> list[Candidate]:
        """The detector's candidates within reach of a light's predicted centre, found in the
        :func:`windows` of the lights' :func:`region`, in the frame's coordinates."""
        boxes = []
        for light in self._lights:
            x, y = light.predicted()
            boxes.append(region(x, y, self._reach(light), light.radius, frame.width, frame.height))
        boxes = [b for b in boxes if b[2] - b[0] >= 4 and b[3] - b[1] >= 4]  # not outside
        found = []
        for x0, y0, x1, y1 in windows(boxes):
            crop = np.ascontiguousarray(frame.image[y0:y1, x0:x1])
            metadata = {**frame.metadata, WINDOW: (x0, y0, frame.width, frame.height)}
            window = Frame(crop, frame.source, frame.index, frame.timestamp, metadata)
            self.calls["regions"] += 1
            found += [shifted(c, x0, y0) for c in self.pipeline.detector.detect(window)]
        return [
            c
            for c in found
            if any(
                math.dist(light.predicted(), (c.x, c.y)) <= self._reach(light)
                for light in self._lights
            )
        ]


def light_of(candidate: Candidate) -> Light:
    """A light first seen at ``candidate`` (no step yet). Its radius is that of the lens box
    when smaller than the candidate's (a housing stage measures the lit lens, where a detector
    such as ``union`` may keep a blob several times the lamp)."""
    x0, y0, x1, y1 = candidate.lens_bbox
    return Light(candidate.x, candidate.y, min(candidate.radius, max(x1 - x0, y1 - y0) / 2))
