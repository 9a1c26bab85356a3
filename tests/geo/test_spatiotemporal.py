"""tsrkit.spatiotemporal: Zheng 2016's equations on hand-computed cases, the passes on a
scripted clip, and temporal accuracy (5.4)."""

import math

import cv2
import numpy as np
import pytest

from tsrkit.spatiotemporal.association import association_score, position_change_score
from tsrkit.spatiotemporal.evaluate import (
    TruthError,
    evaluate_traversal,
    read_truth,
    temporal_accuracy,
    track_light,
)
from tsrkit.spatiotemporal.flow import enclosing_extent, project
from tsrkit.spatiotemporal.passes import first_pass, long_range, recognise, second_pass, select
from tsrkit.spatiotemporal.points import Point, Track, frame_status
from tsrkit.spatiotemporal.ranges import short_range, trajectory_distance


def red(x, y, r=2.0, score=1.0, origin="detected"):
    return Point(x, y, r, "red", {"red": score}, origin)


def test_eq_3_37_state_machine_cases():
    # same colour: 1 - pc; green -> yellow up: 1 - pc/3; red -> green down: 1 - pc/6
    assert position_change_score("green", "green", 0.25, 0.0, 0.25) == 0.75
    assert position_change_score("green", "yellow", 2.4, 0.0, -2.4) == pytest.approx(0.2)
    assert position_change_score("yellow", "red", 2.4, 0.0, -2.4) == pytest.approx(0.2)
    assert position_change_score("red", "green", 4.8, 0.0, 4.8) == pytest.approx(0.2)
    # the wrong direction, a change the machine forbids, and unknown all score 0
    assert position_change_score("green", "yellow", 2.4, 0.0, 2.4) == 0.0
    assert position_change_score("yellow", "green", 2.4, 0.0, 2.4) == 0.0
    assert position_change_score("unknown", "unknown", 0.0, 0.0, 0.0) == 0.0
    # slack tolerates jitter across the head's axis
    assert position_change_score("red", "green", 4.8, -0.3, 4.8) == 0.0
    assert position_change_score("red", "green", 4.8, -0.3, 4.8, slack=0.5) > 0


def test_eq_3_35_to_3_38_association_by_hand():
    first = Point(100.0, 50.0, 2.0, "green", {"green": 0.64, "yellow": 0.1})
    later = Point(100.0, 45.0, 2.5, "yellow", {"yellow": 0.81, "green": 0.2})
    # pc = 5 / 2 = 2.5, moving up: green -> yellow gives (1 - 2.5/3) * exp(sqrt(0.64 * 0.81))
    expected = (1 - 2.5 / 3) * math.exp(math.sqrt(0.64 * 0.81))
    assert association_score(first, later) == pytest.approx(expected)
    # the other order: the lens moved down, so only red -> green (1 - pc/6) is allowed, and
    # with no red evidence exp(ccs) = 1
    assert association_score(later, first) == pytest.approx(1 - 2.5 / 6)


def test_projection_follows_a_translation():
    rng = np.random.default_rng(0)
    texture = cv2.GaussianBlur(rng.integers(0, 255, (160, 200)).astype(np.uint8), (0, 0), 2.0)
    shifted = cv2.warpAffine(texture, np.float32([[1, 0, 3], [0, 1, -2]]), (200, 160))
    for margin in (48, 0):
        moved = project(red(100.0, 80.0, 4.0), texture, shifted, margin)
        assert moved.x == pytest.approx(103.0, abs=0.3)
        assert moved.y == pytest.approx(78.0, abs=0.3)
        assert moved.radius == pytest.approx(4.0, abs=0.3)
        assert (moved.origin, moved.status, moved.state) == ("dof", "in", "red")


def test_projection_flags_a_candidate_leaving_the_frame():
    rng = np.random.default_rng(1)
    texture = cv2.GaussianBlur(rng.integers(0, 255, (120, 160)).astype(np.uint8), (0, 0), 2.0)
    up = cv2.warpAffine(texture, np.float32([[1, 0, 0], [0, 1, -6]]), (160, 120))
    moved = project(red(80.0, 7.0, 3.0), texture, up)
    assert moved.y < 4.0 and moved.status == "partial"  # Farneback is coarse at the border
    assert frame_status(80.0, -9.0, 3.0, 160, 120) == "out"


def test_eq_3_30_to_3_32_extent_of_moved_points():
    assert enclosing_extent(np.array([1.0, 5.0, 3.0]), np.array([2.0, 2.0, 8.0])) == (
        3.0,
        5.0,
        3.0,
    )


def test_short_range_by_trajectory_distance_with_a_stop():
    # 1 m per frame, then 5 frames stopped at x = 20, then on: the stop adds no distance
    x = np.concatenate([np.arange(0.0, 20.0), np.full(5, 20.0), np.arange(21.0, 40.0)])
    y = np.zeros_like(x)
    anchor = 30  # x = 26
    assert trajectory_distance(x, y, anchor)[20] == 6.0
    assert short_range(x, y, anchor, 0, len(x) - 1) == (16, 35)
    assert short_range(x, y, anchor, 18, 33) == (18, 33)  # clipped to the clip


class ScriptedClip:
    """A clip whose detections are given per frame and whose flow moves nothing."""

    def __init__(self, whole, near=None, first=0, last=10):
        self.whole, self.near, self.first, self.last = whole, near or {}, first, last

    def detect(self, i):
        return self.whole.get(i, [])

    def detect_near(self, i, around):
        return [
            p
            for p in self.near.get(i, [])
            if math.hypot(p.x - around.x, p.y - around.y) <= 2 * around.radius
        ]

    def project(self, point, source, target):
        return Point(point.x, point.y, point.radius, point.state, point.scores, "dof")

    def project_all(self, points, source, target):
        return [self.project(p, source, target) for p in points]


def test_first_pass_associates_backwards_and_fills_with_dof():
    clip = ScriptedClip(
        {
            5: [red(10, 10)],
            4: [red(10.5, 10), red(60, 10, score=0.5)],
            3: [],
            2: [red(10, 10.4)],
        }
    )
    tracks = first_pass(clip, 2, 5)
    assert len(tracks) == 2
    lens, other = tracks
    assert [lens.points[i].origin for i in (5, 4, 3, 2)] == [
        "detected",
        "detected",
        "dof",
        "detected",
    ]
    assert other.points[4].x == 60 and other.points[3].origin == "dof" and 5 not in other.points
    assert lens.stability == 3.0 and other.stability == 0.5
    assert select(tracks, 1) == [lens]


def test_second_pass_replaces_dof_and_extends_forward():
    track = Track(0, {2: red(10, 10), 3: red(10, 10, origin="dof")})
    clip = ScriptedClip({}, near={3: [red(10.5, 10.5)], 4: [red(11, 10)], 6: [red(11, 10)]})
    second_pass(clip, [track], 2, 6)
    assert track.points[3].origin == "detected" and track.points[3].x == 10.5
    assert track.points[4].x == 11  # the head extended by forward DOF
    assert 5 not in track.points and 6 not in track.points  # no detection at 5: it stops


def test_long_range_goes_both_ways_and_halts():
    track = Track(0, {4: red(10, 10), 5: red(10, 10)})
    near = {3: [red(10, 10)], 2: [red(10.5, 10)], 0: [red(10, 10)], 6: [red(10, 10)]}
    long_range(ScriptedClip({}, near, first=0, last=8), [track], 4, 5)
    assert sorted(track.points) == [2, 3, 4, 5, 6]  # frame 1 and 7 had nothing: halted


def test_recognise_keeps_the_top_tracks():
    whole = {i: [red(10, 10), red(50, 50, score=0.2)] for i in range(3, 6)}
    tracks, made = recognise(ScriptedClip(whole, first=0, last=6), 3, 5, top=1)
    assert made == 2 and len(tracks) == 1 and tracks[0].stability == 3.0


def truth_lines(tmp_path, frames):
    path = tmp_path / "truth.jsonl"
    lines = []
    for frame, state in frames:
        light = {"id": "A", "state": state, "bbox": [8, 8, 12, 12], "status": "in"}
        lines.append(f'{{"frame": {frame}, "lights": [{__import__("json").dumps(light)}]}}')
    path.write_text("\n".join(lines) + "\n")
    return path


def test_temporal_accuracy_by_hand(tmp_path):
    truth = read_truth(truth_lines(tmp_path, [(0, "red"), (1, "red"), (2, "green"), (3, "green")]))
    track = Track(
        0,
        {
            0: red(10, 10),
            1: red(10.5, 10),
            2: red(10, 10, origin="dof"),  # carries red into a green frame: wrong
            3: Point(10, 11, 2.0, "green", {"green": 0.9}),
        },
    ).to_json()
    assert track_light(track, truth) == "A"
    assert temporal_accuracy(track, "A", truth) == {
        "candidates": 4,
        "correct": 3,
        "detected": 3,
        "detected_correct": 3,
    }
    far = Track(1, {0: red(40, 40), 1: red(40, 40)}).to_json()
    result = evaluate_traversal({"traversal": 0, "tracks": [track, far]}, truth)
    assert (result["true_tracks"], result["false_tracks"]) == (1, 1)
    assert result["temporal_accuracy"] == 0.75 and result["detected_accuracy"] == 1.0


def test_malformed_truth_is_one_clear_error(tmp_path):
    path = tmp_path / "truth.jsonl"
    path.write_text('{"frame": 0, "lights": []}\n{"frame": 1, "lights": [{"id": 1}]}\n')
    with pytest.raises(TruthError, match=r"truth.jsonl: line 2: not a frame record"):
        read_truth(path)
    path.write_text('{"frame": 0, "lights": [{"id": 1, "state": "red", "bbox": [1, 2, 3]}]}\n')
    with pytest.raises(TruthError, match="line 1: a light's bbox"):
        read_truth(path)
    with pytest.raises(TruthError, match="no such file"):
        read_truth(tmp_path / "missing.jsonl")
