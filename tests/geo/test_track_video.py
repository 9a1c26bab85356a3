"""``tsrkit track VIDEO`` end to end on a short rendered drive: traversal, movement, tracked
states (temporal accuracy, Zheng 5.4), outputs, resume from the cache, and bad input."""

import json

import pytest
from click.testing import CliRunner

from tsrkit.cli.main import cli
from tsrkit.synth.drive import DriveOptions, render_drive

# 480x356 as Zheng's video, 10 fps, 75 m through one intersection on green (about 6 s).
DRIVE = DriveOptions(fps=10, route=("through",), lead_m=50, tail_m=25, light_offset=0.0)
PLUGINS = ["-c", "ab-hist", "-p", "h_peak=0.8", "-p", "radii=1,2,3,4,5,6"]


@pytest.fixture(scope="module")
def drive(tmp_path_factory):
    return render_drive(tmp_path_factory.mktemp("drive"), DRIVE, seed=1)


def track_args(folder, out, *extra):
    return [
        "track",
        str(folder / "drive.mp4"),
        "--gps",
        str(folder / "gps.csv"),
        "--map",
        str(folder / "map.osm"),
        "--out",
        str(out),
        "--quiet",
        *PLUGINS,
        *extra,
    ]


def test_a_rendered_drive_is_recovered_and_resumes(drive, tmp_path):
    out = tmp_path / "run"
    args = track_args(drive, out, "--truth", str(drive / "truth.jsonl"))
    result = CliRunner().invoke(cli, args)
    assert result.exit_code == 0, result.output
    (record,) = [json.loads(line) for line in (out / "traversals.jsonl").open()]
    truth = json.loads((drive / "drive.json").read_text())["traversals"][0]
    assert record["movement"] == truth["movement"] == "through"
    assert record["first_frame"] <= record["anchor_frame"] <= record["last_frame"]
    up, down = record["short_range"]
    assert record["first_frame"] <= up < record["anchor_frame"] <= down
    points = [p for t in record["tracks"] for p in t["points"]]
    assert {p["origin"] for p in points} == {"detected", "dof"}
    assert all(p["status"] in ("in", "partial", "out") for p in points)
    report = json.loads((out / "report.json").read_text())
    temporal = report["temporal"]
    assert temporal["true_tracks"] >= 1
    assert temporal["detected_accuracy"] >= 0.95 and temporal["temporal_accuracy"] >= 0.9
    assert report["clip_frames"] < report["frames"]  # only the clip was decoded
    # The report writers of a benchmark write the track run too: plots, summary, HTML, CSV.
    assert report["plots"] == ["plots/vicinity.png", "plots/traversal_000.png"]
    assert all((out / name).read_bytes().startswith(b"\x89PNG") for name in report["plots"])
    assert {"report.json", "summary.md", "report.html", "headline.csv"} <= set(report["files"])
    assert "| 0 | 0 | through |" in (out / "summary.md").read_text()
    page = (out / "report.html").read_text()
    assert 'id="traversals"' in page and "Zheng Figure 3-13" in page
    assert f"{temporal['temporal_accuracy']:.3f}" in page
    headline = (out / "headline.csv").read_text().splitlines()
    assert headline[0].endswith("traversals,temporal.temporal_accuracy,temporal.detected_accuracy")
    again = CliRunner().invoke(cli, args)
    assert again.exit_code == 0, again.output
    resumed = json.loads((out / "report.json").read_text())
    assert resumed["timing"]["cached_traversals"] == 1
    assert resumed["temporal"] == temporal


def test_no_video_still_lists_traversals(drive, tmp_path):
    args = ["track", "--gps", str(drive / "gps.csv"), "--map", str(drive / "map.osm")]
    result = CliRunner().invoke(cli, [*args, "--out", str(tmp_path)])
    assert result.exit_code == 0, result.output
    assert "through" in result.output and (tmp_path / "traversals.jsonl").is_file()
    refused = CliRunner().invoke(cli, [*args, "-c", "ab-hist"])
    assert refused.exit_code == 2 and "need a VIDEO" in refused.output


@pytest.mark.parametrize(
    ("break_it", "message"),
    [
        (lambda d: (d / "drive.mp4").write_text("not a video"), "cannot open as a video"),
        (lambda d: (d / "truth.jsonl").write_text("{oops\n"), "truth.jsonl: line 1"),
        (lambda d: (d / "gps.csv").write_text("time,lat,lon\n0,91,0\n"), "gps.csv: line 2"),
    ],
)
def test_malformed_inputs_give_one_clear_error(tmp_path, break_it, message):
    folder = tmp_path / "d"
    folder.mkdir()
    (folder / "drive.mp4").write_bytes(b"")
    (folder / "gps.csv").write_text("time,lat,lon\n0,47.6,-122.15\n1,47.6001,-122.15\n")
    (folder / "map.osm").write_text('<osm><node id="1" lat="47.6" lon="-122.15"/></osm>')
    (folder / "truth.jsonl").write_text('{"frame": 0, "lights": []}\n')
    break_it(folder)
    args = track_args(folder, tmp_path / "run", "--truth", str(folder / "truth.jsonl"))
    result = CliRunner().invoke(cli, args)
    assert result.exit_code == 2
    assert message in result.output and "Traceback" not in result.output


def strict_json(text: str):
    """Parse ``text`` as JSON, refusing the ``NaN`` / ``Infinity`` tokens Python accepts."""

    def refuse(token):
        raise AssertionError(f"{token} is not JSON")

    return json.loads(text, parse_constant=refuse)


def test_a_damaged_cache_entry_is_computed_again(drive, tmp_path):
    out = tmp_path / "run"
    args = track_args(drive, out)
    assert CliRunner().invoke(cli, args).exit_code == 0
    first = json.loads((out / "report.json").read_text())
    entries = sorted((out / "cache").rglob("*.json"))
    assert entries
    for entry, damage in zip(entries, ["{oops", "[]", '{"tracks": 3}', ""], strict=False):
        entry.write_text(damage)
    again = CliRunner().invoke(cli, args)
    assert again.exit_code == 0, again.output
    assert "Traceback" not in again.output
    report = json.loads((out / "report.json").read_text())
    assert report["timing"]["cached_traversals"] == 0
    assert report["traversals"] == first["traversals"]
    # Every JSON file of the run folder, the rewritten cache included, is strict JSON.
    for path in [*out.rglob("*.json"), *out.rglob("*.jsonl")]:
        for line in [path.read_text()] if path.suffix == ".json" else path.read_text().split("\n"):
            if line.strip():
                strict_json(line)


@pytest.mark.parametrize("option", ["--upstream", "--downstream", "--vicinity", "--slack"])
@pytest.mark.parametrize("value", ["inf", "-inf", "nan"])
def test_non_finite_distances_are_refused(drive, tmp_path, option, value):
    out = tmp_path / "run"
    result = CliRunner().invoke(cli, [*track_args(drive, out), option, value])
    assert result.exit_code == 2
    errors = [line for line in result.output.splitlines() if line.startswith("Error:")]
    assert len(errors) == 1 and option in errors[0] and value in errors[0]
    assert "Traceback" not in result.output and not out.exists()


def test_report_writes_a_track_run_again(drive, tmp_path):
    out = tmp_path / "run"
    assert CliRunner().invoke(cli, track_args(drive, out)).exit_code == 0
    page = (out / "report.html").read_text()
    (out / "report.html").unlink()
    (out / "summary.md").unlink()
    result = CliRunner().invoke(
        cli, ["report", str(out), "--writer", "html", "--writer", "markdown"]
    )
    assert result.exit_code == 0, result.output
    assert (out / "report.html").read_text() == page
    assert "| 0 | 0 | through |" in (out / "summary.md").read_text()
    (out / "traversals.jsonl").write_text('{"traversal": 0}\n')
    broken = CliRunner().invoke(cli, ["report", str(out)])
    assert broken.exit_code == 2
    assert "traversals.jsonl: line 1: not a traversal record (missing intersection" in (
        broken.output
    )


def test_report_says_what_a_track_run_without_video_lacks(drive, tmp_path):
    args = ["track", "--gps", str(drive / "gps.csv"), "--map", str(drive / "map.osm")]
    assert CliRunner().invoke(cli, [*args, "--out", str(tmp_path)]).exit_code == 0
    result = CliRunner().invoke(cli, ["report", str(tmp_path)])
    assert result.exit_code == 2 and "Traceback" not in result.output
    assert "a track run without a video (traversals.jsonl only)" in result.output
