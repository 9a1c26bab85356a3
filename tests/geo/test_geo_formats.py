"""GPX, NMEA, PBF and GeoJSON readers of tsrkit.geo: the real Seattle drive and Bellevue extract
written in each format give what the original files give; malformed files give one clear error
naming the file and the line, track point or feature."""

import json
import sys
from datetime import UTC, datetime

import numpy as np
import pynmea2
import pytest
from click.testing import CliRunner
from conftest import shared_datasets_dir

from tsrkit.cli.main import cli
from tsrkit.geo import GeoError, read_signals, read_track
from tsrkit.geo.export import to_gpx, to_nmea
from tsrkit.geo.osm import _nodes

SET = shared_datasets_dir() / "nk_seattle_gps_bellevue_osm"
DRIVE, MAP = SET / "gps_data.txt", SET / "map-issue147.osm.gz"


@pytest.fixture(scope="module")
def seattle():
    return read_track(DRIVE)


def test_the_seattle_drive_as_gpx_reads_the_same(tmp_path, seattle):
    path = tmp_path / "drive.gpx"
    path.write_text(to_gpx(seattle))
    track = read_track(path)
    assert len(track) == len(seattle) == 7531
    np.testing.assert_array_equal(track.time, seattle.time)
    np.testing.assert_allclose(track.lat, seattle.lat, atol=1e-9)
    np.testing.assert_allclose(track.lon, seattle.lon, atol=1e-9)


@pytest.mark.parametrize("gga_first", [False, True])
def test_the_seattle_drive_as_nmea_reads_the_same(tmp_path, seattle, gga_first):
    path = tmp_path / "drive.log"  # told apart by its content
    path.write_text(to_nmea(seattle, gga_first))
    track = read_track(path)
    assert len(track) == len(seattle)
    np.testing.assert_array_equal(track.time, seattle.time)
    # NMEA keeps 1e-4 arc minutes: 1.7e-6 degrees
    np.testing.assert_allclose(track.lat, seattle.lat, atol=2e-6)
    np.testing.assert_allclose(track.lon, seattle.lon, atol=2e-6)


def test_gga_takes_the_rmc_date_across_midnight(tmp_path):
    rmc = pynmea2.RMC(
        "GP", "RMC", ("235959", "A", "4807.038", "N", "01131.000", "E", "0", "0", "170109", "", "")
    )
    gga = pynmea2.GGA(
        "GP", "GGA", ("000001", "4807.038", "N", "01131.000", "E", "1", "08", "0.9", "0", "M")
    )
    void = pynmea2.RMC("GP", "RMC", ("000002", "V", "", "", "", "", "", "", "180109", "", ""))
    path = tmp_path / "midnight.nmea"
    path.write_text(f"{rmc}\n$GPGSV,1,1,00*79\n{gga}\n{void}\n")
    track = read_track(path)
    day = datetime(2009, 1, 17, 23, 59, 59, tzinfo=UTC).timestamp()
    assert list(track.time) == [day, day + 2]  # the void fix is no position
    assert track.lat[0] == pytest.approx(48 + 7.038 / 60) and track.lon[1] == pytest.approx(
        11 + 31 / 60
    )


def test_gpx_and_nmea_logs_work_in_the_track_verb(tmp_path, seattle):
    gpx = tmp_path / "drive.gpx"
    gpx.write_text(to_gpx(seattle))
    result = CliRunner().invoke(cli, ["track", "--gps", str(gpx), "--map", str(MAP)])
    assert result.exit_code == 0, result.output
    assert "traversals of 30 intersections (7531 fixes)" in result.output


GPX_HEAD = '<?xml version="1.0"?><gpx version="1.1"><trk><trkseg>'


def _points(*points: str) -> str:
    return GPX_HEAD + "".join(points) + "</trkseg></trk></gpx>"


def _pt(lat="47.6", lon="-122.1", time="2009-01-17T20:27:37Z") -> str:
    return f'<trkpt lat="{lat}" lon="{lon}"><time>{time}</time></trkpt>'


@pytest.mark.parametrize(
    "text,fragment",
    [
        ("", "line 1: not well-formed XML"),
        (GPX_HEAD + "<trkpt lat=", "line 1: not well-formed XML"),
        ("<gpx></gpx>", "no GPS fix"),
        (
            '<gpx><wpt lat="1" lon="2"/></gpx>',
            "no track point \\(<trkpt>\\): routes and waypoints are not a drive",
        ),
        (_points(_pt(), _pt(lat="x")), "track point 2: not a valid GPX file"),
        (_points(_pt(), '<trkpt lon="1"/>'), "track point 2: not a valid GPX file"),
        (_points(_pt(), _pt(time="yesterday")), "track point 2: no valid <time>"),
        (_points(_pt(lat="nan")), "track point 1: time, latitude or longitude is not finite"),
        (_points(_pt(lon="190")), "track point 1: latitude 47.6 / longitude 190.0 out of range"),
        (
            _points(_pt(), _pt(time="2009-01-17T20:27:36Z")),
            "track point 2: times are not increasing",
        ),
        (
            '<!DOCTYPE gpx [<!ENTITY a "aaaa">]><gpx>&a;</gpx>',
            "refused XML \\(EntitiesForbidden\\)",
        ),
    ],
)
def test_malformed_gpx_names_the_line_or_track_point(tmp_path, text, fragment):
    path = tmp_path / "bad.gpx"
    path.write_text(text)
    with pytest.raises(GeoError, match=f"bad.gpx: {fragment}"):
        read_track(path)


RMC = "$GPRMC,123519,A,4807.038,N,01131.000,E,022.4,084.4,230394,003.1,W*6A"


@pytest.mark.parametrize(
    "text,fragment",
    [
        ("", "no GPS fix"),
        (RMC + "\n" + RMC[:-1] + "B\n", "line 2: not an NMEA sentence"),
        (RMC + "\nhello\n", "line 2: not an NMEA sentence"),
        (str(pynmea2.RMC("GP", "RMC", ("123519", "A", "", "", "", ""))), "line 1: RMC fix without"),
        (RMC[:-26], "line 1: RMC fix without a valid time or date"),
        (
            str(pynmea2.GGA("GP", "GGA", ("123519", "4807.038", "N", "01131.000", "E", "1"))),
            "line 1: GGA fixes carry no date and the log has no RMC",
        ),
        (
            str(pynmea2.GGA("GP", "GGA", ("123519", "4807.038", "N", "01131.000", "E", "x"))),
            "line 1: bad GGA field",
        ),
        (RMC.replace("4807.038", "9107.038")[:-3], "line 1: latitude 91.1173 / longitude"),
        (
            RMC + "\n" + RMC.replace("4807.038", "4807.039")[:-3] + "\n",
            "line 2: times are not increasing",
        ),
    ],
)
def test_malformed_nmea_names_the_line(tmp_path, text, fragment):
    path = tmp_path / "bad.nmea"
    path.write_text(text)
    with pytest.raises(GeoError, match=f"bad.nmea: {fragment}"):
        read_track(path)


def test_a_pbf_cut_by_osmium_gives_the_signals_of_the_xml_extract(tmp_path):
    osmium = pytest.importorskip("osmium")
    pbf = tmp_path / "bellevue.osm.pbf"
    with osmium.SimpleWriter(str(pbf)) as writer:
        for item in osmium.FileProcessor(str(MAP)):
            writer.add(item)
    xml, binary = read_signals(MAP), read_signals(pbf)
    assert binary.ids == xml.ids and len(xml) == 30
    np.testing.assert_array_equal(binary.lat, xml.lat)
    np.testing.assert_array_equal(binary.crossing_lon, xml.crossing_lon)
    bad = tmp_path / "bad.pbf"
    bad.write_bytes(pbf.read_bytes()[:5000])
    with pytest.raises(GeoError, match=r"bad\.pbf: not a readable OSM PBF file"):
        read_signals(bad)
    with pytest.raises(GeoError, match=r"missing\.pbf: no such file"):
        read_signals(tmp_path / "missing.pbf")


def test_pbf_without_pyosmium_is_one_clear_error(tmp_path, monkeypatch):
    monkeypatch.setitem(sys.modules, "osmium", None)
    with pytest.raises(
        GeoError, match=r"x.pbf: reading .pbf needs pyosmium \(pip install osmium\)"
    ):
        read_signals(tmp_path / "x.pbf")


def test_geojson_signals_match_the_xml_extract(tmp_path):
    features = [
        {
            "type": "Feature",
            "id": f"node/{ident}",
            "properties": tags,
            "geometry": {"type": "Point", "coordinates": [lon, lat]},
        }
        for ident, lat, lon, tags in _nodes(MAP)
    ]
    features.append({"type": "Feature", "properties": {"highway": "stop"}, "geometry": None})
    path = tmp_path / "signals.geojson"
    path.write_text(json.dumps({"type": "FeatureCollection", "features": features}))
    xml, geo = read_signals(MAP), read_signals(path)
    assert geo.ids == xml.ids
    np.testing.assert_array_equal(geo.lat, xml.lat)
    np.testing.assert_array_equal(geo.crossing_lat, xml.crossing_lat)


def _feature(coordinates, kind="Point", **extra):
    properties = {"highway": "traffic_signals"}
    geometry = {"type": kind, "coordinates": coordinates}
    return json.dumps({"type": "Feature", "properties": properties, "geometry": geometry, **extra})


@pytest.mark.parametrize(
    "text,fragment",
    [
        ("", "line 1: not JSON"),
        ('{"type": "FeatureCollection",\n "features": [', "line 2: not JSON"),
        ("[1, 2]", "not a GeoJSON FeatureCollection or Feature"),
        ('{"features": [3]}', "feature 1: not a GeoJSON feature"),
        (_feature([[0, 0], [1, 1]], "LineString"), "feature 1: .* must be a Point, not LineString"),
        (_feature(["a", 1]), "feature 1: Point coordinates must be"),
        (_feature([10**400, 1]), "feature 1: Point coordinates out of range"),
        (_feature([1, 95]), "feature 1: lat 95.0 / lon 1.0 out of range"),
        (_feature([float("nan"), 1]), "feature 1: lat 1.0 / lon nan not finite"),
        ("[" * 100000, "not JSON"),
    ],
)
def test_malformed_geojson_names_the_line_or_feature(tmp_path, text, fragment):
    path = tmp_path / "bad.geojson"
    path.write_text(text)
    with pytest.raises(GeoError, match=f"bad.geojson: {fragment}"):
        read_signals(path)


def test_malformed_osm_nodes_and_entities_are_clear_errors(tmp_path):
    path = tmp_path / "bad.osm"
    path.write_text(
        '<osm><node id="7" lat="nan" lon="1"><tag k="highway" v="traffic_signals"/></node></osm>'
    )
    with pytest.raises(GeoError, match=r"bad\.osm: node 7: lat nan / lon 1\.0 not finite"):
        read_signals(path)
    path.write_text('<!DOCTYPE osm [<!ENTITY a "aaaa">]><osm>&a;</osm>')
    with pytest.raises(GeoError, match=r"bad\.osm: refused XML"):
        read_signals(path)
    gz = tmp_path / "bad.osm.gz"
    gz.write_bytes(MAP.read_bytes()[:20] + b"\x00" * 200)
    with pytest.raises(GeoError, match=r"bad\.osm\.gz: cannot read"):
        read_signals(gz)


def test_a_csv_log_without_the_csv_extension_is_told_by_its_header(tmp_path):
    path = tmp_path / "drive.txt"
    path.write_text("time,lat,lon\n2009-01-17T20:27:37Z,47.6,-122.1\n")
    track = read_track(path)
    assert list(track.time) == [datetime(2009, 1, 17, 20, 27, 37, tzinfo=UTC).timestamp()]
