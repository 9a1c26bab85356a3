"""What ``tsrkit track`` reports, as results the report writers render like a benchmark's: the
run's description (video, GPS log, map, plugins, settings, versions, timing) and the traversals
(a headline, the per-traversal table, the Zheng 5.4 accuracies when ground truth is given, the
vicinity profile and one timeline per traversal)."""

from __future__ import annotations

import functools
import json
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, ClassVar

import numpy as np

from tsrkit.core.errors import TsrkitError
from tsrkit.core.files import loads_json, read_text
from tsrkit.core.results import Figure, MetricResult, Plot, Table, fmt
from tsrkit.eval.runfacts import STAGES, description_tables
from tsrkit.reporting.report import RunResult
from tsrkit.reporting.track_plots import draw_timeline, draw_vicinity

__all__ = [
    "ACCURACY_NOTE",
    "TrackFacts",
    "TraversalsResult",
    "is_track_report",
    "load_track_run",
    "read_traversals",
    "summary_rows",
]

#: What a record of ``traversals.jsonl`` holds (its number and the fields the reports read).
TRAVERSAL_FIELDS = ("traversal", "intersection", "movement", "anchor_frame", "short_range")

#: What the accuracy column of the traversal table holds.
ACCURACY_NOTE = (
    "acc.: temporal accuracy of the true tracks (Zheng 5.4), all candidates / detected ones"
)


def summary_rows(
    records: Sequence[Mapping[str, Any]], evaluations: Sequence[Mapping[str, Any]] | None
) -> tuple[list[str], list[list[str]]]:
    """The per-traversal table: columns and rows (the terminal's and the reports')."""
    columns = ["#", "node", "movement", "anchor", "short range", "tracks"]
    if evaluations is not None:
        columns += ["true", "acc."]
    rows = []
    for k, record in enumerate(records):
        row = [
            str(record["traversal"]),
            str(record["intersection"]),
            record["movement"],
            str(record["anchor_frame"]),
            "{}-{}".format(*record["short_range"]),
            str(len(record["tracks"])),
        ]
        if evaluations is not None:
            e = evaluations[k]
            row += [
                str(e["true_tracks"]),
                f"{fmt(e['temporal_accuracy'])} / {fmt(e['detected_accuracy'])}",
            ]
        rows.append(row)
    return columns, rows


@dataclass(frozen=True)
class TrackFacts(MetricResult):
    """The track run's description: inputs, plugins and their parameters, settings, versions
    and timing (``sections`` is the run's ``report.json``)."""

    order: ClassVar[int] = 0

    def tables(self) -> list[Table]:
        report = self.sections
        given = report.get("plugins") or {}
        plugins = {k: given[k] for k in (*STAGES, "tracker") if given.get(k)}
        rows = [
            *((key, str(report.get(key, "-"))) for key in ("video", "gps", "map")),
            ("frames", fmt(report.get("frames"))),
            ("frames per second", fmt(report.get("fps"), ".2f")),
            ("frames decoded (the clips)", fmt(report.get("clip_frames"))),
        ]
        settings = [
            ("track", key, json.dumps(value))
            for key, value in (report.get("settings") or {}).items()
        ]
        return description_tables(
            rows,
            plugins,
            settings,
            report.get("timing") or {},
            report.get("versions") or {},
        )


@dataclass(frozen=True)
class TraversalsResult(MetricResult):
    """The traversals of a track run: ``sections`` holds ``traversals`` (their number) and, with
    ground truth, ``temporal`` (Zheng 5.4); the records, the frames' distance profile and the
    vicinity draw the table and the plots."""

    order: ClassVar[int] = 10
    records: tuple[Mapping[str, Any], ...] = ()
    frames: np.ndarray = field(default_factory=lambda: np.zeros(0), compare=False)
    distance: np.ndarray = field(default_factory=lambda: np.zeros(0), compare=False)
    vicinity: float = 30.0

    @property
    def temporal(self) -> Mapping[str, Any] | None:
        return self.sections.get("temporal")

    def headline(self) -> list[Figure]:
        figures = [
            Figure("traversals", "traversals", self.sections.get("traversals"), about="count")
        ]
        t = self.temporal
        if t is not None:
            about = "Zheng 5.4 temporal accuracy of the true tracks (all / detected candidates)"
            figures += [
                Figure("temporal.temporal_accuracy", "acc.", t["temporal_accuracy"], about=about),
                Figure(
                    "temporal.detected_accuracy", "det. acc.", t["detected_accuracy"], about=about
                ),
            ]
        return figures

    def remarks(self) -> list[str]:
        t = self.temporal
        if t is None:
            return []
        return [
            f"{ACCURACY_NOTE}. Pooled: {fmt(t['temporal_accuracy'])} over {t['candidates']} "
            f"candidates, {fmt(t['detected_accuracy'])} over {t['detected']} detected; "
            f"{t['true_tracks']} true and {t['false_tracks']} false tracks."
        ]

    def tables(self) -> list[Table]:
        evaluations = self.temporal["per_traversal"] if self.temporal is not None else None
        columns, rows = summary_rows(self.records, evaluations)
        return [
            Table(
                "traversals",
                "Traversals",
                tuple(columns),
                tuple(tuple(r) for r in rows),
                "node: the intersection's map node; anchor: the frame closest to it; short "
                "range: the frames of the first pass (Zheng 3.4.4); tracks: those kept.",
            )
        ]

    def plots(self) -> list[Plot]:
        plots = []
        if self.frames.size:
            plots.append(
                Plot(
                    "vicinity.png",
                    "Distance from the vehicle to the nearest signalised intersection per frame "
                    f"(Zheng Figure 3-13), the {self.vicinity:g} m vicinity (red line), each "
                    "traversal's clip shaded and its anchor frame marked.",
                    lambda figure: draw_vicinity(
                        figure, self.frames, self.distance, self.vicinity, self.records
                    ),
                    (9.0, 3.2),
                )
            )
        for record in self.records:
            tracks = len(record["tracks"])
            plots.append(
                Plot(
                    f"traversal_{record['traversal']:03d}.png",
                    f"Traversal {record['traversal']}: one row per kept track, frames across; "
                    "a filled marker per detected candidate, a hollow one per candidate carried by "
                    "dense optical flow (DOF), coloured by state; the short range shaded, the "
                    "anchor frame dashed.",
                    functools.partial(draw_timeline, record=record),
                    (9.0, 1.2 + 0.45 * max(tracks, 1)),
                )
            )
        return plots


def is_track_report(report: Mapping[str, Any]) -> bool:
    """Whether ``report`` (a ``report.json``) is a ``tsrkit track VIDEO`` run's."""
    return "dataset" not in report and all(k in report for k in ("video", "gps", "map"))


def read_traversals(path: Path) -> list[dict[str, Any]]:
    """The records of a track run's ``traversals.jsonl``.

    Raises
    ------
    TsrkitError
        Missing file, or a line that is not a traversal record (naming the line).
    """
    if not path.exists():
        raise TsrkitError(f"{path.parent}: not a track run folder ({path.name} missing)")
    lines = read_text(path).splitlines()  # InputFileError: one line naming the file
    records = []
    for number, line in enumerate(lines, 1):
        if not line.strip():
            continue
        record = loads_json(line, f"{path}: line {number}")
        missing = [k for k in TRAVERSAL_FIELDS if not isinstance(record, dict) or k not in record]
        tracks = record.get("tracks") if isinstance(record, dict) else None
        if missing or not isinstance(tracks, list) or not all(isinstance(t, dict) for t in tracks):
            problem = f"missing {', '.join(missing)}" if missing else "no list of tracks"
            raise TsrkitError(f"{path}: line {number}: not a traversal record ({problem})")
        records.append(record)
    return records


def load_track_run(folder: Path, report: dict[str, Any]) -> RunResult:
    """The :class:`RunResult` of a ``tsrkit track VIDEO`` folder, from its ``report.json`` and
    ``traversals.jsonl``, to be written again by the report writers.

    The vicinity plot's profile is computed again from the GPS log and the map the report
    names; when they cannot be read any more (moved, edited), that plot is left out and the
    rest of the report is written.

    Raises
    ------
    TsrkitError
        A ``traversals.jsonl`` or ``report.json`` that is not what a track run writes.
    """
    records = read_traversals(folder / "traversals.jsonl")
    try:
        settings = report["settings"]
        vicinity = float(settings["vicinity"])
        fps, count = float(report["fps"]), int(report["frames"])
    except (KeyError, TypeError, ValueError) as exc:
        raise TsrkitError(f"{folder / 'report.json'}: not a track report ({exc!r})") from None
    start = report.get("start_utc", records[0].get("start_utc") if records else None)
    frames, distance = _profile(report, start, fps, count)
    counted: dict[str, Any] = {k: report[k] for k in ("traversals", "temporal") if k in report}
    traversals = TraversalsResult(counted, "traversals", tuple(records), frames, distance, vicinity)
    return RunResult(dict(report), results=(TrackFacts(report, "run"), traversals))


def _profile(
    report: Mapping[str, Any], start: Any, fps: float, count: int
) -> tuple[np.ndarray, np.ndarray]:
    """The run's vicinity profile from the GPS log and map it names; empty when they cannot be
    read again."""
    # pyproj and the map reader: only when a run is reloaded with its map
    from tsrkit.geo import read_signals, read_track
    from tsrkit.spatiotemporal.ranges import frame_profile

    empty = (np.zeros(0, int), np.zeros(0))
    if not isinstance(start, (int, float)):
        return empty
    try:
        track = read_track(str(report["gps"]))
        signals = read_signals(str(report["map"]))
    except (TsrkitError, OSError, ValueError):
        return empty
    return frame_profile(track, signals, float(start), fps, count)
