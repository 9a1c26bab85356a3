"""``tsrkit track --help`` names every input format the GPS and map readers accept."""

from __future__ import annotations

from pathlib import Path

from click.testing import CliRunner

from tsrkit.cli.main import cli
from tsrkit.geo.gps import LOG_FORMATS, log_format
from tsrkit.geo.osm import MAP_FORMATS, map_format

#: The words that name each reader format in a help text.
NAMED_AS = {
    "csv": ["CSV"],
    "gpx": ["GPX", ".gpx"],
    "nmea": ["NMEA", ".nmea"],
    "whitespace": ["dd-Mon-yyyy hh:mm:ss lat lon"],
    "xml": [".osm,", ".osm.gz"],
    "pbf": [".osm.pbf"],
    "geojson": ["GeoJSON", ".geojson"],
}


def test_the_format_lists_hold_every_format_the_readers_answer():
    logs = {log_format(Path(f"x{s}"), "") for s in (".csv", ".gpx", ".nmea", ".nma", ".nme")}
    logs |= {log_format(Path("x.txt"), t) for t in ("<gpx>", "$GPRMC", "time,lat,lon", "1 2")}
    maps = {map_format(Path(n)) for n in ("a.osm", "a.osm.gz", "a.osm.pbf", "a.geojson")}
    assert logs == set(LOG_FORMATS)
    assert maps == set(MAP_FORMATS)


def test_track_help_names_every_gps_and_map_format():
    text = " ".join(CliRunner().invoke(cli, ["track", "--help"], terminal_width=400).output.split())
    missing = [
        word for kind in (*LOG_FORMATS, *MAP_FORMATS) for word in NAMED_AS[kind] if word not in text
    ]
    assert not missing, f"track --help does not name {missing}"
