"""Lee's channelizer detector (2017, 3.5) and depth from known height (Eq. 3.5-3.7)."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from tsrkit.core.depth import PANEL_HEIGHT_M, distance_from_height, lateral_offset, vertical_offset
from tsrkit.core.records import DetectionRecord
from tsrkit.core.types import Candidate, Detection, Frame
from tsrkit.eval.overlap import match_by_iou
from tsrkit.plugin.registry import get_registry
from tsrkit.synth.workzone import generate, render
from tsrkit_plugins.detectors.channelizer import diagonal_edges, panel_height, runs


def test_depth_equations_on_hand_numbers():
    assert pytest.approx(0.6096) == PANEL_HEIGHT_M
    # A 24 in panel 60.96 px tall under f = 1000 px stands 10 m away.
    assert distance_from_height(60.96, PANEL_HEIGHT_M, 1000.0) == pytest.approx(10.0)
    assert lateral_offset(740.0, 640.0, 10.0, 1000.0) == pytest.approx(1.0)
    assert vertical_offset(300.0, 360.0, 20.0, 1200.0) == pytest.approx(-1.0)
    with pytest.raises(ValueError, match="positive"):
        distance_from_height(0.0, PANEL_HEIGHT_M, 1000.0)


def test_diagonal_filters_on_tiny_images():
    # g gives I(y+1, x+1) - I(y, x); its flip g' gives I(y+1, x) - I(y, x+1).
    dot = np.zeros((3, 3), np.uint8)
    dot[1, 1] = 9
    expected = np.array([[9, 9, 0], [9, 9, 0], [0, 0, 0]], np.float32)
    np.testing.assert_allclose(diagonal_edges(dot), expected)
    # At (0, 0): g gives 3, g' gives 0 - 4: the magnitude is 5.
    pair = np.array([[0, 4, 0], [0, 3, 0], [0, 0, 0]], np.uint8)
    assert diagonal_edges(pair)[0, 0] == pytest.approx(5.0)


def test_runs_bridge_small_gaps():
    flags = np.array([0, 1, 1, 0, 0, 1], bool)
    assert runs(flags, max_gap=0) == [(1, 3), (5, 6)]
    assert runs(flags, max_gap=2) == [(1, 6)]
    assert runs(np.zeros(4, bool), max_gap=1) == []


def test_panel_height_reads_a_partly_covered_row():
    image = np.zeros((40, 10, 3), np.uint8)
    image[..., 2] = 100
    image[10:20, :, 2] = 240
    image[9, :, 2] = 170  # half of that row is panel
    assert panel_height(image, (2, 9, 8, 20)) == pytest.approx(10.5)


def test_distance_survives_the_record_round_trip():
    candidate = Candidate.from_box((10, 10, 20, 40), 1.0, state="channelizer")
    record = DetectionRecord.from_detection(Detection(replace(candidate, distance_m=12.3456), "x"))
    assert record.to_json()["distance_m"] == pytest.approx(12.346, abs=1e-3)
    assert DetectionRecord.from_json(record.to_json()) == record
    assert "distance_m" not in DetectionRecord.from_detection(Detection(candidate, "x")).to_json()


@pytest.fixture(scope="module")
def detector():
    return get_registry().create("detector", "channelizer", {})


def test_detector_finds_rendered_channelizers_and_their_depth(detector):
    found = total = false = 0
    errors = []
    for sample in generate(25, seed=11):
        candidates = detector.detect(sample.load())
        boxes = [a.bbox for a in sample.annotations]
        pairs = match_by_iou([c.bbox for c in candidates], [c.score for c in candidates], boxes)
        found, total = found + len(pairs), total + len(boxes)
        false += len(candidates) - len(pairs)
        for i, j in pairs:
            truth = sample.annotations[j].attributes["distance_m"]
            if 10 <= truth <= 50:
                errors.append(abs(candidates[i].distance_m / truth - 1))
    assert found / total >= 0.7
    assert false / max(found + false, 1) <= 0.1
    assert np.median(errors) <= 0.03 and np.mean(np.array(errors) <= 0.05) >= 0.85


def test_no_channelizer_among_cones_barriers_and_lane_markings(detector):
    rng = np.random.default_rng(5)
    for _ in range(10):
        image, annotations = render(rng, channelizers=(0, 1))
        assert annotations == ()
        frame = Frame(image, "distractors", metadata={"focal_px": 1100.0, "horizon_y": 360.0})
        assert detector.detect(frame) == []


def test_without_focal_length_there_is_no_distance(detector):
    sample = generate(1, seed=2).samples[0]
    frame = sample.load()
    bare = Frame(frame.image, frame.source, metadata={"horizon_y": 360.0})
    assert detector.detect(bare) and all(c.distance_m is None for c in detector.detect(bare))
    assert all(c.distance_m is not None for c in detector.detect(frame))
