"""NMEA 0183 logs through pynmea2: the fixes of RMC and GGA sentences (Zheng 2016, 4.3)."""

from __future__ import annotations

from bisect import bisect_right
from datetime import UTC, date, datetime, time, timedelta
from pathlib import Path

import pynmea2

from tsrkit.geo.errors import GeoError

__all__ = ["nmea_rows"]

#: A GGA time further than this from its RMC's time of day lies across midnight.
_HALF_DAY = 43200.0


def _position(path: Path, sentence, number: int) -> tuple[float, float]:
    """Signed degrees of a sentence's ``lat``/``lon`` fields; pynmea2 reads empty fields as 0,
    so presence and hemisphere are checked here first."""
    if (
        not sentence.lat
        or not sentence.lon
        or sentence.lat_dir not in ("N", "S")
        or sentence.lon_dir not in ("E", "W")
    ):
        raise GeoError(path, f"{sentence.sentence_type} fix without a full position", number)
    return float(sentence.latitude), float(sentence.longitude)


def _fixes(path: Path, lines: list[str]) -> list[tuple[int, str, date | None, time, float, float]]:
    """``(line, kind, date or None, time of day, lat, lon)`` of every valid RMC / GGA fix; void
    RMC (status V) and no-fix GGA (quality 0) sentences are skipped: they carry no position."""
    fixes = []
    for number, line in enumerate(lines, start=1):
        text = line.strip()
        if not text:
            continue
        try:
            sentence = pynmea2.parse(text)
        except pynmea2.ParseError as exc:
            raise GeoError(path, f"not an NMEA sentence ({exc})", number) from None
        kind = getattr(sentence, "sentence_type", "")
        if kind not in ("RMC", "GGA"):
            continue
        try:
            if kind == "RMC" and sentence.status != "A":
                continue
            if kind == "GGA" and not int(sentence.gps_qual or 0):
                continue
            day = sentence.datestamp if kind == "RMC" else None
            clock = sentence.timestamp
            # pynmea2 gives None for an empty field and the raw text for one it cannot convert
            if not isinstance(clock, time) or (kind == "RMC" and not isinstance(day, date)):
                raise GeoError(path, f"{kind} fix without a valid time or date", number)
            lat, lon = _position(path, sentence, number)
        except (ValueError, TypeError) as exc:
            raise GeoError(path, f"bad {kind} field ({exc})", number) from None
        fixes.append((number, kind, day, clock, lat, lon))
    return fixes


def nmea_rows(path: Path, lines: list[str]) -> list[tuple[int | str, float, float, float]]:
    """``(line, UTC seconds, lat, lon)`` of the fixes of an NMEA log.

    RMC sentences carry the date; a GGA sentence takes the date of the nearest RMC (the
    previous one, else the next), a day later or earlier when their times of day lie more than
    12 h apart (midnight). An RMC and a GGA of the same second are one fix (the first kept).

    Raises
    ------
    GeoError
        A line that is not an NMEA sentence (bad checksum, unknown type, garbage), a fix with a
        missing or malformed field, or GGA fixes with no RMC to date them.
    """
    fixes = _fixes(path, lines)
    dated = [(k, f[2], f[3]) for k, f in enumerate(fixes) if f[2] is not None]
    if fixes and not dated:
        raise GeoError(path, "GGA fixes carry no date and the log has no RMC", fixes[0][0])
    rows: list[tuple[int | str, float, float, float]] = []
    last_kind = ""
    for k, (number, kind, _, clock, lat, lon) in enumerate(fixes):
        _, day, ref_clock = dated[max(bisect_right(dated, k, key=lambda d: d[0]) - 1, 0)]
        stamp = datetime.combine(day, clock.replace(tzinfo=None), tzinfo=UTC)
        shift = stamp - datetime.combine(day, ref_clock.replace(tzinfo=None), tzinfo=UTC)
        if abs(shift.total_seconds()) > _HALF_DAY:
            stamp -= timedelta(days=1 if shift.total_seconds() > 0 else -1)
        try:
            seconds = stamp.timestamp()
        except (OverflowError, ValueError) as exc:
            raise GeoError(path, f"time out of range ({exc})", number) from None
        if rows and seconds == rows[-1][1] and kind != last_kind:
            continue
        rows.append((number, seconds, lat, lon))
        last_kind = kind
    return rows
