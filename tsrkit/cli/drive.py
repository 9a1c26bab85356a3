"""``tsrkit datasets drive``: render a synthetic test drive (video, GPS log, map, ground truth)
for ``tsrkit track`` and the tracker, with :func:`tsrkit.synth.drive.render_drive`."""

from __future__ import annotations

import json
from pathlib import Path

import click

from tsrkit.cli.common import FiniteFloatRange
from tsrkit.core.errors import TsrkitError
from tsrkit.synth.drive import MOVEMENTS

__all__ = ["drive_command"]


@click.command("drive")
@click.option(
    "--out",
    required=True,
    type=click.Path(file_okay=False, path_type=Path),
    help="Output folder: drive.mp4, gps.csv, map.osm, truth.jsonl, drive.json, "
    "truth_timelines.csv, truth_events.csv.",
)
@click.option(
    "--route",
    default="left",
    show_default=True,
    help=f"Comma-separated movement at each signalised intersection ({', '.join(MOVEMENTS)}).",
)
@click.option("--width", default=480, show_default=True, type=click.IntRange(64, 4096))
@click.option("--height", default=356, show_default=True, type=click.IntRange(48, 4096))
@click.option(
    "--fps", default=14.0, show_default=True, type=FiniteFloatRange(1, 120), help="Frames/s."
)
@click.option("--seed", default=0, show_default=True, type=click.IntRange(min=0), help="Seed.")
@click.option(
    "--green", default=10.0, show_default=True, type=FiniteFloatRange(0.5, 600), help="Green s."
)
@click.option(
    "--yellow", default=3.0, show_default=True, type=FiniteFloatRange(0.5, 60), help="Amber s."
)
@click.option(
    "--all-red",
    default=0.0,
    show_default=True,
    type=FiniteFloatRange(0, 60),
    help="All-red clearance s after each amber.",
)
@click.option(
    "--run-share",
    default=0.0,
    show_default=True,
    type=FiniteFloatRange(0, 1),
    help="Share of traversals where the driver ignores the signal (goes through amber or red).",
)
def drive_command(
    out: Path,
    route: str,
    width: int,
    height: int,
    fps: float,
    seed: int,
    green: float,
    yellow: float,
    all_red: float,
    run_share: float,
) -> None:
    """Render a drive through signalised intersections: the dash-cam video, its 1 Hz GPS log
    (CSV), an OpenStreetMap extract of the signals and the per-frame truth.

    \b
    Examples:
      tsrkit datasets drive --out city/
      tsrkit track city/drive.mp4 --gps city/gps.csv --map city/map.osm --out runs/city
      tsrkit datasets drive --out town/ --route through,left,right --width 640 --height 480
      tsrkit datasets drive --out amber/ --route through,through --yellow 4 --all-red 1 \\
          --run-share 0.5
    """
    # pyproj and the renderer: only when the verb runs
    from tsrkit.runner.outlock import locked
    from tsrkit.synth.drive import DriveOptions, render_drive

    moves = tuple(m.strip() for m in route.split(",") if m.strip())
    try:
        options = DriveOptions(
            width=width,
            height=height,
            fps=fps,
            route=moves,
            green_s=green,
            yellow_s=yellow,
            all_red_s=all_red,
            run_share=run_share,
        )
    except ValueError as exc:
        raise TsrkitError(f"--route/--width/--height: {exc}") from None
    with locked(out):
        folder = render_drive(out, options, seed)
    frames = json.loads((folder / "drive.json").read_text(encoding="utf-8"))["frames"]
    click.echo(
        f"wrote {frames} frames ({frames / fps:.1f} s) through {len(moves)} signalised "
        f"intersections to {folder}: drive.mp4, gps.csv, map.osm, truth.jsonl, "
        "truth_timelines.csv, truth_events.csv"
    )
