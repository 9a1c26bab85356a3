"""Mutation fuzzing of tsrkit's GPS log and map readers: counts the cases that end
in an exception other than tsrkit's own clear ``GeoError`` (the target is 0).

Seeds are cut from the real Seattle drive (its first 40 fixes) and the real Bellevue extract
(its first 12 signal nodes), written as: a CSV log, the whitespace log, GPX, NMEA, OSM XML,
gzipped OSM XML and GeoJSON. Each case is a seed with one to four byte-level mutations
(benchmarks/fuzz.py: flips, insertions, deletions, truncation, a number or quote replaced by
``9999999999``, ``-1``, ``nan`` or nothing), written to a file and read with ``read_track`` or
``read_signals``.

    python benchmarks/fuzz_geo.py [--cases 10000] [--seed 0]
"""

from __future__ import annotations

import argparse
import gzip
import json
import shutil
import tempfile
from datetime import UTC, datetime
from pathlib import Path

import harness
import numpy as np
from fuzz import run_surface  # benchmarks/fuzz.py: the mutations and the outcome counts

from tsrkit.api import Track, read_track
from tsrkit.geo import GeoError, read_signals
from tsrkit.geo.export import to_gpx, to_nmea
from tsrkit.geo.osm import _nodes

REPO = harness.REPO
DATA = harness.data_dir()
SET = DATA / "nk_seattle_gps_bellevue_osm"


def seeds() -> dict[str, tuple[str, list[bytes]]]:
    """Surface name -> (file suffix, seed files)."""
    lines = (SET / "gps_data.txt").read_text().splitlines()[:41]
    whole = read_track(SET / "gps_data.txt")
    track = Track("seed", whole.time[:40], whole.lat[:40], whole.lon[:40])
    iso = [datetime.fromtimestamp(t, UTC).isoformat() for t in track.time]
    csv_seconds = "time,lat,lon\n" + "".join(
        f"{t:.0f},{a},{o}\n" for t, a, o in zip(track.time, track.lat, track.lon)
    )
    csv_iso = "time,lat,lon,speed\n" + "".join(
        f"{s},{a},{o},12.5\n" for s, a, o in zip(iso, track.lat, track.lon)
    )
    nodes = _nodes(SET / "map-issue147.osm.gz")[:12]
    xml = '<?xml version="1.0" encoding="UTF-8"?>\n<osm version="0.6">\n' + "".join(
        f'  <node id="{i}" lat="{a}" lon="{o}" version="1">\n'
        + "".join(f'    <tag k="{k}" v="{v}"/>\n' for k, v in tags.items())
        + "  </node>\n"
        for i, a, o, tags in nodes
    )
    xml += '  <way id="1"><nd ref="1"/><tag k="highway" v="primary"/></way>\n</osm>\n'
    features = [
        {
            "type": "Feature",
            "id": f"node/{i}",
            "properties": tags,
            "geometry": {"type": "Point", "coordinates": [o, a]},
        }
        for i, a, o, tags in nodes
    ]
    geojson = json.dumps({"type": "FeatureCollection", "features": features}, indent=1)
    return {
        "csv": (".csv", [csv_seconds.encode(), csv_iso.encode()]),
        "whitespace": (".txt", ["\n".join(lines).encode()]),
        "gpx": (".gpx", [to_gpx(track).encode()]),
        "nmea": (".nmea", [to_nmea(track).encode(), to_nmea(track, gga_first=True).encode()]),
        "osm": (".osm", [xml.encode()]),
        "osm.gz": (".osm.gz", [gzip.compress(xml.encode(), mtime=0)]),
        "geojson": (".geojson", [geojson.encode()]),
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--cases", type=int, default=10000)
    parser.add_argument("--seed", type=int, default=0)
    args = parser.parse_args()
    harness.announce()
    rng = np.random.default_rng(args.seed)
    folder = Path(tempfile.mkdtemp(prefix="tsrkit-fuzz-geo-"))
    try:
        total = 0
        for name, (suffix, files) in seeds().items():
            path = folder / f"case{suffix}"
            reader = read_track if name in ("csv", "whitespace", "gpx", "nmea") else read_signals

            def target(data: bytes, path=path, reader=reader) -> None:
                path.write_bytes(data)
                reader(path)

            for data in files:  # every seed is read cleanly before it is mutated
                target(data)
            total += run_surface(name, files, target, args.cases, rng, GeoError)
        print(f"total uncaught: {total}")
    finally:
        shutil.rmtree(folder, ignore_errors=True)


if __name__ == "__main__":
    main()
