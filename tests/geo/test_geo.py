"""tsrkit.geo: GPS and map readers, the projection, vicinity traversals and movement."""

import gzip

import numpy as np
import pytest
from click.testing import CliRunner
from pyproj import Geod

from tsrkit.cli.main import cli
from tsrkit.geo import GeoError, LocalProjection, movement, read_signals, read_track, traversals

LAT0, LON0 = 47.58, -122.15
GEOD = Geod(ellps="WGS84")


def test_projection_distances_agree_with_geodesics_over_20_km():
    projection = LocalProjection(LAT0, LON0)
    rng = np.random.default_rng(0)
    for azimuth, far in zip(rng.uniform(0, 360, 20), rng.uniform(1000, 10000, 20)):
        lon1, lat1, _ = GEOD.fwd(LON0, LAT0, azimuth, far)
        lon2, lat2, _ = GEOD.fwd(LON0, LAT0, azimuth + 150, far)
        _, _, truth = GEOD.inv(lon1, lat1, lon2, lat2)
        x, y = projection(np.array([lat1, lat2]), np.array([lon1, lon2]))
        assert abs(np.hypot(x[1] - x[0], y[1] - y[0]) / truth - 1) < 0.005


def drive(tmp_path, turn_left=True):
    """A 1 Hz drive east along a street, through a signal at 300 m, then north (a left turn)."""
    projection = LocalProjection(LAT0, LON0)
    xs = np.concatenate([np.arange(0, 300, 10.0), np.full(30, 300.0)])
    ys = np.concatenate([np.zeros(30), np.arange(0, 300, 10.0) * (1 if turn_left else -1)])
    lon, lat = projection._forward.transform(xs, ys, direction="INVERSE")
    lines = ["time,lat,lon"] + [
        f"{1000 + k},{a:.7f},{o:.7f}" for k, (a, o) in enumerate(zip(lat, lon))
    ]
    path = tmp_path / "drive.csv"
    path.write_text("\n".join(lines) + "\n")
    s_lon, s_lat = projection._forward.transform(
        [300.0, 310.0, 150.0], [0.0, 20.0, 500.0], direction="INVERSE"
    )
    nodes = [
        (1, s_lat[0], s_lon[0], "highway"),
        (2, s_lat[1], s_lon[1], "highway"),  # 22 m away: the same junction
        (3, s_lat[2], s_lon[2], "crossing"),  # a pedestrian signal, kept apart
    ]
    body = "".join(
        f'<node id="{i}" lat="{a}" lon="{o}"><tag k="{k}" v="traffic_signals"/></node>'
        for i, a, o, k in nodes
    )
    osm = tmp_path / "city.osm.gz"
    with gzip.open(osm, "wt") as fh:
        fh.write(f'<?xml version="1.0"?><osm version="0.6">{body}</osm>')
    return path, osm


def test_a_left_turn_through_one_merged_intersection(tmp_path):
    gps, osm = drive(tmp_path)
    track, signals = read_track(gps), read_signals(osm)
    assert len(track) == 60 and signals.ids == ((1, 2),) and len(signals.crossing_lat) == 1
    found = traversals(track, signals, 30.0)
    assert len(found) == 1
    t = found[0]
    assert t.movement == "left" and 60 < t.turn_deg <= 90
    assert t.closest_m < 12 and t.entry < t.anchor < t.exit
    right = traversals(read_track(drive(tmp_path, turn_left=False)[0]), signals, 30.0)
    assert right[0].movement == "right"


def test_movement_follows_eq_3_29_threshold():
    assert movement(0.0, 25.0)[0] == "left"
    assert movement(0.0, -25.0)[0] == "right"
    assert movement(0.0, 15.0)[0] == "through"
    assert movement(170.0, -170.0) == ("through", 20.0)


def test_interpolation_reports_gaps_instead_of_bridging(tmp_path):
    path = tmp_path / "g.csv"
    path.write_text("time,lat,lon\n0,47.0,-122.0\n1,47.0005,-122.0\n20,47.001,-122.0\n")
    track = read_track(path)
    lat, _ = track.at(np.array([0.5, 10.0, 30.0]))
    assert lat[0] == pytest.approx(47.00025) and np.isnan(lat[1]) and np.isnan(lat[2])
    assert track.gaps() == [(1.0, 20.0)]


@pytest.mark.parametrize(
    "text,fragment",
    [
        ("", "CSV header lacks lat, lon, time"),
        ("time,lat,lon\n", "no GPS fix"),
        ("time,lat,lon\n0,47.0\n", "line 2: expected 3 columns"),
        ("time,lat,lon\n0,nan,-122\n", "line 2: time, latitude or longitude is not finite"),
        ("time,lat,lon\n0,95.0,-122\n", "line 2: latitude 95.0"),
        ("time,lat,lon\n5,47,-122\n4,47,-122\n", "line 3: times are not increasing"),
        ("time,lat\n0,47\n", "line 1: CSV header lacks lon"),
        ("time,lat,lon\n0,abc,-122\n", "line 2: not a time"),
    ],
)
def test_malformed_csv_logs_name_file_and_line(tmp_path, text, fragment):
    path = tmp_path / "bad.csv"
    path.write_text(text)
    with pytest.raises(GeoError, match=fragment):
        read_track(path)


def test_malformed_maps_and_whitespace_logs_are_one_clear_error(tmp_path):
    bad = tmp_path / "bad.txt"
    bad.write_text("17-Jan-2009 20:27:37 47.6\n")
    with pytest.raises(GeoError, match="line 1: expected"):
        read_track(bad)
    osm = tmp_path / "bad.osm"
    osm.write_text(
        '<osm><node id="1" lat="47" lon="-122">\n<tag k="highway" v="traffic_signals"/></osm>'
    )
    with pytest.raises(GeoError, match="not well-formed XML"):
        read_signals(osm)
    with pytest.raises(GeoError, match="no such file"):
        read_signals(tmp_path / "missing.osm")


def test_track_verb_writes_the_traversals(tmp_path):
    gps, osm = drive(tmp_path)
    out = tmp_path / "run"
    result = CliRunner().invoke(
        cli, ["track", "--gps", str(gps), "--map", str(osm), "-o", str(out)]
    )
    assert result.exit_code == 0, result.output
    lines = (out / "traversals.jsonl").read_text().splitlines()
    assert len(lines) == 1 and '"movement": "left"' in lines[0]


def test_a_car_waiting_at_the_light_anchors_on_its_last_stopped_fix(tmp_path):
    """Zheng 3.4.2: on a flat valley bottom the latest bottom frame is the anchor."""
    gps, osm = drive(tmp_path)
    rows = gps.read_text().splitlines()
    header, fixes = rows[0], rows[1:]
    stop = fixes[31]  # (300, 10), 5 m from the merged junction: the car waits there 5 s
    t0 = int(stop.split(",")[0])
    waiting = [f"{t0 + k}," + stop.split(",", 1)[1] for k in range(6)]
    later = [f"{int(f.split(',')[0]) + 5}," + f.split(",", 1)[1] for f in fixes[32:]]
    gps.write_text("\n".join([header, *fixes[:31], *waiting, *later]) + "\n")
    (found,) = traversals(read_track(gps), read_signals(osm), 30.0)
    assert found.anchor == t0 + 5 and found.movement == "left"
