"""``tsrkit detect``: run a detector (and classifier, tracker) over images, folders or videos."""

from __future__ import annotations

import contextlib
import json
import os
import sys
from collections.abc import Iterator
from contextlib import nullcontext
from pathlib import Path
from typing import Literal, NamedTuple, TextIO

import click
import cv2
from rich.console import Console

from tsrkit.cli.common import plugin_options
from tsrkit.cli.errors import UserError
from tsrkit.core.atomic import atomic_open, json_line
from tsrkit.core.errors import TsrkitError
from tsrkit.core.outputs import reading, refuse_input, refuse_special, writing
from tsrkit.core.records import FrameRecord
from tsrkit.core.types import Frame, Skipped
from tsrkit.plugin.selection import build
from tsrkit.reporting.draw import draw_detections
from tsrkit.reporting.report import ProgressBar
from tsrkit.runner.agreement import Agreement
from tsrkit.runner.follow import Follower
from tsrkit.runner.inputs import IMAGE_EXTENSIONS, VIDEO_EXTENSIONS, check_range
from tsrkit.runner.outlock import locked_file
from tsrkit.runner.streams import Runner, run_pipeline
from tsrkit.runner.workers import check_workers

__all__ = [
    "Resumed",
    "default_inputs",
    "detect_command",
    "flushed_output",
    "read_partial",
    "run_detect",
]


class Resumed(NamedTuple):
    """What the ``OUT.partial`` of an aborted run holds (``detect --resume``)."""

    #: Each input's last frame done (0 for an image).
    done: dict[str, int]
    #: Frames and detections written.
    frames: int
    detections: int


def read_partial(partial: Path) -> Resumed:
    """The frames an aborted run wrote to ``partial``, which is cut after its last whole record
    (a run killed while writing a line leaves half of one).

    Raises
    ------
    UserError
        When ``partial`` cannot be read.
    """
    done: dict[str, int] = {}
    frames = detections = kept = 0
    try:
        with open(partial, "r+b") as fh:
            for line in fh:
                try:
                    record = FrameRecord.from_json(json.loads(line))
                except (ValueError, KeyError, TypeError):
                    break
                if not line.endswith(b"\n"):
                    break
                done[record.source] = record.index
                frames += 1
                detections += len(record.detections)
                kept += len(line)
            fh.truncate(kept)
    except OSError as exc:
        raise UserError(f"{partial}: cannot resume from it: {exc.strerror or exc}") from None
    return Resumed(done, frames, detections)


def run_detect(
    pipeline: Runner,
    paths,
    out,
    draw: Path | None = None,
    every: int = 1,
    start: int = 0,
    end: int | None = None,
    workers: int = 1,
    progress: bool = False,
    agree: int = 1,
    resumed: Resumed | None = None,
) -> tuple[int, int, list[Skipped]]:
    """Write one JSON Lines record per frame to the text stream ``out``, in input order.

    A frame on which a plugin crashes is reported as skipped and the run goes on; a
    :class:`TsrkitError` from a plugin (a setup problem such as a mismatched model) stops it.
    ``workers`` > 1 runs the pipeline in worker processes
    (:func:`tsrkit.runner.streams.run_pipeline`);
    overlays (``draw``) need the frames here, so they need one worker. ``progress`` shows a
    progress bar (frames done, frames/s) on stderr. ``agree`` > 1 keeps only the detections
    whose light is found on that many consecutive video frames
    (:class:`tsrkit.runner.agreement.Agreement`; still images keep every detection).
    ``resumed``: the frames an aborted run already wrote, which are not run again (and are
    counted in the totals).

    Returns
    -------
    frames, detections, skipped
    """
    if draw is not None and workers > 1:
        raise TsrkitError("--draw needs the frames in this process: use it with --workers 1")
    done, frames, detections = resumed or Resumed({}, 0, 0)
    skipped: list[Skipped] = []
    stream = run_pipeline(
        pipeline, paths, every=every, start=start, end=end, workers=workers, done=done
    )
    if agree > 1:
        stream = Agreement(agree).filter(stream)
    with ProgressBar(None, progress, "detect") as bar:  # type: ignore[arg-type]
        for result, frame in bar.track(stream):
            if isinstance(result, Skipped):
                skipped.append(result)
                continue
            out.write(json_line(result.to_record()) + "\n")
            frames += 1
            detections += len(result.detections)
            if draw is not None and frame is not None:
                _write_overlay(draw, frame, frames, result.detections)
    return frames, detections, skipped


@contextlib.contextmanager
def flushed_output(out: Path, resume: bool = False) -> Iterator[TextIO]:
    """Write ``OUT.partial`` one flushed line per frame, renamed to ``OUT`` when the run ends.

    A run that aborts (an error, Ctrl-C) keeps ``OUT.partial`` with every frame done so far and
    says so; ``OUT`` itself is only ever a complete run's output. ``resume`` appends to an
    existing ``OUT.partial`` instead of starting it anew.
    """
    partial = out.with_name(out.name + ".partial")
    partial.parent.mkdir(parents=True, exist_ok=True)
    mode: Literal["a", "w"] = "a" if resume else "w"
    with open(partial, mode, encoding="utf-8", buffering=1) as fh:  # line-buffered: flushed
        try:
            yield fh
        except BaseException:
            fh.flush()
            click.echo(f"aborted: the frames done so far are in {partial}", err=True)
            raise
    os.replace(partial, out)


def _write_overlay(folder: Path, frame: Frame, number: int, detections) -> None:
    name = f"{number:06d}_{Path(frame.source).stem}"
    if frame.index:
        name += f"_f{frame.index:06d}"
    ok, encoded = cv2.imencode(".png", draw_detections(frame.image, detections))
    if ok:
        with atomic_open(folder / f"{name}.png", "wb") as fh:
            fh.write(encoded.tobytes())


def printable(text: str) -> str:
    """``text`` with control characters escaped, so that a skipped file's line stays one line.

    Examples
    --------
    >>> printable("a\\nb.png")
    'a\\\\nb.png'
    """
    return "".join(c if c.isprintable() else repr(c)[1:-1] for c in text)


def default_inputs() -> list[str]:
    """The bundled synthetic sample's images (generated on first use)."""
    # cv2 and NumPy of the renderer: only when no input is given
    from tsrkit.synth import sample_path

    return [str(sample_path().parent / "images")]


@click.command("detect")
@click.argument("paths", nargs=-1, type=click.Path())
@plugin_options
@click.option(
    "--out",
    "-o",
    type=click.Path(dir_okay=False, path_type=Path),
    default=None,
    help="JSON Lines output file; default stdout. Written as OUT.partial, one line per frame "
    "as it completes, and renamed to OUT at the end (an aborted run keeps OUT.partial).",
)
@click.option(
    "--resume",
    is_flag=True,
    help="Go on with the OUT.partial an aborted run left (same PATHS and options): its frames "
    "are kept and not run again. Not with a tracker, --key-every or --agree, which carry "
    "lights from frame to frame.",
)
@click.option(
    "--draw",
    type=click.Path(file_okay=False),
    default=None,
    help="Folder for overlay images coloured by state.",
)
@click.option("--every", type=click.IntRange(min=1), default=1, help="Keep every N-th frame.")
@click.option("--start", type=click.IntRange(min=0), default=0, help="First video frame.")
@click.option("--end", type=click.IntRange(min=0), default=None, help="Video frame to stop before.")
@click.option(
    "--workers",
    "-w",
    type=click.IntRange(min=1),
    default=1,
    help="Worker processes; each decodes its own images or 64-frame video chunks.",
)
@click.option(
    "--key-every",
    type=click.IntRange(min=1),
    default=1,
    show_default=True,
    help="Videos: the whole pipeline on every K-th kept frame only; in between, the same "
    "detector and verifier in a window around each light of the frame before (a light "
    "appearing meanwhile is found at most K-1 frames late). 1: the whole pipeline on every "
    "frame.",
)
@click.option(
    "--agree",
    type=click.IntRange(min=1),
    default=1,
    show_default=True,
    help="Videos: report a detection only when its light is found on at least N consecutive "
    "frames (from its first frame on; the output lags up to N-1 frames). 1: every detection. "
    "Still images have no next frame: their detections are all reported.",
)
@click.option(
    "--quiet",
    "-q",
    is_flag=True,
    help="No progress bar (there is none when stderr is not a terminal).",
)
def detect_command(
    paths,
    detector,
    verifier,
    classifier,
    tracker,
    params,
    config,
    out,
    resume,
    draw,
    every,
    start,
    end,
    workers,
    key_every,
    agree,
    quiet,
) -> None:
    """Detect lit signal lenses in images, folders (recursive) or videos.

    Writes one JSON record per frame: source, frame, width, height, ms and detections (x, y,
    radius, bbox, score, state, state_scores). With no PATHS, runs on the bundled sample.
    Unreadable inputs are skipped with their reason; exit status 1 when every one was.

    \b
    Examples:
      tsrkit detect frames/ -o detections.jsonl
      tsrkit detect drive.mp4 -d lab-frst -c ab-hist -t meanshift --every 2 -o drive.jsonl
      tsrkit detect frames/ --config recommended --draw overlays/ -q
      tsrkit detect frames/ -d conspicuity -p weights=1,1,2 -w 2 -o d.jsonl
      tsrkit detect drive.mp4 --config recommended --agree 3 -w 2 -o drive.jsonl
    """
    if any(not str(p) for p in paths):
        raise UserError("an empty path was given (quote a real file or folder)")
    check_range(every, start, end)
    check_workers(workers)
    inputs = list(paths) or default_inputs()
    draw_dir = Path(draw) if draw else None
    with reading(inputs):
        for given, option in ((out, "--out"), (draw_dir, "--draw")):
            if given is not None:
                refuse_input(given, option)
                refuse_special(given, option)
        if out is not None and out.suffix.lower() in IMAGE_EXTENSIONS | VIDEO_EXTENSIONS:
            raise UserError(f"--out {out} names an image or video; detect writes JSON Lines")
        pipeline = build(detector, verifier, classifier, tracker, params, config).pipeline()
    if key_every > 1 and pipeline.tracker is not None:
        raise UserError("--key-every and --tracker both carry lights between frames: choose one")
    if resume and out is None:
        raise UserError("--resume goes on with OUT.partial: it needs --out OUT")
    if resume and (pipeline.tracker is not None or key_every > 1 or agree > 1):
        raise UserError(
            "--resume: a tracker, --key-every and --agree carry lights from frame to frame, "
            "so a resumed run would differ; run again without --resume"
        )
    runner = Follower(pipeline, key_every) if key_every > 1 else pipeline
    if draw_dir is not None:
        draw_dir.mkdir(parents=True, exist_ok=True)
    progress = not quiet and Console(stderr=True).is_terminal  # no bar in redirected logs
    partial = out.with_name(out.name + ".partial") if out else None
    lock = locked_file(out) if out else nullcontext()
    console = Console(stderr=True, soft_wrap=True)  # one line per skipped input, never wrapped
    with lock, writing([out, partial, draw_dir]):
        resumed = None
        if resume and partial is not None and partial.is_file():
            resumed = read_partial(partial)
            console.print(f"resuming after the {resumed.frames} frames in {partial}", markup=False)
        elif resume:
            console.print(f"no {partial} to resume: starting at the first frame", markup=False)
        sink = flushed_output(out, resumed is not None) if out else nullcontext(sys.stdout)
        with sink as stream:
            frames, found, skipped = run_detect(
                runner,
                inputs,
                stream,
                draw_dir,
                every,
                start,
                end,
                workers,
                progress,
                agree,
                resumed,
            )
    console.print(
        f"[bold]{frames}[/bold] frames, [bold]{found}[/bold] detections, "
        f"[bold]{len(skipped)}[/bold] skipped" + (f" -> {out}" if out else "")
    )
    for item in skipped:
        console.print(f"  skipped {printable(item.source)}: {item.reason}", markup=False)
    if frames == 0 and skipped:
        console.print(f"error: all {len(skipped)} inputs were skipped", markup=False)
        raise SystemExit(1)
    if frames == 0:
        console.print(f"error: no input found in {', '.join(inputs)}", markup=False)
        raise SystemExit(1)
