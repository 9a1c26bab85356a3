"""GPX track points through gpxpy (Zheng 2016, 4.3: the positions a drive was logged at)."""

from __future__ import annotations

from datetime import UTC
from pathlib import Path
from xml.etree.ElementTree import Element, ParseError

import gpxpy
import gpxpy.gpx
from defusedxml import DefusedXmlException, ElementTree as SafeTree

from tsrkit.geo.errors import GeoError

__all__ = ["gpx_rows"]


def _bad_point(root: Element) -> str:
    """The label of the first ``<trkpt>`` whose lat or lon is missing or not a number."""
    points = (e for e in root.iter() if e.tag.rsplit("}", 1)[-1] == "trkpt")
    for number, point in enumerate(points, start=1):
        try:
            float(point.get("lat", "")), float(point.get("lon", ""))
        except ValueError:
            return f"track point {number}"
    return ""


def gpx_rows(path: Path, text: str) -> list[tuple[int | str, float, float, float]]:
    """``(label, UTC seconds, lat, lon)`` of every track point, in file order; the label is
    "track point N", N counting from 1 over all tracks and segments. A time without a zone is
    UTC.

    The XML is first parsed with defusedxml (entities and DTDs refused, the line of a syntax
    error named), then read with gpxpy.

    Raises
    ------
    GeoError
        Malformed XML (with its line), a point gpxpy rejects, a point without a valid time.
    """
    try:
        root = SafeTree.fromstring(text)
    except ParseError as exc:
        raise GeoError(path, f"not well-formed XML ({exc})", exc.position[0]) from None
    except DefusedXmlException as exc:
        raise GeoError(path, f"refused XML ({type(exc).__name__})") from None
    try:
        gpx = gpxpy.parse(text)
    except gpxpy.gpx.GPXException as exc:
        raise GeoError(path, f"not a valid GPX file ({exc})", _bad_point(root)) from None
    if not any(segment.points for track in gpx.tracks for segment in track.segments) and (
        gpx.routes or gpx.waypoints
    ):
        raise GeoError(path, "no track point (<trkpt>): routes and waypoints are not a drive")
    rows: list[tuple[int | str, float, float, float]] = []
    points = (p for track in gpx.tracks for segment in track.segments for p in segment.points)
    for number, point in enumerate(points, start=1):
        label = f"track point {number}"
        if point.time is None:
            raise GeoError(path, "no valid <time> (ISO 8601 date and time)", label)
        stamp = point.time if point.time.tzinfo else point.time.replace(tzinfo=UTC)
        try:
            seconds = stamp.timestamp()
        except (OverflowError, ValueError) as exc:
            raise GeoError(path, f"time {point.time} out of range ({exc})", label) from None
        rows.append((label, seconds, float(point.latitude), float(point.longitude)))
    return rows
