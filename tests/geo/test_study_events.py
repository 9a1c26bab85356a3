"""Drives with behaviour, controlling-signal timelines and driving events (issue 39): the true
events of planned drives, the event rules, the Lee 5.3.4 fusion, the GPS kinematics and the
scoring, without rendering; ``test_study_track.py`` runs ``tsrkit track`` on a rendered drive."""

from itertools import pairwise

import numpy as np
import pytest

from tsrkit.spatiotemporal.egomotion import dated_rest, rest_edges
from tsrkit.spatiotemporal.events import Dilemma, Interval, Motion, derive_events, until_crossing
from tsrkit.spatiotemporal.kinematics import approach_motion, approach_of
from tsrkit.spatiotemporal.scoring import match_events, pair_traversals, timeline_scores
from tsrkit.spatiotemporal.timeline import controlling_tracks, fused_states, state_intervals
from tsrkit.synth.behaviour import true_timeline, truth_rows
from tsrkit.synth.drive import DriveOptions, plan_drive

MIXED = DriveOptions(
    fps=10, random_nodes=12, signal_fraction=1.0, run_share=0.4, all_red_s=1.0, trucks=False
)


@pytest.fixture(scope="module")
def mixed():
    drive = plan_drive(MIXED, seed=3)
    return drive, *truth_rows(drive)


def test_all_red_keeps_the_default_cycle_and_lengthens_the_red():
    drive = plan_drive(DriveOptions(fps=10, light_offset=0.0, all_red_s=2.0), 0)
    node = drive.route.nodes[0]
    kinds = [(i.kind, round(i.end - i.time, 3)) for i in true_timeline(drive, node, 0.0, 30.0)]
    assert kinds[:3] == [("green", 10.0), ("yellow", 3.0), ("red", 17.0)]  # 2 + 13 + 2
    assert DriveOptions().cycle == 26.0  # the default two-phase cycle is unchanged
    with pytest.raises(ValueError, match="run_share"):
        DriveOptions(run_share=1.5)


def test_truth_of_a_mixed_drive(mixed):
    drive, timelines, events = mixed
    kinds = {e["kind"] for e in events}
    assert {"stop", "go", "red_crossing", "red_onset"} <= kinds
    runners = {k for k, n in enumerate(n for n in drive.route.nodes if n.signalised) if n.runs}
    for event in events:
        if event["kind"] == "red_crossing":  # only a driver who ignores the signal runs a red
            assert event["traversal"] in runners and event["state"] == "red"
            assert "red since" in event["evidence"]
        if event["kind"] == "stop":
            assert abs(event["distance"] - 0.5) < 0.1  # the car halts 0.5 m before the line
    for number in {t["traversal"] for t in timelines}:
        rows = [t for t in timelines if t["traversal"] == number]
        assert all(a["end"] == b["time"] for a, b in pairwise(rows))


def test_events_from_a_timeline_and_motion():
    t = np.arange(0, 20, 0.1)
    speed = np.where(t < 6, 12.0, np.clip(12.0 - 3.0 * (t - 6), 0, None))
    distance = 60.0 - np.cumsum(speed) * 0.1
    distance -= distance[int(10 / 0.1)]  # at rest on the stop position from t = 10
    intervals = [Interval("green", 0, 4), Interval("yellow", 4, 8), Interval("red", 8, 20)]
    events = derive_events(7, intervals, Motion(t, distance, speed), 0.0)
    assert [e["kind"] for e in events] == ["amber_onset", "red_onset", "stop"]
    amber = events[0]
    assert amber["traversal"] == 7 and amber["speed"] == 12.0 and amber["zone"] == "can_stop"
    assert events[2]["time"] == pytest.approx(10.0, abs=0.11)
    through = Motion(t, 30.0 - 12.0 * t, np.full(len(t), 12.0))  # crosses at 2.5 s, on green
    assert derive_events(0, intervals, through, 0.0) == []
    late = Motion(t, 100.0 - 12.0 * t, np.full(len(t), 12.0))  # crosses at 8.33 s, on red
    flagged = [e for e in derive_events(0, intervals, late, 0.0) if e["kind"] == "red_crossing"]
    assert len(flagged) == 1 and flagged[0]["evidence"].startswith("red since 0.33 s")
    cut = until_crossing(intervals, late)
    assert cut[-1].kind == "red" and cut[-1].end == pytest.approx(100 / 12)
    assert Dilemma().zone(0.0, 10.0, 3.0) == "" and Dilemma().zone(12.0, 30.0, None) == ""


def _track(ident, x, y, states, first=0, confidence=0.8):
    return {
        "id": ident,
        "points": [
            {
                "frame": first + k,
                "x": x,
                "y": y,
                "radius": 2.0,
                "origin": "detected",
                "status": "in",
                "state": s,
                "confidence": confidence,
            }
            for k, s in enumerate(states)
        ],
    }


def test_controlling_heads_are_fused_and_the_cross_street_head_left_out():
    ahead = ["red"] * 20 + ["green"] * 20
    heads = [
        _track(1, 250, 80, ahead),
        _track(2, 300, 85, ahead[:18] + ["yellow", "yellow"] + ahead[20:]),  # agrees 95 %
        _track(3, 460, 90, ["green"] * 20 + ["yellow"] * 20),  # the cross street, at the side
        _track(4, 240, 300, ["yellow"] * 40),  # below the horizon: no head
    ]
    chosen = controlling_tracks(heads, (480, 356), 39)
    assert [t["id"] for t in chosen] == [1, 2]
    states, votes = fused_states(chosen, 0, 39, 10.0)
    intervals = state_intervals(states, votes, 0, 10.0, 1000.0)
    assert [i.kind for i in intervals] == ["red", "green"]
    assert intervals[1].time == pytest.approx(1001.95)  # half-way between frames 19 and 20
    gap = [_track(1, 250, 80, ["red"] * 5), _track(1, 250, 80, ["red"] * 5, first=30)]
    states, _ = fused_states(gap, 0, 39, 10.0)
    assert states[4] == "red" and states[15] == "unknown"  # a long gap is unknown (Lee 5.3.4)


def test_gps_kinematics_date_a_stop_and_the_pull_away():
    rng = np.random.default_rng(5)
    t = np.arange(0.0, 30.0, 1.0)
    fine = np.arange(0.0, 30.0, 0.01)
    v = np.clip(np.minimum(12.0 - 3.0 * (fine - 4.0), 12.0), 0, None)
    v = np.where(fine >= 16.0, np.clip(2.0 * (fine - 16.0), 0, 12.0), v)
    s = np.cumsum(v) * 0.01
    y = -80.0 + s
    fx = np.interp(t, fine, np.full(len(fine), 1.75)) + rng.normal(0, 1.0, len(t))
    fy = np.interp(t, fine, y) + rng.normal(0, 1.0, len(t))
    approach = approach_of(fx, fy, t, np.zeros(2), 25.0, np.zeros((0, 2)))
    assert approach.heading @ np.array((0.0, 1.0)) > 0.99 and approach.source == "offset"
    motion = approach_motion(t, approach.distance(fx, fy), np.arange(0.0, 29.0, 0.1))
    rest = np.flatnonzero(motion.speed < 0.1)
    assert motion.time[rest[0]] == pytest.approx(8.0, abs=0.5)  # 12 m/s at 3 m/s^2 from 4 s
    assert motion.time[rest[-1]] == pytest.approx(16.0, abs=0.5)
    stop_line = approach_of(fx, fy, t, np.zeros(2), 25.0, np.array([[2.0, -10.0], [-30, 5]]))
    assert stop_line.source == "osm" and stop_line.stop.tolist() == [2.0, -10.0]


def test_scoring_pairs_traversals_and_matches_events(mixed):
    _, timelines, events = mixed
    shifted = [{**r, "traversal": r["traversal"] + 100} for r in timelines]
    pairs = pair_traversals(shifted, timelines)
    assert pairs == {r["traversal"] + 100: r["traversal"] for r in timelines}
    moved = [{**e, "traversal": e["traversal"] + 100, "time": e["time"] + 0.4} for e in events]
    assert len(match_events(moved, events, pairs)) == len(events)
    late = [{**e, "time": e["time"] + 0.6} for e in moved]
    assert match_events(late, events, pairs) == []
    assert timeline_scores(shifted, timelines, pairs)["accuracy"] == 1.0


def test_the_video_dates_the_ends_of_a_stop():
    frames = list(range(40))
    moving = [5.0] * 12 + [0.6, 0.8, 0.5, 1.2] * 4 + [0.7, 0.6] + [4.0] * 10
    # the GPS says 10..28; the image stops changing at frame 12 and changes again at 30
    assert rest_edges(frames, moving, 10, 28, 5) == (12, 29)
    t = np.arange(40) / 10.0
    speed = np.where((np.arange(40) >= 10) & (np.arange(40) <= 28), 0.0, 3.0)
    dated = dated_rest(Motion(t, np.zeros(40), speed), frames, dict(zip(frames, moving)), 10)
    assert np.flatnonzero(dated.speed == 0).tolist() == list(range(12, 30))
