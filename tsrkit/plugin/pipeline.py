"""Detector -> verifier -> tracker -> classifier on one frame, timed.

``FrameResult.ms`` is the compute time of the plugins on that frame (decoding and I/O excluded).
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, replace
from typing import Any

from tsrkit.core.records import FrameRecord
from tsrkit.core.types import Candidate, Detection, Frame
from tsrkit.plugin.base import Classifier, Detector, Tracker, Verifier

__all__ = ["FrameResult", "Pipeline", "as_detections", "check_detection"]


@dataclass(frozen=True)
class FrameResult:
    """The detections of one frame and how long they took."""

    source: str
    index: int
    width: int
    height: int
    ms: float
    detections: tuple[Detection, ...]
    notes: tuple[str, ...] = ()

    def to_record(self) -> dict[str, Any]:
        """The JSON Lines record of ``tsrkit detect`` (``FrameRecord.to_json``)."""
        return FrameRecord.from_result(self).to_json()


def check_detection(detection: Detection) -> None:
    """Raise ValueError for a detection whose lens or housing is not finite or has no area
    (a plugin bug: the frame is then skipped with this reason, the run goes on)."""
    c = detection.candidate
    boxes = [c.bbox] + ([c.housing] if c.housing is not None else [])
    for x0, y0, x1, y1 in boxes:
        values = (c.x, c.y, c.radius, x0, y0, x1, y1)
        if not all(math.isfinite(v) for v in values) or x1 < x0 or y1 < y0:
            raise ValueError(f"invalid detection box {(x0, y0, x1, y1)} at ({c.x}, {c.y})")
    if c.distance_m is not None and not (math.isfinite(c.distance_m) and c.distance_m > 0):
        raise ValueError(f"invalid distance {c.distance_m} m at ({c.x}, {c.y})")


def as_detections(candidates: list[Candidate]) -> list[Detection]:
    """Detections for a detector used alone: the detector's own state, else ``unknown``."""
    return [Detection(c, c.state or "unknown") for c in candidates]


@dataclass
class Pipeline:
    """A detector with an optional classifier, tracker and verifier."""

    detector: Detector
    classifier: Classifier | None = None
    tracker: Tracker | None = None
    verifier: Verifier | None = None
    _video: str | None = None

    def process(self, frame: Frame) -> FrameResult:
        """Detect, verify, track, then classify ``frame``; exceptions from a plugin propagate.

        The verifier rescores, refines or rejects the detector's candidates; the tracker sees
        what it kept; the classifier then sees every reported
        object, tracked ones included, and its states replace the detector's own.
        """
        start = time.perf_counter()
        if self.tracker is not None and frame.source != self._video:
            self.tracker.reset()
            self._video = frame.source
        detect = self.tracker is None or self.tracker.needs_detection()
        return self.finish(frame, self.detector.detect(frame) if detect else [], start)

    def finish(
        self, frame: Frame, candidates: list[Candidate], start: float | None = None
    ) -> FrameResult:
        """Verify, track and classify ``candidates`` found on ``frame`` (by the detector, or
        elsewhere); ``start`` is the :func:`time.perf_counter` time the frame's work began."""
        start = time.perf_counter() if start is None else start
        if self.verifier is not None and candidates:
            candidates = self.verifier.verify(frame, candidates)
        detections = as_detections(candidates)
        if self.tracker is not None:
            detections = self.tracker.update(frame, detections)
        if self.classifier is not None:
            states = self.classifier.classify(frame, [d.candidate for d in detections])
            detections = [
                replace(s, origin=d.origin, track_id=d.track_id) for s, d in zip(states, detections)
            ]
        for detection in detections:
            check_detection(detection)
        ms = (time.perf_counter() - start) * 1000.0
        stages = (self.detector, self.verifier, self.tracker, self.classifier)
        notes = tuple(n for p in stages if p is not None for n in p.notes)
        return FrameResult(
            frame.source, frame.index, frame.width, frame.height, ms, tuple(detections), notes
        )
