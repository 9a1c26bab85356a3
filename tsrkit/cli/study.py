"""``tsrkit study MANIFEST``: ``tsrkit track`` on every drive of a manifest, resumable, and the
combined timelines, events and traversals (:mod:`tsrkit.spatiotemporal.manifest`)."""

from __future__ import annotations

from pathlib import Path

import click

from tsrkit.cli.common import FiniteFloatRange, plugin_options

__all__ = ["study_command"]


@click.command("study")
@click.argument("manifest", type=click.Path(dir_okay=False))
@click.option(
    "--out",
    "-o",
    required=True,
    type=click.Path(file_okay=False),
    help="Folder: drives/NAME/ per drive, and the combined timelines.csv, events.csv, "
    "traversals.geojson.",
)
@click.option(
    "--vicinity",
    type=FiniteFloatRange(min=1.0, max=1000.0),
    default=30.0,
    show_default=True,
    help="Distance (m) within which a fix is near an intersection (as tsrkit track).",
)
@plugin_options
@click.option("--quiet", "-q", is_flag=True, help="No progress bars.")
@click.pass_context
def study_command(
    ctx, manifest, out, vicinity, detector, verifier, classifier, tracker, params, config, quiet
) -> None:
    """Run `tsrkit track VIDEO --gps LOG --map MAP` on every drive of MANIFEST (CSV or YAML:
    video, gps, map, optional name and start_utc) into OUT/drives/NAME/, skipping drives
    finished before (a killed study resumes), then write the combined timelines.csv and
    events.csv (a `drive` column first) and traversals.geojson into OUT.

    \b
    Examples:
      tsrkit study drives.csv --out runs/study -c ab-hist -p h_peak=0.8
      tsrkit study drives.yaml --out runs/study --vicinity 60
    """
    from tsrkit.cli.track import track_command
    from tsrkit.core.outputs import reading, refuse_input
    from tsrkit.spatiotemporal.manifest import combine, finished, mark_done, read_manifest

    entries = read_manifest(manifest)
    folder = Path(out)
    with reading([manifest, *(str(p) for e in entries for p in (e.video, e.gps, e.map))]):
        refuse_input(out, "--out")
    for number, entry in enumerate(entries, start=1):
        target = folder / "drives" / entry.name
        if finished(entry, target):
            click.echo(f"[{number}/{len(entries)}] {entry.name}: finished before, skipped")
            continue
        click.echo(f"[{number}/{len(entries)}] {entry.name}: tracking {entry.video}")
        ctx.invoke(
            track_command,
            video=str(entry.video),
            gps=str(entry.gps),
            osm=str(entry.map),
            vicinity=vicinity,
            detector=detector,
            verifier=verifier,
            classifier=classifier,
            tracker=tracker,
            params=params,
            config=config,
            start_utc=entry.start_utc,
            quiet=quiet,
            out=str(target),
        )
        mark_done(entry, target)
    counts = combine(folder, entries)
    click.echo(
        f"-> {folder}: timelines.csv ({counts['timelines']} intervals), events.csv "
        f"({counts['events']} events), traversals.geojson ({counts['traversals']} traversals)"
    )
