"""Temporal agreement: a light kept from its first frame when it persists, a one-frame light
dropped, and nothing linked across videos."""

import pytest

from tsrkit.core.types import Candidate, Detection, Skipped
from tsrkit.plugin.pipeline import FrameResult
from tsrkit.runner.agreement import Agreement


def frame(index, *centres, source="drive.mp4"):
    detections = tuple(Detection(Candidate.from_circle(x, y, 3.0, 1.0), "red") for x, y in centres)
    return FrameResult(source, index, 640, 480, 1.0, detections)


def kept(items, frames):
    return [
        [(d.candidate.x, d.candidate.y) for d in r.detections]
        if isinstance(r, FrameResult)
        else r.reason
        for r, _ in Agreement(frames).filter((item, None) for item in items)
    ]


def test_a_persistent_light_is_kept_from_its_first_frame_and_a_flash_is_dropped():
    moving = [(100.0 + 4 * t, 50.0 - t) for t in range(4)]
    items = [
        frame(0, moving[0]),
        frame(1, moving[1], (400.0, 300.0)),  # a one-frame false light
        frame(2, moving[2]),
        frame(3, moving[3]),
    ]
    assert kept(items, 3) == [[moving[0]], [moving[1]], [moving[2]], [moving[3]]]
    assert kept(items, 1)[1] == [moving[1], (400.0, 300.0)]
    assert kept(items, 5) == [[], [], [], []]  # four frames are not five


def test_frames_pass_in_order_with_skipped_inputs_in_place():
    items = [frame(0, (10.0, 10.0)), Skipped("drive.mp4#1", "frame could not be decoded")]
    items += [frame(2, (11.0, 10.0))]
    assert kept(items, 2) == [[(10.0, 10.0)], "frame could not be decoded", [(11.0, 10.0)]]


def test_lights_of_another_video_or_far_away_do_not_link():
    assert kept([frame(0, (10.0, 10.0)), frame(1, (10.0, 10.0), source="other.mp4")], 2) == [
        [],
        [],
    ]
    assert kept([frame(0, (10.0, 10.0)), frame(1, (60.0, 10.0))], 2) == [[], []]


def test_bad_settings_are_refused():
    with pytest.raises(ValueError, match="frames >= 1"):
        Agreement(0)
