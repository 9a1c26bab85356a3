"""Property tests of the GPS log and map readers and of the extended k-d tree (hypothesis,
bounded), and the crashes ``benchmarks/fuzz_geo.py`` found, kept as regression cases."""

import gzip
import json
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings, strategies as st
from scipy.spatial import cKDTree

from tsrkit.geo import GeoError, Track, read_signals, read_track
from tsrkit.geo.export import to_gpx, to_nmea
from tsrkit.geo.nearest import nearest_extended, nearest_kdtree

FAST = settings(
    max_examples=60, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture]
)

TRACK = Track(
    "seed",
    np.array([1232224057.0, 1232224058.0, 1232224060.0]),
    np.array([47.66748333, 47.6675, 47.66761]),
    np.array([-122.1070833, -122.1070667, -122.10699]),
)
NODES = (
    '<osm version="0.6">\n'
    '<node id="30234498" lat="47.5812861" lon="-122.1709525">'
    '<tag k="highway" v="traffic_signals"/></node>\n'
    '<node id="5" lat="47.58" lon="-122.17"><tag k="crossing" v="traffic_signals"/></node>\n'
    "</osm>\n"
)
GEOJSON = json.dumps(
    {
        "type": "FeatureCollection",
        "features": [
            {
                "type": "Feature",
                "id": "node/7",
                "properties": {"highway": "traffic_signals"},
                "geometry": {"type": "Point", "coordinates": [-122.17, 47.58]},
            }
        ],
    }
)
SEEDS = {
    ".csv": b"time,lat,lon\n1232224057,47.66748333,-122.1070833\n1232224058,47.6675,-122.10706\n",
    ".txt": b"Date (UTC)\tTime (UTC)\tLatitude\tLongitude\n"
    b"17-Jan-2009\t20:27:37\t47.66748333\t-122.1070833\n"
    b"17-Jan-2009\t20:27:38\t47.6675\t-122.1070667\n",
    ".gpx": to_gpx(TRACK).encode(),
    ".nmea": to_nmea(TRACK).encode(),
    ".osm": NODES.encode(),
    ".geojson": GEOJSON.encode(),
}
TOKENS = ["nan", "-1", "9999999999", "1e400", ",", "<", ">", '"', "$", "*", "\n", "\t", "0", ":"]


@st.composite
def mutated(draw, seed: bytes) -> bytes:
    """``seed`` with up to three edits: a token or random text inserted, a run deleted, the
    tail cut."""
    data = bytearray(seed)
    for _ in range(draw(st.integers(1, 3))):
        at = draw(st.integers(0, len(data)))
        kind = draw(st.sampled_from(["token", "text", "delete", "cut"]))
        if kind == "token":
            data[at:at] = draw(st.sampled_from(TOKENS)).encode()
        elif kind == "text":
            data[at:at] = draw(st.text(max_size=8)).encode("utf-8", "surrogatepass")
        elif kind == "delete":
            del data[at : at + draw(st.integers(1, 12))]
        else:
            del data[at:]
    return bytes(data)


def _reads_or_clear_error(path: Path, data: bytes) -> None:
    path.write_bytes(data)
    reader = read_signals if path.suffix in (".osm", ".geojson") else read_track
    try:
        reader(path)
    except GeoError as exc:
        assert str(exc).startswith(str(path)) and "\n" not in str(exc).strip()


@pytest.mark.parametrize("suffix", sorted(SEEDS))
def test_every_seed_reads(tmp_path, suffix):
    path = tmp_path / f"seed{suffix}"
    path.write_bytes(SEEDS[suffix])
    result = (read_signals if suffix in (".osm", ".geojson") else read_track)(path)
    assert len(result) == {".csv": 2, ".txt": 2, ".gpx": 3, ".nmea": 3}.get(suffix, 1)


@pytest.mark.parametrize("suffix", sorted(SEEDS))
def test_mutated_files_read_or_fail_with_one_clear_line(tmp_path, suffix):
    @FAST
    @given(mutated(SEEDS[suffix]))
    def check(data):
        _reads_or_clear_error(tmp_path / f"case{suffix}", data)

    check()


#: Tracks a vehicle can drive: each step at most 0.0005 degrees in latitude and longitude
#: (79 m) in at least 1 s, below ``read_track``'s plausible speed.
tracks = st.integers(1, 30).flatmap(
    lambda n: st.tuples(
        st.lists(st.integers(1, 600), min_size=n, max_size=n),
        st.floats(-88.0, 88.0),
        st.floats(-178.0, 178.0),
        st.lists(st.floats(-0.0005, 0.0005), min_size=n, max_size=n),
        st.lists(st.floats(-0.0005, 0.0005), min_size=n, max_size=n),
    )
)


@FAST
@given(tracks, st.sampled_from([".csv", ".gpx", ".nmea"]))
def test_any_valid_track_round_trips(tmp_path, columns, suffix):
    steps, lat0, lon0, north, east = columns
    lat, lon = (lat0 + np.cumsum(north)).tolist(), (lon0 + np.cumsum(east)).tolist()
    track = Track("t", 946684800.0 + np.cumsum(steps), np.array(lat), np.array(lon))
    path = tmp_path / f"drive{suffix}"
    if suffix == ".csv":
        rows = "".join(f"{t:.0f},{a!r},{o!r}\n" for t, a, o in zip(track.time, lat, lon))
        path.write_text("time,lat,lon\n" + rows)
    else:
        path.write_text(to_gpx(track) if suffix == ".gpx" else to_nmea(track))
    back = read_track(path)
    np.testing.assert_array_equal(back.time, track.time)
    tolerance = 2e-6 if suffix == ".nmea" else 1e-9
    np.testing.assert_allclose(back.lat, track.lat, atol=tolerance)
    np.testing.assert_allclose(back.lon, track.lon, atol=tolerance)


@FAST
@given(
    st.lists(
        st.tuples(st.floats(47.0, 47.01), st.floats(-122.01, -122.0), st.booleans()),
        min_size=1,
        max_size=12,
    )
)
def test_osm_xml_and_geojson_give_the_same_signals(tmp_path, nodes):
    tags = ["crossing" if pedestrian else "highway" for _, _, pedestrian in nodes]
    xml = "".join(
        f'<node id="{i}" lat="{a!r}" lon="{o!r}"><tag k="{k}" v="traffic_signals"/></node>'
        for i, ((a, o, _), k) in enumerate(zip(nodes, tags), start=1)
    )
    (tmp_path / "m.osm.gz").write_bytes(gzip.compress(f"<osm>{xml}</osm>".encode()))
    features = [
        {
            "type": "Feature",
            "id": i,
            "properties": {k: "traffic_signals"},
            "geometry": {"type": "Point", "coordinates": [o, a]},
        }
        for i, ((a, o, _), k) in enumerate(zip(nodes, tags), start=1)
    ]
    (tmp_path / "m.geojson").write_text(
        json.dumps({"type": "FeatureCollection", "features": features})
    )
    a, b = read_signals(tmp_path / "m.osm.gz"), read_signals(tmp_path / "m.geojson")
    assert a.ids == b.ids and len(a.crossing_lat) == tags.count("crossing")
    np.testing.assert_array_equal(a.lat, b.lat)
    np.testing.assert_array_equal(a.crossing_lon, b.crossing_lon)


@FAST
@given(st.integers(0, 2**32 - 1), st.integers(2, 40), st.integers(2, 3000))
def test_extended_equals_kdtree_when_every_excursion_outlasts_tau(seed, targets, n):
    """Condition 3-1 holds when every run of positions nearest to another intersection lasts,
    from the position before it to the one after, at least tau_min: then the recursion must
    give the basic answer exactly."""
    rng = np.random.default_rng(seed)
    tree = cKDTree(rng.uniform(0, 1000, (targets, 2)))
    points = np.cumsum(rng.normal(0, 15, (n, 2)), axis=0) + 500
    times = np.cumsum(rng.uniform(0.01, 0.2, n))
    basic, distance = nearest_kdtree(tree, points)
    change = np.flatnonzero(np.diff(basic)) + 1  # first position of each run after the first
    starts, ends = change[:-1], change[1:]  # interior runs: [start, end)
    brackets = times[ends] - times[starts - 1]
    tau = float(brackets.min()) if len(brackets) else 1e9
    index, extended = nearest_extended(tree, points, times, tau)
    np.testing.assert_array_equal(index, basic)
    np.testing.assert_allclose(extended, distance, atol=1e-9)


RMC = "$GPRMC,{},A,4807.038,N,01131.000,E,022.4,084.4,{},003.1,W"


def _nmea(body: str) -> str:
    checksum = 0
    for char in body[1:]:
        checksum ^= ord(char)
    return f"{body}*{checksum:02X}\n"


@pytest.mark.parametrize(
    "name,data,fragment",
    [
        # fuzz_geo.py: pynmea2 hands back the raw text of a field it cannot convert
        ("t.nmea", _nmea(RMC.format("12x519", "230394")), "line 1: RMC fix without a valid time"),
        ("d.nmea", _nmea(RMC.format("123519", "2303x4")), "line 1: RMC fix without a valid time"),
        # fuzz_geo.py: an unknown encoding in the XML declaration is a LookupError
        ("e.osm", '<?xml version="1.0" encoding="UTF-e"?><osm/>', "cannot decode the XML"),
        # found while writing the readers: csv's field size limit raised csv.Error
        ("big.csv", "time,lat,lon\n" + "x" * 200_000 + ",1,2\n", "line 2: not CSV"),
    ],
)
def test_crashes_found_by_fuzzing_are_clear_errors(tmp_path, name, data, fragment):
    path = tmp_path / name
    path.write_text(data)
    with pytest.raises(GeoError, match=fragment):
        (read_signals if name.endswith(".osm") else read_track)(path)


def test_a_byte_order_mark_is_not_part_of_the_csv_header(tmp_path):
    path = tmp_path / "bom.csv"
    path.write_text("\ufefftime,lat,lon\n0,47,-122\n", encoding="utf-8")
    assert len(read_track(path)) == 1
