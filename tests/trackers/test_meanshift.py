"""meanshift tracker: equation pieces, following a synthetic lamp, scale change, pipeline use."""

from __future__ import annotations

import numpy as np
import pytest

from tsrkit.core.types import Candidate, Detection, Frame
from tsrkit.plugin.base import Detector
from tsrkit.plugin.pipeline import Pipeline
from tsrkit_plugins.trackers import meanshift as ms


def lamp_frame(cx, cy, radius, index=0, seed=0, size=(120, 160)):
    """Grey noisy background and a lamp: saturated orange rim, paler yellow centre."""
    rng = np.random.default_rng(seed + index)
    image = rng.integers(90, 140, (*size, 1)).repeat(3, axis=2).astype(np.uint8)
    ys, xs = np.mgrid[: size[0], : size[1]]
    r = np.hypot(xs - cx, ys - cy) / radius
    inner, outer = r <= 0.5, (r > 0.5) & (r <= 1.0)
    image[inner] = (90, 220, 255)
    image[outer] = (0, 120, 255)
    return Frame(image, "lamp.mp4", index)


def lamp_detection(cx, cy, radius, state="red"):
    return Detection(Candidate.from_circle(cx, cy, radius, 1.0), state)


def make(**params):
    values = {p.name: p.default for p in ms.MeanShift.PARAMS}
    values.update(params)
    return ms.MeanShift(**values)


def test_histogram_similarity_and_weights():
    target = ms.kernel_histogram(np.array([0, 0, 1, 3]), np.array([1.0, 1, 2, 0]), 4)
    np.testing.assert_allclose(target, [0.5, 0.5, 0, 0])
    assert ms.bhattacharyya(target, target) == pytest.approx(1.0)
    assert ms.bhattacharyya(target, np.array([0, 0, 1.0, 0])) == 0.0
    candidate = np.array([0.25, 0.25, 0.5, 0])
    np.testing.assert_allclose(
        ms.pixel_weights(target, candidate, np.array([0, 2, 3])), [np.sqrt(2), 0, 0]
    )
    np.testing.assert_allclose(ms.epanechnikov_profile(np.array([0, 0.25, 1, 2])), [1, 0.75, 0, 0])


def test_mean_shift_step_is_weighted_mean():
    xs, ys = np.array([0.0, 10, 20]), np.array([0.0, 0, 30])
    z = ms.mean_shift_step(xs, ys, np.array([1.0, 1, 2]), np.array([1, 1, 0]))
    assert z == pytest.approx((5.0, 0.0))
    assert ms.mean_shift_step(xs, ys, np.zeros(3), np.ones(3)) is None


def test_follows_moving_lamp_for_30_frames():
    tracker = make()
    start = (40.0, 50.0)
    out = tracker.update(lamp_frame(*start, 12), [lamp_detection(*start, 12)])
    assert out[0].track_id == 0 and out[0].origin == "detected"
    assert not tracker.needs_detection()
    for i in range(1, 31):
        cx, cy = start[0] + 2.5 * i, start[1] + 0.8 * i
        (det,) = tracker.update(lamp_frame(cx, cy, 12, index=i), [])
        assert det.origin == "tracked" and det.track_id == 0 and det.state == "red"
        assert np.hypot(det.candidate.x - cx, det.candidate.y - cy) < 2.0


def test_survives_ten_percent_scale_change():
    tracker = make()
    tracker.update(lamp_frame(80, 60, 15), [lamp_detection(80, 60, 15)])
    (det,) = tracker.update(lamp_frame(83, 61, 16.5, index=1), [])
    assert np.hypot(det.candidate.x - 83, det.candidate.y - 61) < 2.0
    x0, _, x1, _ = det.candidate.bbox
    assert 30 <= x1 - x0 <= 34


def test_start_condition_and_track_end():
    tracker = make(min_size=20)
    small = [lamp_detection(40, 50, 5)]
    assert tracker.update(lamp_frame(40, 50, 5), small)[0].track_id is None
    assert tracker.needs_detection()
    tracker.update(lamp_frame(40, 50, 12), [lamp_detection(40, 50, 12)])
    empty = Frame(np.full((120, 160, 3), 120, np.uint8), "lamp.mp4", 2)
    assert tracker.update(empty, []) == []
    assert tracker.needs_detection()


class _OneLamp(Detector):
    name = "one-lamp"

    def __init__(self):
        super().__init__()
        self.calls = 0

    def detect(self, frame):
        self.calls += 1
        return [Candidate.from_circle(40 + 2 * frame.index, 50, 12, 1.0)]


def test_pipeline_detects_then_tracks():
    detector = _OneLamp()
    pipeline = Pipeline(detector, tracker=make())
    results = [pipeline.process(lamp_frame(40 + 2 * i, 50, 12, index=i)) for i in range(5)]
    assert detector.calls == 1
    assert [r.detections[0].origin for r in results] == ["detected"] + ["tracked"] * 4
    assert results[-1].detections[0].to_record()["track_id"] == 0
