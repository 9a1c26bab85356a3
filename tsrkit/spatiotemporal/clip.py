"""The decoded frames of one traversal, with the chosen plugins' detections (whole frame or a
restricted region) and flow projections on demand: what the passes of Zheng 2016, 3.4.4-3.4.5
ask of a frame."""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import cv2
import numpy as np

from tsrkit.core.types import Frame
from tsrkit.plugin.pipeline import Pipeline
from tsrkit.spatiotemporal.flow import farneback, project, project_with
from tsrkit.spatiotemporal.points import Point

__all__ = ["CONTEXT_PX", "KEPT_FLOWS", "MIN_REGION_PX", "WHOLE_FLOW_POINTS", "Clip"]

#: Pixels of context around a restricted region given to the detector (its filters need some).
CONTEXT_PX = 12
#: The smallest restricted-region radius, pixels (twice a 1.5 px candidate's radius).
MIN_REGION_PX = 3.0
#: Above this many candidates, one whole-frame flow is cheaper than a window each.
WHOLE_FLOW_POINTS = 8
#: Whole-frame flows kept for reuse.
KEPT_FLOWS = 4


@dataclass
class Clip:
    """Frames ``images[index]`` (BGR) of one video clip.

    ``pipeline`` runs on whole frames (detector, verifier, tracker, classifier) cut to their
    upper ``roi_top`` share, Zheng's "general region of interests" (5.4: the upper 60 %);
    ``regional`` (the same plugins without the tracker) on restricted regions. ``margin`` is
    the flow window of :func:`tsrkit.spatiotemporal.flow.project`, 0 for whole-frame flows
    (the default: windows lose the lens under fast image motion, see RESULTS.track.md);
    projecting more than :data:`WHOLE_FLOW_POINTS` candidates at once always uses one
    whole-frame flow.
    """

    source: str
    images: dict[int, np.ndarray]
    pipeline: Pipeline
    regional: Pipeline
    margin: int = 0
    roi_top: float = 1.0
    calls: dict[str, int] = field(
        default_factory=lambda: {"whole": 0, "region": 0, "flow": 0, "projections": 0}
    )
    _gray: dict[int, np.ndarray] = field(default_factory=dict, repr=False)
    _whole: dict[int, list[Point]] = field(default_factory=dict, repr=False)
    _flows: dict[tuple[int, int], np.ndarray] = field(default_factory=dict, repr=False)

    @property
    def first(self) -> int:
        return min(self.images)

    @property
    def last(self) -> int:
        return max(self.images)

    def gray(self, index: int) -> np.ndarray:
        if index not in self._gray:
            self._gray[index] = cv2.cvtColor(self.images[index], cv2.COLOR_BGR2GRAY)
        return self._gray[index]

    def detect(self, index: int) -> list[Point]:
        """Detected and classified candidates of the whole frame (computed once)."""
        if index not in self._whole:
            image = self.images[index]
            h, w = image.shape[:2]
            top = np.ascontiguousarray(image[: max(1, int(round(h * self.roi_top)))])
            result = self.pipeline.process(Frame(top, self.source, index))
            self.calls["whole"] += 1
            self._whole[index] = [Point.from_detection(d, w, h) for d in result.detections]
        return self._whole[index]

    def detect_near(self, index: int, around: Point) -> list[Point]:
        """Candidates detected within the region co-centred with ``around`` with twice its
        radius (at least :data:`MIN_REGION_PX`): the tracked detection of Algorithms 3-3
        and 3-4. The detector sees the region plus :data:`CONTEXT_PX` pixels of context."""
        image = self.images[index]
        h, w = image.shape[:2]
        reach = max(2.0 * around.radius, MIN_REGION_PX)
        pad = reach + CONTEXT_PX
        x0, y0 = max(int(around.x - pad), 0), max(int(around.y - pad), 0)
        x1, y1 = min(int(math.ceil(around.x + pad)), w), min(int(math.ceil(around.y + pad)), h)
        if x1 - x0 < 4 or y1 - y0 < 4:
            return []
        crop = np.ascontiguousarray(image[y0:y1, x0:x1])
        result = self.regional.process(Frame(crop, self.source, index))
        self.calls["region"] += 1
        found = []
        for detection in result.detections:
            point = Point.from_detection(detection, w, h)
            point = Point(
                point.x + x0,
                point.y + y0,
                point.radius,
                point.state,
                point.scores,
                point.origin,
                point.status,
                point.score,
            )
            if math.hypot(point.x - around.x, point.y - around.y) <= reach:
                found.append(point)
        return found

    def flow(self, source: int, target: int) -> np.ndarray:
        """The whole-frame Farneback flow from ``source`` to ``target`` (the last few kept:
        every track projected between the same two frames shares it)."""
        key = (source, target)
        if key not in self._flows:
            self.calls["flow"] += 1
            self._flows[key] = farneback(self.gray(source), self.gray(target))
            while len(self._flows) > KEPT_FLOWS:
                self._flows.pop(next(iter(self._flows)))
        return self._flows[key]

    def project(self, point: Point, source: int, target: int) -> Point:
        """``point`` of frame ``source`` projected onto frame ``target`` by Farneback flow."""
        self.calls["projections"] += 1
        if self.margin <= 0:
            return project_with(point, self.flow(source, target), self.images[target].shape)
        self.calls["flow"] += 1
        return project(point, self.gray(source), self.gray(target), self.margin)

    def project_all(self, points: list[Point], source: int, target: int) -> list[Point]:
        """Every point of frame ``source`` projected onto ``target``: windowed flows for a
        few, one whole-frame flow for many (the same Farneback flow, computed once)."""
        if len(points) <= WHOLE_FLOW_POINTS:
            return [self.project(p, source, target) for p in points]
        self.calls["projections"] += len(points)
        flow = self.flow(source, target)
        return [project_with(p, flow, self.images[target].shape) for p in points]
