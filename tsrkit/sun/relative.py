"""The Sun as a camera sees it: the relative azimuth between the Sun and the viewing direction
(Lee 2017, 4.2) from a frame's time, position and heading.

Lee measures the relative azimuth from the Sun to the camera that faces the target: 0 degrees
when the Sun is right behind the camera (the target's face is lit head-on, Figure 4.5), 180 when
the camera looks into the Sun. Elevation is left out, as in Lee's tables.

A frame's facts come, in this order, from its own metadata (a dataset's per-frame fields), from
the run's settings (``--param``), or from a GPS log matched to the frame's time (the heading is
the bearing of the track around that time). A frame that lacks them has no :class:`SunView`, and
the Sun-compensated model falls back to its uncompensated form.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass
from datetime import datetime
from typing import Any

import numpy as np
from pyproj import Geod

from tsrkit.core.errors import TsrkitError
from tsrkit.geo.gps import Track
from tsrkit.sun.geometry import sun_position

__all__ = [
    "KEYS",
    "SunMetadataError",
    "SunView",
    "bearing",
    "frame_facts",
    "relative_azimuth",
    "sun_elevation",
    "sun_view",
    "track_facts",
    "utc_seconds",
]

#: The per-frame metadata keys read, with what they hold.
KEYS = {
    "utc": "time of the frame: ISO 8601 with a time zone, or UTC seconds since the epoch",
    "lat": "camera latitude, degrees north",
    "lon": "camera longitude, degrees east",
    "heading_deg": "viewing direction, degrees clockwise from north",
    "relative_azimuth_deg": "the relative azimuth itself, when known (overrides the others)",
}
_WGS84 = Geod(ellps="WGS84")


class SunMetadataError(TsrkitError):
    """A frame's Sun facts are present but malformed (names the key and the value)."""


@dataclass(frozen=True)
class SunView:
    """Where the Sun stands for one frame: its azimuth and elevation (None when only the
    relative azimuth was given) and the relative azimuth in [0, 180] degrees."""

    relative_azimuth: float
    sun_azimuth: float | None = None
    sun_elevation: float | None = None


def relative_azimuth(sun_azimuth, heading) -> np.ndarray:
    """Lee 4.2's relative azimuth, ``180 - |wrap(sun_azimuth - heading)|`` in [0, 180]: 0 with
    the Sun behind a camera looking along ``heading``, 180 looking straight into it."""
    delta = np.mod(np.asarray(sun_azimuth, np.float64) - np.asarray(heading, np.float64), 360.0)
    return 180.0 - np.abs(np.where(delta > 180.0, delta - 360.0, delta))


def bearing(lat0, lon0, lat1, lon1) -> np.ndarray:
    """Forward geodesic azimuth (degrees clockwise from north, [0, 360)) from the first point to
    the second on the WGS84 ellipsoid (pyproj)."""
    forward, _, _ = _WGS84.inv(lon0, lat0, lon1, lat1)
    return np.mod(np.asarray(forward, np.float64), 360.0)


def utc_seconds(value: Any, key: str = "utc") -> float:
    """UTC seconds of a number (seconds since the epoch) or an ISO 8601 text with a time zone.

    Raises
    ------
    SunMetadataError
        For anything else, and for a time without a zone (the Sun's position needs UTC).
    """
    if isinstance(value, bool):
        raise SunMetadataError(f"{key}: expected a time, got {value!r}")
    if isinstance(value, (int, float)):
        if not math.isfinite(value):
            raise SunMetadataError(f"{key}: time is not finite ({value!r})")
        return float(value)
    if not isinstance(value, str):
        raise SunMetadataError(f"{key}: expected ISO 8601 text or seconds, got {value!r}")
    try:
        stamp = datetime.fromisoformat(value.strip().replace("Z", "+00:00"))
    except ValueError:
        raise SunMetadataError(f"{key}: not an ISO 8601 time: {value!r}") from None
    if stamp.tzinfo is None:
        raise SunMetadataError(f"{key}: {value!r} has no time zone; add Z or +hh:mm")
    return stamp.timestamp()


def _angle(facts: Mapping[str, Any], key: str, low: float, high: float) -> float | None:
    value = facts.get(key)
    if value is None:
        return None
    try:
        number = float(value)
    except (TypeError, ValueError):
        raise SunMetadataError(f"{key}: expected a number, got {value!r}") from None
    if not (math.isfinite(number) and low <= number <= high):
        raise SunMetadataError(f"{key}: {value!r} is outside [{low}, {high}]")
    return number


def sun_view(facts: Mapping[str, Any]) -> SunView | None:
    """The :class:`SunView` of one frame's facts (keys of :data:`KEYS`), or None when they are
    incomplete.

    Raises
    ------
    SunMetadataError
        When a fact is present but malformed.
    """
    given = _angle(facts, "relative_azimuth_deg", 0.0, 180.0)
    if given is not None:
        return SunView(given)
    lat = _angle(facts, "lat", -90.0, 90.0)
    lon = _angle(facts, "lon", -180.0, 180.0)
    heading = _angle(facts, "heading_deg", -360.0, 360.0)
    if facts.get("utc") is None or lat is None or lon is None or heading is None:
        return None
    azimuth, elevation = sun_position(utc_seconds(facts["utc"]), lat, lon)
    return SunView(float(relative_azimuth(azimuth, heading)), float(azimuth), float(elevation))


def sun_elevation(facts: Mapping[str, Any]) -> float | None:
    """The Sun's elevation in degrees at one frame's time and position (keys ``utc``, ``lat``,
    ``lon`` of :data:`KEYS`; no heading needed), or None when one is missing. Zheng's lighting
    conditions read it (:func:`tsrkit.eval.lighting.zheng_condition`).

    Raises
    ------
    SunMetadataError
        When a fact is present but malformed.

    Examples
    --------
    >>> round(sun_elevation({"utc": "2024-06-21T12:00:00Z", "lat": 0.0, "lon": 0.0}))
    67
    >>> sun_elevation({"lat": 0.0, "lon": 0.0}) is None
    True
    """
    lat = _angle(facts, "lat", -90.0, 90.0)
    lon = _angle(facts, "lon", -180.0, 180.0)
    if facts.get("utc") is None or lat is None or lon is None:
        return None
    return float(sun_position(utc_seconds(facts["utc"]), lat, lon)[1])


def track_facts(track: Track, utc: float, span_s: float = 1.0) -> dict[str, float]:
    """Position and heading at ``utc`` from a GPS track: the interpolated fix (Zheng Eq. 4.2)
    and the bearing from ``span_s`` before to ``span_s`` after it (within the track's ends);
    empty when the track has no fix there (outside it, or in a gap) or the car stands still."""
    start, end = float(track.time[0]), float(track.time[-1])
    times = np.array([max(utc - span_s, start), utc, min(utc + span_s, end)])
    lat, lon = track.at(times)
    if not np.all(np.isfinite(lat)) or (lat[0] == lat[2] and lon[0] == lon[2]):
        return {}
    return {
        "utc": utc,
        "lat": float(lat[1]),
        "lon": float(lon[1]),
        "heading_deg": float(bearing(lat[0], lon[0], lat[2], lon[2])),
    }


def frame_facts(
    metadata: Mapping[str, Any],
    timestamp: float | None,
    settings: Mapping[str, Any],
    track: Track | None = None,
) -> dict[str, Any]:
    """The Sun facts of one frame: the run's ``settings`` (keys of :data:`KEYS`, plus
    ``start_utc``, the time of a video's first frame, to which the frame's ``timestamp`` in
    seconds is added), overridden by the frame's own ``metadata``; position and heading still
    missing are taken from ``track`` at the frame's time."""
    facts = {k: v for k, v in settings.items() if k in KEYS and v is not None}
    start = settings.get("start_utc")
    if start is not None and "utc" not in facts:
        facts["utc"] = utc_seconds(start, "start_utc") + (timestamp or 0.0)
    facts.update({k: v for k, v in metadata.items() if k in KEYS and v is not None})
    if track is not None and "utc" in facts and "relative_azimuth_deg" not in facts:
        found = track_facts(track, utc_seconds(facts["utc"]))
        facts.update({k: v for k, v in found.items() if k not in facts})
    return facts
