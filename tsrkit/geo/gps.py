"""GPS logs (CSV, the whitespace ``dd-Mon-yyyy hh:mm:ss lat lon`` lines, GPX, NMEA) and
positions at frame times (Zheng 2016, 4.3, Eq. 4.1-4.2)."""

from __future__ import annotations

import csv
import math
import os
import warnings
from dataclasses import dataclass
from datetime import UTC, datetime
from pathlib import Path

import numpy as np

from tsrkit.core.errors import TsrkitWarning
from tsrkit.geo.errors import GeoError, read_text
from tsrkit.geo.gpx import gpx_rows
from tsrkit.geo.nmea import nmea_rows

__all__ = ["LOG_FORMATS", "MAX_SPEED", "MIN_JUMP_M", "Rows", "Track", "log_format", "read_track"]

#: The fastest a logged vehicle moves between two fixes, m/s (324 km/h, past any road vehicle):
#: a faster step is a receiver glitch or a jump between two logs, never a drive.
MAX_SPEED = 90.0
#: Steps shorter than this, metres, are never a jump, however fast: the position noise of a log
#: of 10 Hz or more moves a fix that far between neighbours.
MIN_JUMP_M = 50.0


@dataclass(frozen=True)
class Track:
    """GPS fixes in time order: UTC seconds since the epoch, latitude and longitude (degrees).

    ``breaks`` are the indices of the fixes that start a new piece of the log: the step from
    the fix before is faster than :data:`MAX_SPEED`, so no position is interpolated across it.
    """

    source: str
    time: np.ndarray
    lat: np.ndarray
    lon: np.ndarray
    breaks: tuple[int, ...] = ()

    def __len__(self) -> int:
        return len(self.time)

    def at(self, times: np.ndarray, max_gap: float = 5.0) -> tuple[np.ndarray, np.ndarray]:
        """Latitude and longitude at ``times`` by linear interpolation between the two fixes
        around each (Eq. 4.2); NaN where the fixes are more than ``max_gap`` seconds apart, or
        across one of the ``breaks``, or ``times`` lie outside the track: a gap is reported,
        never bridged."""
        times = np.asarray(times, np.float64)
        right = np.clip(np.searchsorted(self.time, times), 1, len(self.time) - 1)
        left = right - 1
        span = self.time[right] - self.time[left]
        w = np.where(span > 0, (times - self.time[left]) / np.where(span > 0, span, 1), 0.0)
        lat = self.lat[left] + w * (self.lat[right] - self.lat[left])
        lon = self.lon[left] + w * (self.lon[right] - self.lon[left])
        jump = np.isin(right, self.breaks) & (times < self.time[right])
        bad = (span > max_gap) | jump | (times < self.time[0]) | (times > self.time[-1])
        return np.where(bad, np.nan, lat), np.where(bad, np.nan, lon)

    def gaps(self, max_gap: float = 5.0) -> list[tuple[float, float]]:
        """(start, end) UTC seconds of every gap between fixes longer than ``max_gap``, and of
        every one of the ``breaks``."""
        step = np.diff(self.time)
        ends = sorted({*np.flatnonzero(step > max_gap).tolist(), *(i - 1 for i in self.breaks)})
        return [(float(self.time[i]), float(self.time[i + 1])) for i in ends]


def _whitespace_time(date: str, clock: str) -> float:
    stamp = datetime.strptime(f"{date} {clock}", "%d-%b-%Y %H:%M:%S")
    return stamp.replace(tzinfo=UTC).timestamp()


def _csv_time(text: str) -> float:
    try:
        return float(text)
    except ValueError:
        stamp = datetime.fromisoformat(text.replace("Z", "+00:00"))
        if stamp.tzinfo is None:
            stamp = stamp.replace(tzinfo=UTC)
        return stamp.timestamp()


Rows = list[tuple[int | str, float, float, float]]

#: UTC seconds of the first and last instant a GPS time may name (1970-01-01, 9999-12-31).
EARLIEST, LATEST = 0.0, 253402300799.0

#: Log formats by file extension; other extensions are told apart by their first character.
#: Every format :func:`log_format` answers (``tsrkit track --gps`` names each in its help).
LOG_FORMATS = ("csv", "gpx", "nmea", "whitespace")
_BY_SUFFIX = {".csv": "csv", ".gpx": "gpx", ".nmea": "nmea", ".nma": "nmea", ".nme": "nmea"}


def _csv_rows(path: Path, lines: list[str]) -> Rows:
    reader = csv.reader(lines)
    try:
        header = [h.strip().lower() for h in next(reader, [])]
        missing = {"time", "lat", "lon"} - set(header)
        if missing:
            raise GeoError(path, f"CSV header lacks {', '.join(sorted(missing))}", 1)
        index = [header.index(k) for k in ("time", "lat", "lon")]
        rows: Rows = []
        for fields in reader:
            number = reader.line_num
            if not fields or not "".join(fields).strip():
                continue
            if len(fields) < len(header):
                raise GeoError(path, f"expected {len(header)} columns, got {len(fields)}", number)
            try:
                t, la, lo = (
                    _csv_time(fields[index[0]]),
                    float(fields[index[1]]),
                    float(fields[index[2]]),
                )
            except (ValueError, OverflowError) as exc:
                raise GeoError(
                    path, f"not a time, latitude and longitude ({exc})", number
                ) from None
            rows.append((number, t, la, lo))
    except csv.Error as exc:
        raise GeoError(path, f"not CSV ({exc})", reader.line_num) from None
    return rows


def _whitespace_rows(path: Path, lines: list[str]) -> Rows:
    rows: Rows = []
    for number, line in enumerate(lines, start=1):
        fields = line.split()
        if not fields or fields[0].lower().startswith("date"):
            continue
        if len(fields) != 4:
            raise GeoError(
                path, f"expected 'dd-Mon-yyyy hh:mm:ss lat lon', got {len(fields)} fields", number
            )
        try:
            rows.append(
                (number, _whitespace_time(fields[0], fields[1]), float(fields[2]), float(fields[3]))
            )
        except ValueError as exc:
            raise GeoError(
                path, f"not a date, time, latitude and longitude ({exc})", number
            ) from None
    return rows


def log_format(path: Path, text: str) -> str:
    """``csv``, ``gpx``, ``nmea`` or ``whitespace``: by extension, else by the content (``<``
    first: GPX; ``$`` or ``!``: NMEA; a first line with a comma and ``lat``: CSV; anything else
    the whitespace lines).

    >>> log_format(Path("drive.log"), "$GPRMC,...")
    'nmea'
    >>> log_format(Path("drive.txt"), "time,lat,lon\\n0,47.6,-122.1")
    'csv'
    """
    if path.suffix.lower() in _BY_SUFFIX:
        return _BY_SUFFIX[path.suffix.lower()]
    first = text.lstrip().split("\n", 1)[0].lower()
    if first[:1] in ("<", "$", "!"):
        return "gpx" if first[0] == "<" else "nmea"
    return "csv" if "," in first and "lat" in first else "whitespace"


def _rows(path: Path) -> tuple[Rows, str]:
    text = read_text(path)
    kind = log_format(path, text)
    if kind == "gpx":
        return gpx_rows(path, text), kind
    lines = text.splitlines()
    if kind == "nmea":
        return nmea_rows(path, lines), kind
    if kind == "csv":
        return _csv_rows(path, lines), kind
    return _whitespace_rows(path, lines), kind


def read_track(path: str | os.PathLike) -> Track:
    """Read a GPS log: CSV with a ``time,lat,lon`` header (time as UTC seconds or ISO 8601),
    the whitespace ``dd-Mon-yyyy hh:mm:ss lat lon`` lines of the Seattle drive, GPX (track
    points, through gpxpy) or NMEA 0183 (RMC and GGA sentences, through pynmea2); the format
    is chosen by :func:`log_format`.

    Raises
    ------
    GeoError
        Naming the file and line (GPX: track point): missing file, invalid text, wrong column
        count or tags, a value that is not a number, NaN, a time outside the years 1970-9999,
        a latitude or longitude out of range, times not increasing, or no fix at all.

    Warns
    -----
    TsrkitWarning
        A fix that exactly repeats the one before is left out; so is a glitch fix, reached and
        left faster than :data:`MAX_SPEED` (over more than :data:`MIN_JUMP_M`) while its
        neighbours are not that far apart; any other step that fast splits the log
        (:attr:`Track.breaks`). One warning for each, naming the line.
    """
    path = Path(path)
    rows, _ = _rows(path)
    if not rows:
        raise GeoError(path, "no GPS fix in the file")
    previous = -math.inf
    kept: Rows = []
    for number, t, la, lo in rows:
        if not all(math.isfinite(v) for v in (t, la, lo)):
            raise GeoError(path, "time, latitude or longitude is not finite", number)
        if not EARLIEST <= t <= LATEST:
            raise GeoError(path, f"time {t:g} s is outside the years 1970-9999", number)
        if not -90 <= la <= 90 or not -180 <= lo <= 180:
            raise GeoError(path, f"latitude {la} / longitude {lo} out of range", number)
        if kept and kept[-1][1:] == (t, la, lo):
            _warn(path, number, "exactly repeats the fix before: left out")
            continue
        if t <= previous:
            raise GeoError(path, "times are not increasing (sort the log)", number)
        previous = t
        kept.append((number, t, la, lo))
    kept, breaks = _plausible(path, kept)
    columns = np.array([row[1:] for row in kept], np.float64)
    return Track(str(path), columns[:, 0], columns[:, 1], columns[:, 2], tuple(breaks))


Fix = tuple[int | str, float, float, float]


def _metres(a: Fix, b: Fix) -> float:
    """Great-circle distance from fix ``a`` to fix ``b`` (haversine, mean Earth radius)."""
    p0, p1 = math.radians(a[2]), math.radians(b[2])
    h = (
        math.sin((p1 - p0) / 2) ** 2
        + math.cos(p0) * math.cos(p1) * math.sin(math.radians(b[3] - a[3]) / 2) ** 2
    )
    return 2 * 6_371_008.8 * math.asin(min(1.0, math.sqrt(h)))


def _too_fast(a: Fix, b: Fix) -> bool:
    """Whether the step from fix ``a`` to the later fix ``b`` is no drive: faster than
    :data:`MAX_SPEED` over more than :data:`MIN_JUMP_M`."""
    metres = _metres(a, b)
    return metres > MIN_JUMP_M and metres > MAX_SPEED * (b[1] - a[1])


def _plausible(path: Path, rows: Rows) -> tuple[Rows, list[int]]:
    """``rows`` without glitch fixes, and the indices where a jump faster than
    :data:`MAX_SPEED` splits what is left (see :func:`read_track`)."""
    kept = list(rows)
    k = 1
    while k < len(kept) - 1:
        before, fix, after = kept[k - 1 : k + 2]
        if _too_fast(before, fix) and _too_fast(fix, after) and not _too_fast(before, after):
            _warn(
                path,
                fix[0],
                f"a glitch: the fix {fix[2]:.6f}, {fix[3]:.6f} is reached and left faster than "
                f"{MAX_SPEED:g} m/s: left out",
            )
            del kept[k]
            continue
        k += 1
    breaks = [k for k in range(1, len(kept)) if _too_fast(kept[k - 1], kept[k])]
    for k in breaks:
        _warn(
            path,
            kept[k][0],
            f"the log jumps {_metres(kept[k - 1], kept[k]):,.0f} m in "
            f"{kept[k][1] - kept[k - 1][1]:g} s (faster than {MAX_SPEED:g} m/s): split there, "
            "no position is interpolated across the jump",
        )
    return kept, breaks


def _warn(path: Path, line: int | str, problem: str) -> None:
    """One :class:`TsrkitWarning` naming ``path`` and ``line``, worded as :class:`GeoError`."""
    warnings.warn(str(GeoError(path, problem, line)), TsrkitWarning, stacklevel=3)
