"""``tsrkit track``: the traversals of a GPS track through the signalised intersections of a map
(Zheng 2016, 3.4.2-3.4.3); the video stages of the framework are not built yet."""

from __future__ import annotations

import json
from datetime import UTC, datetime
from pathlib import Path

import click
from rich.console import Console
from rich.table import Table

from tsrkit.atomic import atomic_open


def _utc(seconds: float) -> str:
    return datetime.fromtimestamp(seconds, UTC).strftime("%Y-%m-%d %H:%M:%S")


@click.command("track")
@click.option(
    "--gps",
    "gps",
    required=True,
    type=click.Path(dir_okay=False),
    help="GPS log (CSV time,lat,lon or 'dd-Mon-yyyy hh:mm:ss lat lon' lines).",
)
@click.option(
    "--map",
    "osm",
    required=True,
    type=click.Path(dir_okay=False),
    help="OpenStreetMap extract (.osm or .osm.gz).",
)
@click.option(
    "--vicinity",
    type=click.FloatRange(min=1.0, max=1000.0),
    default=30.0,
    show_default=True,
    help="Distance (m) within which a fix is near an intersection.",
)
@click.option(
    "--out",
    "-o",
    type=click.Path(file_okay=False),
    default=None,
    help="Folder for traversals.jsonl.",
)
def track_command(gps, osm, vicinity, out) -> None:
    """List the traversals of the GPS track through the map's signalised intersections.

    Example: tsrkit track --gps drive.txt --map city.osm.gz --out runs/drive
    """
    from tsrkit.geo import read_signals, read_track, traversals

    track = read_track(gps)
    signals = read_signals(osm)
    found = traversals(track, signals, vicinity)
    console = Console()
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
        path.parent.mkdir(parents=True, exist_ok=True)
        with atomic_open(path) as fh:
            for t in found:
                fh.write(json.dumps(t.to_json(signals)) + "\n")
        console.print(f"-> {path}")
