"""The pipeline: detector alone, with a classifier, and a tracker that pauses detection."""

import numpy as np

import tsrkit
from tsrkit.core.types import Candidate, Detection, Frame


class Fixed(tsrkit.Detector):
    name = "fixed"

    def __init__(self, **params):
        super().__init__(**params)
        self.calls = 0

    def detect(self, frame):
        self.calls += 1
        return [
            Candidate.from_circle(5, 6, 2, 0.9, state="red"),
            Candidate.from_circle(1, 1, 1, 0.1),
        ]


class Greenify(tsrkit.Classifier):
    name = "greenify"

    def classify(self, frame, candidates):
        return [Detection(c, "green", {"green": 1.0}) for c in candidates]


class Sticky(tsrkit.Tracker):
    """Detects on the first frame of a video, then reports the same object as tracked."""

    name = "sticky"

    def reset(self):
        self.kept = None

    def needs_detection(self):
        return self.kept is None

    def update(self, frame, detections):
        if self.kept is None:
            self.kept = detections[0]
            return list(detections)
        return [Detection(self.kept.candidate, self.kept.state, origin="tracked", track_id=1)]


def frame(source="v.mp4", index=0):
    return Frame(np.zeros((12, 12, 3), np.uint8), source, index)


def test_detector_alone_keeps_its_own_states():
    result = tsrkit.Pipeline(Fixed()).process(frame())
    assert [d.state for d in result.detections] == ["red", "unknown"]
    record = result.to_record()
    assert set(record) == {"source", "frame", "width", "height", "ms", "detections"}
    assert record["detections"][0]["bbox"] == [3.0, 4.0, 7.0, 8.0]
    assert record["ms"] >= 0


def test_classifier_sets_states():
    result = tsrkit.Pipeline(Fixed(), Greenify()).process(frame())
    assert [d.state for d in result.detections] == ["green", "green"]
    assert result.detections[0].state_scores == {"green": 1.0}


def test_tracker_pauses_detection_and_resets_per_video():
    detector = Fixed()
    pipeline = tsrkit.Pipeline(detector, tracker=Sticky())
    origins = [[d.origin for d in pipeline.process(frame("a.mp4", i)).detections] for i in range(3)]
    assert origins == [["detected", "detected"], ["tracked"], ["tracked"]]
    assert detector.calls == 1
    pipeline.process(frame("b.mp4", 0))
    assert detector.calls == 2  # a new video resets the tracker


def test_classifier_sees_tracked_objects_and_keeps_their_identity():
    pipeline = tsrkit.Pipeline(Fixed(), Greenify(), Sticky())
    pipeline.process(frame("a.mp4", 0))
    (tracked,) = pipeline.process(frame("a.mp4", 1)).detections
    assert (tracked.state, tracked.origin, tracked.track_id) == ("green", "tracked", 1)


class KeepFirstWithHousing(tsrkit.Verifier):
    """Keeps the best candidate and gives it a housing three lenses tall."""

    name = "keep-first"

    def verify(self, frame, candidates):
        from dataclasses import replace

        c = candidates[0]
        housing = (c.x - 2 * c.radius, c.y - 2 * c.radius, c.x + 2 * c.radius, c.y + 8 * c.radius)
        return [replace(c, housing=housing, housing_score=0.8)]


def test_verifier_rejects_and_adds_a_housing_reported_as_bbox():
    result = tsrkit.Pipeline(Fixed(), verifier=KeepFirstWithHousing()).process(frame())
    (only,) = result.to_record()["detections"]
    assert only["bbox"] == [1.0, 2.0, 9.0, 22.0]
    assert only["lens_bbox"] == [3.0, 4.0, 7.0, 8.0]
    assert only["housing_score"] == 0.8
    assert only["state"] == "red"
