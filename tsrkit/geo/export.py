"""A track written as GPX (gpxpy) or NMEA 0183 RMC + GGA sentences (pynmea2): to hand a log to
tools that want those formats, and to test the readers on real drives."""

from __future__ import annotations

from datetime import UTC, datetime

import gpxpy.gpx
import pynmea2

from tsrkit.geo.gps import Track

__all__ = ["to_gpx", "to_nmea"]


def to_gpx(track: Track) -> str:
    """``track`` as a GPX 1.1 document with one track of one segment."""
    gpx = gpxpy.gpx.GPX()
    segment = gpxpy.gpx.GPXTrackSegment()
    gpx.tracks.append(gpxpy.gpx.GPXTrack())
    gpx.tracks[0].segments.append(segment)
    for t, lat, lon in zip(track.time, track.lat, track.lon):
        stamp = datetime.fromtimestamp(float(t), UTC)
        segment.points.append(gpxpy.gpx.GPXTrackPoint(float(lat), float(lon), time=stamp))
    return gpx.to_xml()


def _minutes(value: float, width: int) -> str:
    degrees = int(abs(value))
    return f"{degrees:0{width}d}{(abs(value) - degrees) * 60:07.4f}"


def to_nmea(track: Track, gga_first: bool = False) -> str:
    """``track`` as one RMC and one GGA sentence per fix (whole seconds, 1e-4 arc minutes),
    checksums by pynmea2; ``gga_first`` puts each GGA before its RMC.

    >>> import numpy as np
    >>> print(to_nmea(Track("t", np.zeros(1), np.array([48.1173]), np.array([-11.5]))))
    $GPRMC,000000,A,4807.0380,N,01130.0000,W,0.0,0.0,010170,,*0B
    $GPGGA,000000,4807.0380,N,01130.0000,W,1,08,0.9,0,M,0,M*62
    <BLANKLINE>
    """
    lines = []
    for t, lat, lon in zip(track.time, track.lat, track.lon):
        stamp = datetime.fromtimestamp(float(t), UTC)
        clock, day = stamp.strftime("%H%M%S"), stamp.strftime("%d%m%y")
        where = (
            _minutes(lat, 2),
            "N" if lat >= 0 else "S",
            _minutes(lon, 3),
            "E" if lon >= 0 else "W",
        )
        rmc = pynmea2.RMC("GP", "RMC", (clock, "A", *where, "0.0", "0.0", day, "", ""))
        gga = pynmea2.GGA("GP", "GGA", (clock, *where, "1", "08", "0.9", "0", "M", "0", "M"))
        lines += [str(gga), str(rmc)] if gga_first else [str(rmc), str(gga)]
    return "\n".join(lines) + "\n"
