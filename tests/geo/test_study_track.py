"""``tsrkit track VIDEO`` writes the controlling signal's timeline and the driving events of a
short rendered drive (the car waits at a red, then goes on green), scored against its truth."""

import csv
import json

import pytest
from click.testing import CliRunner

from tsrkit.cli.main import cli
from tsrkit.spatiotemporal.events import EVENT_COLUMNS, TIMELINE_COLUMNS
from tsrkit.spatiotemporal.scoring import score
from tsrkit.synth.drive import DriveOptions, render_drive

# 5 fps, 60 m through one junction: red until 7 s (offset 19 s of the 26 s cycle), the car
# halts at the line at about 4.7 s and pulls away on green.
DRIVE = DriveOptions(
    fps=5, route=("through",), lead_m=45, tail_m=15, light_offset=19.0, trucks=False
)
PLUGINS = ["-c", "ab-hist", "-p", "h_peak=0.8", "-p", "radii=1,2,3,4,5,6"]


@pytest.fixture(scope="module")
def drive(tmp_path_factory):
    return render_drive(tmp_path_factory.mktemp("study"), DRIVE, seed=2)


def rows(path):
    with path.open(newline="") as fh:
        return list(csv.DictReader(fh))


def test_timeline_and_events_of_a_red_wait(drive, tmp_path):
    truth = rows(drive / "truth_events.csv")
    assert [e["kind"] for e in truth] == ["stop", "go"]
    out = tmp_path / "run"
    args = ["track", str(drive / "drive.mp4"), "--gps", str(drive / "gps.csv")]
    args += ["--map", str(drive / "map.osm"), "--vicinity", "60", "--out", str(out), "-q"]
    result = CliRunner().invoke(cli, args + PLUGINS)
    assert result.exit_code == 0, result.output
    timeline, events = rows(out / "timelines.csv"), rows(out / "events.csv")
    assert tuple(timeline[0])[: len(TIMELINE_COLUMNS)] == TIMELINE_COLUMNS
    assert [r["kind"] for r in timeline if r["kind"] != "unknown"] == ["red", "green"]
    assert all(float(r["time"]) < float(r["end"]) for r in timeline)
    assert tuple(events[0])[: len(EVENT_COLUMNS)] == EVENT_COLUMNS
    figures = score(out, drive)
    assert figures["kinds"]["stop"] == {"estimated": 1, "true": 1, "matched": 1}
    assert figures["kinds"]["go"]["estimated"] == 1  # 1 Hz GPS dates it to about 0.6 s
    assert figures["red_crossing"]["flagged"] == 0
    assert figures["timeline"]["accuracy"] >= 0.7  # unknown while the lenses are < 1.5 px


def test_study_runs_a_manifest_resumes_and_combines(drive, tmp_path):
    manifest = tmp_path / "drives.csv"
    manifest.write_text(
        f"name,video,gps,map\nred_wait,{drive / 'drive.mp4'},{drive / 'gps.csv'},"
        f"{drive / 'map.osm'}\n"
    )
    out = tmp_path / "study"
    args = ["study", str(manifest), "--out", str(out), "--vicinity", "60", "-q", *PLUGINS]
    first = CliRunner().invoke(cli, args)
    assert first.exit_code == 0, first.output
    again = CliRunner().invoke(cli, args)
    assert again.exit_code == 0 and "red_wait: finished before, skipped" in again.output
    events = rows(out / "events.csv")
    assert events and all(e["drive"] == "red_wait" for e in events)
    assert rows(out / "timelines.csv")[0]["drive"] == "red_wait"
    geojson = json.loads((out / "traversals.geojson").read_text())
    assert geojson["features"][0]["properties"]["stop"] == 1
    bad = tmp_path / "bad.csv"
    bad.write_text("video,gps\nnone.mp4,none.csv\n")
    result = CliRunner().invoke(cli, ["study", str(bad), "--out", str(tmp_path / "x")])
    assert result.exit_code != 0 and "drive 1: no map" in result.output
    assert "Traceback" not in result.output
