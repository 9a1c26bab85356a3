"""A study's manifest of drives (videos with their GPS logs and maps) and the combined answers
of their ``tsrkit track`` runs: ``timelines.csv``, ``events.csv`` and ``traversals.geojson``.

Manifest: CSV with a header, or YAML (a list of mappings, or a mapping with a ``drives`` list);
fields ``video``, ``gps``, ``map`` (paths, relative ones to the manifest's folder), optional
``name`` (default the video's stem, numbered when repeated) and ``start_utc`` (the video's first
frame, epoch seconds or ISO 8601, as ``tsrkit track --start-utc``).

Each drive runs into ``OUT/drives/NAME/``; a drive whose ``done.json`` names the same inputs
(paths, sizes, modification times) is finished and skipped, so a killed study resumes.
"""

from __future__ import annotations

import csv
import json
import os
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import yaml

from tsrkit.core.atomic import write_json
from tsrkit.core.errors import TsrkitError
from tsrkit.spatiotemporal.events import TIMELINE_COLUMNS, write_rows
from tsrkit.spatiotemporal.study import STUDY_EVENT_COLUMNS

__all__ = [
    "DriveEntry",
    "ManifestError",
    "combine",
    "finished",
    "mark_done",
    "read_manifest",
]

FIELDS = ("video", "gps", "map")


class ManifestError(TsrkitError):
    """A manifest that cannot be read or lacks a field."""


@dataclass(frozen=True)
class DriveEntry:
    """One drive of a manifest: its name, inputs and the video's start time (text or None)."""

    name: str
    video: Path
    gps: Path
    map: Path
    start_utc: str | None = None

    def inputs(self) -> dict[str, Any]:
        """The inputs' paths, sizes and modification times (what ``done.json`` records)."""
        facts = {}
        for key in FIELDS:
            path = getattr(self, key)
            stat = path.stat()
            facts[key] = {"path": str(path), "size": stat.st_size, "mtime": stat.st_mtime}
        return {**facts, "start_utc": self.start_utc}


def _records(path: Path) -> list[Any]:
    try:
        text = path.read_text(encoding="utf-8")
    except FileNotFoundError:
        raise ManifestError(f"{path}: no such file") from None
    except (OSError, UnicodeDecodeError) as exc:
        raise ManifestError(f"{path}: cannot read as UTF-8 text ({exc})") from None
    if path.suffix.lower() in (".yaml", ".yml"):
        try:
            data = yaml.safe_load(text)
        except yaml.YAMLError as exc:
            raise ManifestError(f"{path}: not valid YAML ({str(exc).splitlines()[0]})") from None
        if isinstance(data, dict):
            data = data.get("drives")
        if not isinstance(data, list):
            raise ManifestError(f"{path}: expected a list of drives (or a 'drives' list)")
        return data
    return list(csv.DictReader(text.splitlines()))


def read_manifest(path: str | os.PathLike) -> list[DriveEntry]:
    """The drives of a CSV or YAML manifest (module notes).

    Raises
    ------
    ManifestError
        Naming the file and, for a bad entry, its number (1 = the first drive).
    """
    path = Path(path)
    entries: list[DriveEntry] = []
    names: dict[str, int] = {}
    for number, record in enumerate(_records(path), start=1):
        if not isinstance(record, dict):
            raise ManifestError(f"{path}: drive {number}: not a mapping of fields")
        missing = [key for key in FIELDS if not str(record.get(key) or "").strip()]
        if missing:
            raise ManifestError(f"{path}: drive {number}: no {', '.join(missing)}")
        paths = {key: path.parent / str(record[key]).strip() for key in FIELDS}
        for key, value in paths.items():
            if not value.is_file():
                raise ManifestError(f"{path}: drive {number}: {key} {value}: no such file")
        base = str(record.get("name") or "").strip() or paths["video"].stem
        if "/" in base or base in (".", ".."):
            raise ManifestError(f"{path}: drive {number}: name {base!r} is not a folder name")
        names[base] = names.get(base, 0) + 1
        name = base if names[base] == 1 else f"{base}_{names[base]}"
        start = record.get("start_utc")
        entries.append(
            DriveEntry(name, **paths, start_utc=str(start) if start not in (None, "") else None)
        )
    if not entries:
        raise ManifestError(f"{path}: no drive listed")
    return entries


def finished(entry: DriveEntry, folder: Path) -> bool:
    """Whether ``folder`` holds a finished run of ``entry`` on the same inputs."""
    try:
        done = json.loads((folder / "done.json").read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return False
    return done == json.loads(json.dumps(entry.inputs()))


def mark_done(entry: DriveEntry, folder: Path) -> None:
    """Record that ``folder`` holds a finished run of ``entry`` (atomically, last)."""
    write_json(folder / "done.json", entry.inputs())


def _read(path: Path) -> list[dict[str, str]]:
    with path.open(encoding="utf-8", newline="") as fh:
        return list(csv.DictReader(fh))


def combine(out: Path, entries: Sequence[DriveEntry]) -> dict[str, int]:
    """Write ``timelines.csv`` and ``events.csv`` (each drive's rows after a ``drive`` column)
    and ``traversals.geojson`` (a point per traversal at its intersection, with the drive,
    traversal, movement, entry and exit times and the count of each event kind) into ``out``;
    returns the row counts."""
    timelines, events, features = [], [], []
    for entry in entries:
        folder = out / "drives" / entry.name
        timelines += [{"drive": entry.name, **r} for r in _read(folder / "timelines.csv")]
        found = [{"drive": entry.name, **r} for r in _read(folder / "events.csv")]
        events += found
        for line in (folder / "traversals.jsonl").read_text(encoding="utf-8").splitlines():
            record = json.loads(line)
            kinds = [e["kind"] for e in found if e["traversal"] == str(record["traversal"])]
            properties = {
                "drive": entry.name,
                "traversal": record["traversal"],
                "intersection": record["intersection"],
                "movement": record["movement"],
                "entry": record["entry"],
                "exit": record["exit"],
                **{kind: kinds.count(kind) for kind in sorted(set(kinds))},
            }
            features.append(
                {
                    "type": "Feature",
                    "geometry": {"type": "Point", "coordinates": [record["lon"], record["lat"]]},
                    "properties": properties,
                }
            )
    write_rows(out / "timelines.csv", ("drive", *TIMELINE_COLUMNS), timelines)
    write_rows(out / "events.csv", ("drive", *STUDY_EVENT_COLUMNS), events)
    write_json(out / "traversals.geojson", {"type": "FeatureCollection", "features": features})
    return {"timelines": len(timelines), "events": len(events), "traversals": len(features)}
