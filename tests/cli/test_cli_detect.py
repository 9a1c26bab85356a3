"""``tsrkit detect`` and ``tsrkit plugins`` end to end, with the example plugin registered."""

import json
import sys
from pathlib import Path

import cv2
import numpy as np
import pytest
from click.testing import CliRunner

from tsrkit.cli.main import cli

EXAMPLE = Path(__file__).resolve().parents[2] / "examples" / "tsrkit-brightest-blobs"
RECORD_KEYS = {"source", "frame", "width", "height", "ms", "detections"}
DETECTION_KEYS = {
    "x",
    "y",
    "radius",
    "bbox",
    "lens_bbox",
    "score",
    "state",
    "state_scores",
    "origin",
}


@pytest.fixture
def example_plugin(registry, monkeypatch):
    monkeypatch.syspath_prepend(str(EXAMPLE))
    import tsrkit_brightest_blobs

    registry.add(tsrkit_brightest_blobs, "brightest-blobs", "tsrkit-brightest-blobs", "0.1.0")
    yield
    sys.modules.pop("tsrkit_brightest_blobs", None)


@pytest.fixture
def mixed_folder(tmp_path):
    folder = tmp_path / "in"
    folder.mkdir()
    for i in range(2):
        image = np.full((40, 60, 3), 30, np.uint8)
        cv2.circle(image, (15 + 20 * i, 20), 3, (40, 40, 255), -1)
        cv2.imwrite(str(folder / f"good{i}.png"), image)
    (folder / "zero.png").write_bytes(b"")
    jpeg = cv2.imencode(".jpg", np.full((64, 64, 3), 90, np.uint8))[1].tobytes()
    (folder / "cut.jpg").write_bytes(jpeg[: len(jpeg) // 2])
    (folder / "readme.txt").write_text("not an image")
    return folder


def test_detect_writes_records_and_reports_skips(example_plugin, mixed_folder, tmp_path):
    out = tmp_path / "dets.jsonl"
    result = CliRunner().invoke(
        cli,
        [
            "detect",
            str(mixed_folder),
            "--detector",
            "brightest-blobs",
            "--param",
            "top=1",
            "--out",
            str(out),
            "--draw",
            str(tmp_path / "draw"),
        ],
    )
    assert result.exit_code == 0, result.output
    records = [json.loads(line) for line in out.read_text().splitlines()]
    assert [Path(r["source"]).name for r in records] == ["good0.png", "good1.png"]
    for record, x in zip(records, (15, 35)):
        assert set(record) == RECORD_KEYS
        assert (record["width"], record["height"], record["frame"]) == (60, 40, 0)
        (det,) = record["detections"]
        assert set(det) == DETECTION_KEYS
        assert abs(det["x"] - x) <= 1 and abs(det["y"] - 20) <= 1
        assert det["state"] == "unknown"
    assert "2 frames" in result.stderr and "3 skipped" in result.stderr
    for name in ("zero.png", "cut.jpg", "readme.txt"):
        assert f"{name}:" in result.stderr
    assert len(list((tmp_path / "draw").glob("*.png"))) == 2


@pytest.mark.parametrize(
    "args, message",
    [
        (["--param", "top=zero"], "parameter 'top' must be an integer"),
        (["--param", "colour=red"], "unknown parameter 'colour'"),
        (["--param", "noequals"], "--param expects key=value"),
        (["--classifier", "nope"], "no classifier called 'nope'"),
        (["--key-every", "3", "--tracker", "meanshift"], "--key-every and --tracker"),
    ],
)
def test_bad_input_is_one_line_exit_2(example_plugin, mixed_folder, args, message):
    result = CliRunner().invoke(cli, ["detect", str(mixed_folder), "-d", "brightest-blobs", *args])
    assert result.exit_code == 2
    assert message in result.stderr
    assert "Traceback" not in result.output + result.stderr
    assert len(result.stderr.strip().splitlines()) == 1


def test_crashing_plugin_costs_a_frame_not_the_run(registry, mixed_folder):
    import tsrkit
    from tsrkit.plugin.hookspecs import hookimpl

    class Crashy(tsrkit.Detector):
        name = "crashy"

        def detect(self, frame):
            if frame.source.endswith("good0.png"):
                raise RuntimeError("kaput")
            return []

    class Plugin:
        @hookimpl
        def register_detectors(register):
            register(Crashy)

    registry.add(Plugin, "crashy")
    result = CliRunner().invoke(cli, ["detect", str(mixed_folder), "-d", "crashy"])
    assert result.exit_code == 0
    assert len(result.stdout.splitlines()) == 1
    assert "plugin error: RuntimeError: kaput" in result.stderr


def test_plugins_json_lists_name_kind_package_version_summary(example_plugin):
    result = CliRunner().invoke(cli, ["plugins", "--json"])
    listing = json.loads(result.stdout)
    (entry,) = [p for p in listing if p["name"] == "brightest-blobs"]
    assert entry["kind"] == "detector" and entry["package"] == "tsrkit-brightest-blobs"
    assert entry["version"] == "0.1.0" and entry["summary"].startswith("Brightest")
    assert [p["name"] for p in entry["params"]] == ["percentile", "top", "min_area"]


@pytest.fixture
def needs_model(registry):
    """A detector that, like a trainable one without its model, raises TsrkitError on use."""
    import tsrkit
    from tsrkit.plugin.hookspecs import hookimpl

    class NeedsModel(tsrkit.Detector):
        name = "needs-model"

        def detect(self, frame):
            raise tsrkit.TsrkitError("needs-model needs a model: pass --param model=M")

    class Plugin:
        @hookimpl
        def register_detectors(register):
            register(NeedsModel)

    registry.add(Plugin, "needs-model")


def test_setup_error_from_a_plugin_stops_detect_with_one_line(needs_model, mixed_folder):
    result = CliRunner().invoke(cli, ["detect", str(mixed_folder), "-d", "needs-model"])
    assert result.exit_code == 2
    assert result.stderr.strip() == "Error: needs-model needs a model: pass --param model=M"
    assert result.stdout == ""


def test_agree_drops_a_light_seen_on_one_frame_of_a_video(example_plugin, tmp_path):
    video = tmp_path / "drive.mp4"
    writer = cv2.VideoWriter(str(video), cv2.VideoWriter_fourcc(*"mp4v"), 10.0, (64, 48))
    for t in range(6):
        image = np.full((48, 64, 3), 30, np.uint8)
        cv2.circle(image, (14 + t, 20), 4, (40, 40, 255), -1)
        if t == 2:
            cv2.circle(image, (48, 30), 4, (40, 40, 255), -1)
        writer.write(image)
    writer.release()
    counts = {}
    for agree in ("1", "2"):
        out = tmp_path / f"agree{agree}.jsonl"
        args = ["detect", str(video), "-d", "brightest-blobs", "-p", "top=2", "-o", str(out)]
        result = CliRunner().invoke(cli, [*args, "--agree", agree])
        assert result.exit_code == 0, result.output
        records = [json.loads(line) for line in out.read_text().splitlines()]
        assert [r["frame"] for r in records] == list(range(6))
        counts[agree] = [len(r["detections"]) for r in records]
    assert counts["1"][2] == 2 and counts["2"][2] == 1
    assert counts["2"] == [1] * 6
