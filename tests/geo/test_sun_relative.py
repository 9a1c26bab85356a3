"""Relative azimuth between the Sun and the camera (Lee 2017, 4.2) from frame facts."""

from __future__ import annotations

import numpy as np
import pytest

from tsrkit.geo.gps import Track
from tsrkit.sun.geometry import sun_position
from tsrkit.sun.relative import (
    SunMetadataError,
    bearing,
    frame_facts,
    relative_azimuth,
    sun_view,
    utc_seconds,
)


def test_relative_azimuth_is_zero_with_the_sun_behind_the_camera():
    # Sun in the south (180), camera looking north (0): the Sun is right behind it.
    assert relative_azimuth(180.0, 0.0) == 0.0
    assert relative_azimuth(180.0, 180.0) == 180.0
    assert relative_azimuth([90.0, 350.0], [0.0, 100.0]).tolist() == [90.0, 70.0]


def test_bearing_of_the_four_directions():
    assert bearing(0.0, 0.0, 0.001, 0.0) == pytest.approx(0.0, abs=1e-6)
    assert bearing(0.0, 0.0, 0.0, 0.001) == pytest.approx(90.0)
    assert bearing(0.0, 0.0, -0.001, 0.0) == pytest.approx(180.0)
    assert bearing(0.0, 0.0, 0.0, -0.001) == pytest.approx(270.0)


def test_utc_seconds_reads_numbers_and_zoned_iso_and_refuses_the_rest():
    assert utc_seconds(0) == 0.0
    assert utc_seconds("1970-01-01T01:00:00Z") == 3600.0
    assert utc_seconds("1970-01-01T02:00:00+01:00") == 3600.0
    for bad in ("1970-01-01T01:00:00", "noon", float("nan"), True, [1]):
        with pytest.raises(SunMetadataError):
            utc_seconds(bad)


def test_sun_view_from_time_position_and_heading():
    facts = {"utc": "2025-06-21T16:00:00Z", "lat": 40.44, "lon": -79.94, "heading_deg": 10.0}
    view = sun_view(facts)
    azimuth, elevation = sun_position(utc_seconds(facts["utc"]), 40.44, -79.94)
    assert view.sun_azimuth == pytest.approx(float(azimuth))
    assert view.sun_elevation == pytest.approx(float(elevation))
    assert view.relative_azimuth == pytest.approx(float(relative_azimuth(azimuth, 10.0)))
    assert sun_view({"relative_azimuth_deg": 30}).relative_azimuth == 30.0
    assert sun_view({"lat": 1.0, "lon": 2.0}) is None
    with pytest.raises(SunMetadataError, match="lat"):
        sun_view({**facts, "lat": 123.0})
    with pytest.raises(SunMetadataError, match="heading_deg"):
        sun_view({**facts, "heading_deg": "east"})


def test_frame_facts_prefer_the_frame_then_settings_then_the_gps_track():
    times = np.arange(100.0, 111.0)
    track = Track("drive", times, np.zeros(11), (times - 100.0) * 0.001)
    facts = frame_facts({}, 5.0, {"start_utc": 100.0}, track)
    assert facts["utc"] == 105.0
    assert facts["lat"] == pytest.approx(0.0) and facts["lon"] == pytest.approx(0.005)
    assert facts["heading_deg"] == pytest.approx(90.0)  # driving east
    own = frame_facts({"heading_deg": 45.0}, 5.0, {"start_utc": 100.0, "heading_deg": 0.0}, track)
    assert own["heading_deg"] == 45.0
    assert frame_facts({}, None, {"lat": 1.0}) == {"lat": 1.0}
    # At the track's first fix the heading comes from the fixes after it.
    assert frame_facts({}, 0.0, {"start_utc": 100.0}, track)["heading_deg"] == pytest.approx(90.0)
    # Outside the track: no position, so no Sun view (the fallback).
    assert sun_view(frame_facts({}, 50.0, {"start_utc": 100.0}, track)) is None
