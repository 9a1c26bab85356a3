"""``tsrkit track``: the traversals of a GPS track through the signalised intersections of a map
(Zheng 2016, 3.4.2-3.4.3) and, given the drive's video, the tracked signal states of each
traversal (3.4.4-3.4.5), evaluated against ground truth when given (5.4)."""

from __future__ import annotations

import contextlib
import json
import time
from datetime import UTC, datetime
from pathlib import Path

import click
from rich.console import Console
from rich.table import Table

from tsrkit.cli.common import FiniteFloatRange, plugin_options
from tsrkit.cli.errors import UserError
from tsrkit.core.atomic import atomic_open, json_line
from tsrkit.core.files import not_regular
from tsrkit.core.outputs import reading, refuse_input
from tsrkit.geo.gps import EARLIEST, LATEST
from tsrkit.runner.outlock import locked

__all__ = ["track_command"]


def _utc(seconds: float) -> str:
    return datetime.fromtimestamp(seconds, UTC).strftime("%Y-%m-%d %H:%M:%S")


def _start_time(text: str | None) -> float | None:
    """UTC seconds from epoch seconds or ISO 8601 (``Z`` or an offset; naive means UTC)."""
    if text is None:
        return None
    try:
        seconds = float(text)
    except ValueError:
        try:
            stamp = datetime.fromisoformat(text.replace("Z", "+00:00"))
        except ValueError:
            raise click.BadParameter(
                f"'{text}' is neither epoch seconds nor ISO 8601", param_hint="--start-utc"
            ) from None
        seconds = (stamp if stamp.tzinfo else stamp.replace(tzinfo=UTC)).timestamp()
    if not EARLIEST <= seconds <= LATEST:  # NaN fails too
        raise click.BadParameter(
            f"'{text}' is not a time in the years 1970-9999", param_hint="--start-utc"
        )
    return seconds


def _write_jsonl(path: Path, records) -> None:
    with atomic_open(path) as fh:
        for record in records:
            fh.write(json_line(record) + "\n")


@click.command("track")
@click.argument("video", required=False, type=click.Path(dir_okay=False))
@click.option(
    "--gps",
    "gps",
    required=True,
    type=click.Path(dir_okay=False),
    help="GPS log: CSV with a time,lat,lon header, 'dd-Mon-yyyy hh:mm:ss lat lon' lines, GPX "
    "(.gpx) or NMEA 0183 (.nmea: RMC and GGA sentences); by extension, else by content.",
)
@click.option(
    "--map",
    "osm",
    required=True,
    type=click.Path(dir_okay=False),
    help="Signal map: OpenStreetMap XML (.osm, .osm.gz), an .osm.pbf extract (needs "
    "pyosmium) or GeoJSON signal points (.geojson, .json); by extension.",
)
@click.option(
    "--vicinity",
    type=FiniteFloatRange(min=1.0, max=1000.0),
    default=30.0,
    show_default=True,
    help="Distance (m) within which a fix is near an intersection (Zheng's Figure 3-13: 50).",
)
@plugin_options
@click.option(
    "--start-utc",
    default=None,
    help="UTC time of the video's first frame (epoch seconds or ISO 8601); "
    "default the first GPS fix.",
)
@click.option(
    "--upstream",
    type=FiniteFloatRange(min=0.0, max=1000.0),
    default=10.0,
    show_default=True,
    help="Short range: trajectory metres before the anchor frame (3.4.4).",
)
@click.option(
    "--downstream",
    type=FiniteFloatRange(min=0.0, max=1000.0),
    default=5.0,
    show_default=True,
    help="Short range: trajectory metres after the anchor frame (3.4.4).",
)
@click.option(
    "--top",
    type=click.IntRange(min=1),
    default=5,
    show_default=True,
    help="Tracks kept after the first pass, by stability (3.4.4).",
)
@click.option(
    "--roi-top",
    type=FiniteFloatRange(min=0.05, max=1.0),
    default=0.6,
    show_default=True,
    help="Share of the frame's height searched by whole-frame detection (Zheng 5.4: 0.6).",
)
@click.option(
    "--slack",
    type=FiniteFloatRange(min=0.0, max=3.0),
    default=0.0,
    show_default=True,
    help="Tolerance (radii) across a head's axis for colour changes in Eq. 3.37 (paper: 0).",
)
@click.option(
    "--flow-margin",
    type=click.IntRange(min=0),
    default=0,
    show_default=True,
    help="Farneback flow in a window this many pixels around a candidate; 0: whole frames "
    "(accurate under fast motion, slower).",
)
@click.option(
    "--truth",
    type=click.Path(dir_okay=False),
    default=None,
    help="Per-frame ground truth (JSON Lines of lights) for Zheng 5.4's temporal accuracy.",
)
@click.option("--quiet", "-q", is_flag=True, help="No progress bar.")
@click.option(
    "--out",
    "-o",
    type=click.Path(file_okay=False),
    default=None,
    help="Folder for traversals.jsonl (and, with VIDEO, timelines.csv, events.csv, "
    "report.json / .md, plots/, cache/).",
)
def track_command(
    video,
    gps,
    osm,
    vicinity,
    detector,
    verifier,
    classifier,
    tracker,
    params,
    config,
    start_utc,
    upstream,
    downstream,
    top,
    roi_top,
    slack,
    flow_margin,
    truth,
    quiet,
    out,
) -> None:
    """List the traversals of the GPS track through the map's signalised intersections; with
    VIDEO, recognise the signal states of each traversal on its clip (Zheng 2016, 3.4).

    \b
    Examples:
      tsrkit track --gps drive.txt --map city.osm.gz --out runs/drive
      tsrkit track drive.mp4 --gps gps.csv --map map.osm --out runs/drive
      tsrkit track drive.mp4 --gps gps.csv --map map.osm -d conspicuity -c ab-hist \\
          -p h_peak=0.8 --vicinity 50 --truth truth.jsonl --out runs/drive
    """
    # pyproj, SciPy and the plugins: only when the verb runs
    from tsrkit.geo import read_signals, read_track, traversals

    if video is None:
        given = video_options_given(click.get_current_context())
        if given:
            raise click.UsageError(
                f"{', '.join(given)}: need a VIDEO (without one, track lists the traversals)"
            )
    with reading([video, gps, osm, truth]):
        if out is not None:
            refuse_input(out, "--out")
    for given in (video, truth):
        problem = not_regular(given) if given is not None else None
        if problem:
            raise UserError(f"{given}: {problem}")
    track = read_track(gps)
    signals = read_signals(osm)
    if len(track) < 2:  # one fix has no direction: no movement through an intersection
        raise UserError(f"{gps}: one GPS fix only; a track needs at least two GPS fixes")
    console = Console()
    if video is not None:
        # pyproj, SciPy and the plugins: only when the verb runs
        from tsrkit.spatiotemporal.run import TrackSettings

        settings = TrackSettings(vicinity, upstream, downstream, top, slack, flow_margin, roi_top)
        _track_video(
            video,
            track,
            signals,
            settings,
            (detector, verifier, classifier, tracker, params, config),
            _start_time(start_utc),
            truth,
            quiet,
            Path(out) if out else None,
            console,
        )
        return
    no_signals(signals, osm)
    found = traversals(track, signals, vicinity)
    table = Table(
        title=f"{len(found)} traversals of {len(signals)} intersections ({len(track)} fixes)"
    )
    for column in ("intersection", "lat, lon", "entry (UTC)", "exit", "closest m", "movement"):
        table.add_column(column)
    for t in found:
        table.add_row(
            str(t.intersection),
            f"{signals.lat[t.intersection]:.5f}, {signals.lon[t.intersection]:.5f}",
            _utc(t.entry),
            _utc(t.exit)[11:],
            f"{t.closest_m:.1f}",
            t.movement,
        )
    console.print(table)
    for start, end in track.gaps():
        console.print(f"GPS gap: {_utc(start)} - {_utc(end)[11:]} (not bridged)", markup=False)
    if out:
        path = Path(out) / "traversals.jsonl"
        with locked(out):
            _write_jsonl(path, (t.to_json(signals) for t in found))
        console.print(f"-> {path}")


def _track_video(
    video, track, signals, settings, plugins, start_utc, truth, quiet, out, console
) -> None:
    """The video mode of ``tsrkit track`` (see :func:`tsrkit.spatiotemporal.track_video`)."""
    # pyproj, SciPy and the plugins: only when the verb runs
    from tsrkit.plugin.selection import build
    from tsrkit.reporting.report import ProgressBar, versions
    from tsrkit.reporting.runfolder import write_track_run
    from tsrkit.spatiotemporal.evaluate import evaluate_traversal, read_truth, temporal_section
    from tsrkit.spatiotemporal.ranges import frame_profile, frame_traversals
    from tsrkit.spatiotemporal.run import identity, track_video, video_facts
    from tsrkit.spatiotemporal.study import write_study

    selection = build(*plugins)
    truth_frames = read_truth(truth) if truth else None
    fps, count = video_facts(video)
    no_signals(signals, signals.source)
    start = float(track.time[0]) if start_utc is None else start_utc
    if start > track.time[-1] or start + count / max(fps, 1e-9) < track.time[0]:
        raise UserError(
            f"--start-utc {_utc(start)}: the video's {count} frames lie outside the GPS log "
            f"({_utc(float(track.time[0]))} - {_utc(float(track.time[-1]))[11:]})"
        )
    found = frame_traversals(
        track,
        signals,
        start,
        fps,
        count,
        settings.vicinity,
        settings.upstream,
        settings.downstream,
    )
    total = sum(f.last - f.first + 1 for f in found)
    records, began = [], time.perf_counter()
    lock = locked(out) if out is not None else contextlib.nullcontext()
    with lock, ProgressBar(total, not quiet, "track") as bar:
        for record in track_video(
            video,
            track,
            signals,
            selection,
            settings,
            start,
            out / "cache" if out is not None else None,
            bar.advance,
        ):
            records.append(record)
        elapsed = time.perf_counter() - began
        evaluations = (
            [evaluate_traversal(r, truth_frames) for r in records] if truth_frames else None
        )
        if out is not None:
            _write_jsonl(out / "traversals.jsonl", records)
            report = {
                "video": str(video),
                "gps": track.source,
                "map": signals.source,
                "frames": count,
                "fps": fps,
                "start_utc": start,
                "clip_frames": total,
                "traversals": len(records),
                **json.loads(identity(selection, settings)),
                "timing": {
                    "seconds": round(elapsed, 3),
                    "clip_frames_per_second": round(total / elapsed, 2) if elapsed else None,
                    "video_frames_per_second": round(count / elapsed, 2) if elapsed else None,
                    "cached_traversals": sum(bool(r.get("cached")) for r in records),
                },
                "versions": versions(),
            }
            if evaluations is not None:
                report["temporal"] = temporal_section(evaluations)
            profile = frame_profile(track, signals, start, fps, count)
            written = write_track_run(out, report, records, profile, settings.vicinity).report
            write_study(out, records, track, signals, video)
    _print_traversals(console, records, evaluations, count, total, elapsed)
    if out is not None:
        for note in written.get("notes", []):
            console.print(f"note: {note}", markup=False)
        shown = ", ".join(["traversals.jsonl", "timelines.csv", "events.csv", *written["files"]])
        console.print(f"-> {out}: {shown}, plots/", markup=False)


#: The options that act on the video's frames only.
VIDEO_ONLY = (
    "detector",
    "verifier",
    "classifier",
    "tracker",
    "params",
    "config",
    "start_utc",
    "upstream",
    "downstream",
    "top",
    "roi_top",
    "slack",
    "flow_margin",
    "truth",
)


def video_options_given(ctx: click.Context) -> list[str]:
    """The video-only options the command line (or the environment) set, by their long name:
    without a VIDEO they would be ignored without a word."""
    flags = {p.name: p.opts[-1] for p in ctx.command.params}
    return [
        flags[name]
        for name in VIDEO_ONLY
        if ctx.get_parameter_source(name) not in (None, click.core.ParameterSource.DEFAULT)
    ]


def no_signals(signals, osm) -> None:
    """Refuse a map without a signalised intersection: every run on it finds nothing."""
    if not len(signals):
        raise UserError(f"{osm}: no traffic signal (highway=traffic_signals node) in the map")


def _print_traversals(console, records, evaluations, frames, clip_frames, elapsed) -> None:
    # the report's tables: only when the verb runs (``tsrkit --help`` stays fast)
    from tsrkit.reporting.track import ACCURACY_NOTE, summary_rows

    table = Table(
        title=f"{len(records)} traversals; {clip_frames} of {frames} frames decoded "
        f"({elapsed:.1f} s)",
        caption=ACCURACY_NOTE if evaluations is not None else None,
    )
    columns, rows = summary_rows(records, evaluations)
    for column in columns:
        table.add_column(column, no_wrap=True)
    for row in rows:
        table.add_row(*row)
    console.print(table)
