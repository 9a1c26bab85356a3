"""Lee's solar geometry (2017, 4.1.1, Eq. 4.1-4.6) on hand-computed cases, and the run-time NOAA
algorithm against pvlib's solar position over a year at several latitudes."""

from __future__ import annotations

import math

import numpy as np
import pytest

from tsrkit.sun.geometry import (
    azimuth_from,
    day_of_year,
    declination_lee,
    elevation_from,
    equation_of_time_lee,
    hour_angle,
    local_solar_time,
    sun_position,
    sun_position_lee,
    zenith,
)

DAY = 86400.0


def test_day_of_year_counts_from_one_and_knows_leap_years():
    assert day_of_year(0.0) == 1  # 1970-01-01
    assert day_of_year(np.array([DAY * 31, DAY * 365 - 1])).tolist() == [32, 365]
    new_year_eve_2024 = (
        (np.datetime64("2024-12-31T23:00") - np.datetime64("1970-01-01"))
        .astype("timedelta64[s]")
        .astype(float)
    )
    assert day_of_year(new_year_eve_2024) == 366


def test_hour_angle_eq_4_1():
    assert hour_angle(12.0) == 0.0
    assert hour_angle(15.0) == 45.0
    assert hour_angle(6.0) == -90.0


def test_equation_of_time_and_time_correction_eq_4_2():
    assert equation_of_time_lee(81) == pytest.approx(-7.53)
    # Longitude 15 degrees east of its meridian: 60 minutes later, less EoT's 7.53 minutes.
    assert local_solar_time(10.0, 30.0, 1.0, 81) == pytest.approx(10.0 + (60 - 7.53) / 60)


def test_declination_eq_4_3():
    assert declination_lee(81) == pytest.approx(0.0, abs=1e-12)
    expected = math.degrees(
        math.asin(math.sin(math.radians(23.45)) * math.sin(math.radians(360 / 365.24 * 91)))
    )
    assert declination_lee(172) == pytest.approx(expected)
    assert declination_lee(172) == pytest.approx(23.45, abs=0.01)


def test_elevation_azimuth_zenith_eq_4_4_to_4_6():
    assert elevation_from(0.0, 0.0, 0.0) == pytest.approx(90.0)
    assert elevation_from(0.0, 45.0, 0.0) == pytest.approx(45.0)
    assert elevation_from(0.0, 0.0, -90.0) == pytest.approx(0.0, abs=1e-9)
    # Equinox sunrise on the equator: due east; sunset: due west.
    assert azimuth_from(0.0, 0.0, -90.0, 0.0) == pytest.approx(90.0)
    assert azimuth_from(0.0, 0.0, 90.0, 0.0) == pytest.approx(270.0)
    # Noon at 45 N on the equinox: due south.
    assert azimuth_from(0.0, 45.0, -1e-9, 45.0) == pytest.approx(180.0, abs=1e-6)
    assert zenith(30.0) == 60.0


@pytest.fixture(scope="module")
def year_of_positions():
    pd = pytest.importorskip("pandas")
    solarposition = pytest.importorskip("pvlib.solarposition")
    times = pd.date_range("2025-01-01", "2026-01-01", freq="47min", tz="UTC")[:-1]
    utc = (times - pd.Timestamp("1970-01-01", tz="UTC")).total_seconds().to_numpy()
    places = [(-54.8, -68.3), (-33.9, 151.2), (0.3, 32.6), (23.4, -82.4), (40.4, -80.0),
              (52.5, 13.4), (64.1, -21.9)]  # fmt: skip
    result = []
    for lat, lon in places:
        ref = solarposition.get_solarposition(times, lat, lon, method="nrel_numpy")
        result.append((utc, lat, lon, ref["azimuth"].to_numpy(), ref["elevation"].to_numpy()))
    return result


def angle_errors(position, utc, lat, lon, ref_az, ref_el):
    az, el = position(utc, lat, lon)
    up = ref_el > 0
    # Azimuth is undefined at the zenith: compare it below 88 degrees of elevation.
    steep = up & (ref_el < 88)
    return (
        np.abs(el - ref_el)[up].max(),
        np.abs((az - ref_az + 180) % 360 - 180)[steep].max(),
    )


def test_run_time_position_matches_pvlib_within_half_a_degree(year_of_positions):
    for utc, lat, lon, ref_az, ref_el in year_of_positions:
        el_err, az_err = angle_errors(sun_position, utc, lat, lon, ref_az, ref_el)
        assert el_err < 0.5 and az_err < 0.5, (lat, el_err, az_err)


def test_lee_equations_stay_within_their_approximation(year_of_positions):
    """Lee's day-of-year sine and three-term EoT err by about a degree of elevation; the test
    pins that documented size, so a broken equation (signs, units) cannot pass."""
    for utc, lat, lon, ref_az, ref_el in year_of_positions:
        el_err, _ = angle_errors(sun_position_lee, utc, lat, lon, ref_az, ref_el)
        assert 0.3 < el_err < 1.5, (lat, el_err)
