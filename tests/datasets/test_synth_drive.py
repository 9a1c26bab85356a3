"""tsrkit.synth.drive: the rendered drive's schedule, motion, files and ground truth."""

import json

import numpy as np
import pytest

from tsrkit.geo import read_signals, read_track, traversals
from tsrkit.runner.inputs import iter_video
from tsrkit.synth.drive import (
    HEAD_PAST,
    Camera,
    DriveOptions,
    light_state,
    plan_drive,
    plan_nodes,
    render_drive,
)

TINY = DriveOptions(width=160, height=120, fps=5, route=("left",), lead_m=40, tail_m=15)


def test_light_schedule_by_hand():
    options = DriveOptions(green_s=10, yellow_s=3)
    node = plan_nodes(options, np.random.default_rng(0))[0]
    node = type(node)(0, 0, "N", "N", "through", True, 0.0)
    assert [light_state(options, node, "N", t) for t in (0, 9.9, 10, 12.9, 13, 25.9, 26)] == [
        "green",
        "green",
        "yellow",
        "yellow",
        "red",
        "red",
        "green",
    ]
    # the cross street is red while north-south is green or yellow, then green
    assert [light_state(options, node, "E", t) for t in (0, 12.9, 13, 23, 25.9)] == [
        "red",
        "red",
        "green",
        "yellow",
        "yellow",
    ]


def test_the_car_stops_at_the_line_for_a_red():
    # offset 13 s: the light is red from t = 0 to 13 s, so the car arriving at ~4 s waits
    drive = plan_drive(DriveOptions(route=("through",), lead_m=60, light_offset=13.0))
    stopped = np.flatnonzero(drive.speed < 0.05)
    assert len(stopped) > 5 * 14  # waits several seconds
    y = drive.y[stopped]
    assert np.all(y < -HEAD_PAST + 0.5) and np.all(y > -HEAD_PAST - 3)
    assert drive.speed.max() <= DriveOptions().cruise + 1e-9


def test_camera_projects_a_point_ahead():
    camera = Camera(0.0, 0.0, np.pi / 2, 100.0, 200, 100)  # looking north
    u, v, depth = camera.project((1.0, 10.0, 1.3 + 2.0))
    assert (u, v, depth) == pytest.approx((100 + 10.0, 50 - 20.0, 10.0))


def test_tiny_drive_files_and_truth(tmp_path):
    folder = render_drive(tmp_path / "d", TINY, seed=3)
    summary = json.loads((folder / "drive.json").read_text())
    frames = list(iter_video(folder / "drive.mp4"))
    assert len(frames) == summary["frames"] and frames[0].image.shape == (120, 160, 3)
    truth = [json.loads(line) for line in (folder / "truth.jsonl").open()]
    assert [r["frame"] for r in truth] == list(range(len(frames)))
    track, signals = read_track(folder / "gps.csv"), read_signals(folder / "map.osm")
    assert len(signals) == 1 and len(signals.crossing_lat) == 1  # the crossing kept apart
    found = traversals(track, signals, 30.0)
    assert [t.movement for t in found] == ["left"] == [summary["traversals"][0]["movement"]]
    # a lit lens in full view is brighter than the sky around its housing
    lit = [
        (r["frame"], light)
        for r in truth
        for light in r["lights"]
        if light["status"] == "in" and light["visible"] == 1 and light["radius"] > 1
    ]
    assert lit
    frame, light = lit[len(lit) // 2]
    image = frames[frame].image.astype(int)
    x, y = int(light["x"]), int(light["y"])
    assert image[y, x].sum() > image[y, x - int(3 * light["radius"])].sum() - 60
    again = render_drive(tmp_path / "e", TINY, seed=3)
    assert (again / "truth.jsonl").read_text() == (folder / "truth.jsonl").read_text()
    assert (again / "gps.csv").read_text() == (folder / "gps.csv").read_text()


def test_options_are_checked():
    with pytest.raises(ValueError, match="route"):
        DriveOptions(route=("u-turn",))
    with pytest.raises(ValueError, match="block"):
        DriveOptions(block=40)
