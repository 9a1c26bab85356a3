"""Where the Sun stands: Lee's solar geometry (Lee 2017, 4.1.1, Eq. 4.1-4.6) and the NOAA
solar-position algorithm that tsrkit uses at run time.

Lee's equations approximate the declination by a sine of the day of the year and the equation of
time by three terms; they err by up to about 1.5 degrees of elevation (measured against pvlib's
SPA in ``benchmarks/RESULTS.sun.md``). :func:`sun_position` therefore uses the NOAA solar
calculator (Meeus, *Astronomical Algorithms*, low-precision series), which agrees with pvlib's SPA
to about 0.01 degree for 1900-2100 and needs only NumPy: it is vectorised and has no pandas
dependency, so tsrkit uses it at run time and keeps Lee's equations for reference and comparison.

Times are UTC seconds since the Unix epoch; angles are degrees. Azimuth is measured clockwise
from north (0 north, 90 east); elevation is the geometric elevation above the horizon, without
atmospheric refraction.
"""

from __future__ import annotations

import numpy as np

__all__ = [
    "DAY_S",
    "UNIX_EPOCH_JD",
    "azimuth_from",
    "day_of_year",
    "declination_lee",
    "elevation_from",
    "equation_of_time_lee",
    "hour_angle",
    "local_solar_time",
    "sun_position",
    "sun_position_lee",
    "zenith",
]

#: Seconds in a day and the Julian date of the Unix epoch.
DAY_S = 86400.0
UNIX_EPOCH_JD = 2440587.5


def day_of_year(utc_s: np.ndarray) -> np.ndarray:
    """Day of the year of UTC seconds since the epoch, January 1 being 1 (Lee 2017, 4.1.1)."""
    days = np.asarray(utc_s, np.float64) // DAY_S
    date = np.datetime64("1970-01-01", "D") + days.astype("timedelta64[D]")
    year_start = date.astype("datetime64[Y]").astype("datetime64[D]")
    return (date - year_start).astype(np.int64) + 1


def hour_angle(solar_time_h: np.ndarray) -> np.ndarray:
    """Eq. 4.1: the hour angle ``15 (gamma - 12)`` degrees of the local solar time in hours."""
    return 15.0 * (np.asarray(solar_time_h, np.float64) - 12.0)


def equation_of_time_lee(day: np.ndarray) -> np.ndarray:
    """EoT in minutes, ``9.87 sin 2B - 7.53 cos B - 1.5 sin B`` with ``B = 360 (d - 81) / 365``
    degrees (Lee 2017, 4.1.1, under Eq. 4.4; the printed minus signs were lost)."""
    b = np.radians(360.0 / 365.0 * (np.asarray(day, np.float64) - 81.0))
    return 9.87 * np.sin(2 * b) - 7.53 * np.cos(b) - 1.5 * np.sin(b)


def local_solar_time(local_time_h, longitude, utc_offset_h, day) -> np.ndarray:
    """Eq. 4.2: ``gamma = eta + TC / 60`` hours, with the time correction
    ``TC = 4 (longitude - LSTM) + EoT`` minutes and ``LSTM = 15 dT_GMT`` degrees."""
    lstm = 15.0 * np.asarray(utc_offset_h, np.float64)
    tc = 4.0 * (np.asarray(longitude, np.float64) - lstm) + equation_of_time_lee(day)
    return np.asarray(local_time_h, np.float64) + tc / 60.0


def declination_lee(day: np.ndarray) -> np.ndarray:
    """Eq. 4.3: ``asin(sin 23.45 sin(360 (d - 81) / 365.24))`` in degrees."""
    angle = np.radians(360.0 / 365.24 * (np.asarray(day, np.float64) - 81.0))
    return np.degrees(np.arcsin(np.sin(np.radians(23.45)) * np.sin(angle)))


def elevation_from(declination, latitude, hour_angle_deg) -> np.ndarray:
    """Eq. 4.4: ``asin(sin d sin phi + cos d cos phi cos HRA)`` in degrees."""
    d, phi, h = (
        np.radians(np.asarray(v, np.float64)) for v in (declination, latitude, hour_angle_deg)
    )
    return np.degrees(
        np.arcsin(np.clip(np.sin(d) * np.sin(phi) + np.cos(d) * np.cos(phi) * np.cos(h), -1, 1))
    )


def azimuth_from(declination, latitude, hour_angle_deg, elevation) -> np.ndarray:
    """Eq. 4.5: ``acos((sin d cos phi - cos d sin phi cos HRA) / cos theta)`` in degrees from
    north; the equation gives the morning half, so afternoons (``HRA > 0``) take
    ``360 - acos(...)`` (the text leaves this case implicit)."""
    d, phi, h, el = (
        np.radians(np.asarray(v, np.float64))
        for v in (declination, latitude, hour_angle_deg, elevation)
    )
    cos_el = np.cos(el)
    ratio = (np.sin(d) * np.cos(phi) - np.cos(d) * np.sin(phi) * np.cos(h)) / np.where(
        cos_el > 1e-12, cos_el, 1e-12
    )
    morning = np.degrees(np.arccos(np.clip(ratio, -1.0, 1.0)))
    return np.where(np.asarray(hour_angle_deg) > 0, 360.0 - morning, morning)


def zenith(elevation) -> np.ndarray:
    """Eq. 4.6: the zenith angle ``90 - theta_s`` in degrees."""
    return 90.0 - np.asarray(elevation, np.float64)


def sun_position_lee(utc_s, latitude, longitude) -> tuple[np.ndarray, np.ndarray]:
    """Azimuth and elevation by Lee's Eq. 4.1-4.5 from UTC seconds (so ``dT_GMT = 0`` and
    ``eta`` is the UTC hour; the result does not depend on the time zone)."""
    utc_s = np.asarray(utc_s, np.float64)
    day = day_of_year(utc_s)
    hours = np.mod(utc_s, DAY_S) / 3600.0
    hra = hour_angle(local_solar_time(hours, longitude, 0.0, day))
    hra = np.mod(hra + 180.0, 360.0) - 180.0
    decl = declination_lee(day)
    elevation = elevation_from(decl, latitude, hra)
    return azimuth_from(decl, latitude, hra, elevation), elevation


def sun_position(utc_s, latitude, longitude) -> tuple[np.ndarray, np.ndarray]:
    """Azimuth (clockwise from north) and geometric elevation of the Sun, in degrees, by the NOAA
    solar calculator (Meeus' low-precision series); the run-time algorithm of tsrkit.

    Parameters
    ----------
    utc_s : array_like
        UTC seconds since the Unix epoch.
    latitude, longitude : array_like
        Degrees, north and east positive; broadcast against ``utc_s``.

    Returns
    -------
    azimuth, elevation : numpy.ndarray
    """
    utc_s = np.asarray(utc_s, np.float64)
    lat = np.radians(np.asarray(latitude, np.float64))
    lon = np.asarray(longitude, np.float64)
    t = (utc_s / DAY_S + UNIX_EPOCH_JD - 2451545.0) / 36525.0  # Julian centuries since J2000
    mean_long = np.mod(280.46646 + t * (36000.76983 + t * 0.0003032), 360.0)
    anomaly = np.radians(357.52911 + t * (35999.05029 - 0.0001537 * t))
    ecc = 0.016708634 - t * (0.000042037 + 0.0000001267 * t)
    centre = (
        np.sin(anomaly) * (1.914602 - t * (0.004817 + 0.000014 * t))
        + np.sin(2 * anomaly) * (0.019993 - 0.000101 * t)
        + np.sin(3 * anomaly) * 0.000289
    )
    omega = np.radians(125.04 - 1934.136 * t)
    apparent_long = np.radians(mean_long + centre - 0.00569 - 0.00478 * np.sin(omega))
    mean_obliquity = (
        23.0 + (26.0 + (21.448 - t * (46.815 + t * (0.00059 - t * 0.001813))) / 60.0) / 60.0
    )
    obliquity = np.radians(mean_obliquity + 0.00256 * np.cos(omega))
    decl = np.arcsin(np.sin(obliquity) * np.sin(apparent_long))
    y = np.tan(obliquity / 2) ** 2
    l0 = np.radians(mean_long)
    eot_min = 4 * np.degrees(
        y * np.sin(2 * l0)
        - 2 * ecc * np.sin(anomaly)
        + 4 * ecc * y * np.sin(anomaly) * np.cos(2 * l0)
        - 0.5 * y * y * np.sin(4 * l0)
        - 1.25 * ecc * ecc * np.sin(2 * anomaly)
    )
    true_solar_min = np.mod(np.mod(utc_s, DAY_S) / 60.0 + eot_min + 4 * lon, 1440.0)
    hra = np.radians(true_solar_min / 4.0 - 180.0)
    cos_zen = np.clip(np.sin(lat) * np.sin(decl) + np.cos(lat) * np.cos(decl) * np.cos(hra), -1, 1)
    zen = np.arccos(cos_zen)
    azimuth = np.degrees(
        np.arctan2(np.sin(hra), np.cos(hra) * np.sin(lat) - np.tan(decl) * np.cos(lat))
    )
    return np.mod(azimuth + 180.0, 360.0), 90.0 - np.degrees(zen)
