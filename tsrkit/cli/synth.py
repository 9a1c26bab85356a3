"""``tsrkit datasets synth``: render a deterministic synthetic dataset (images + COCO + JSON)."""

from __future__ import annotations

from collections import Counter
from pathlib import Path

import click
from rich.console import Console

from tsrkit.core.errors import TsrkitError
from tsrkit.core.outputs import refuse_special
from tsrkit.runner.outlock import locked_file
from tsrkit.synth import LIGHTINGS, generate

__all__ = ["synth_command"]


@click.command("synth")
@click.option(
    "--out",
    required=True,
    type=click.Path(file_okay=False, path_type=Path),
    help="Output folder (images/, annotations.json, coco.json).",
)
@click.option(
    "--frames",
    default=48,
    show_default=True,
    type=click.IntRange(1, 1_000_000),
    help="Number of frames.",
)
@click.option(
    "--seed", default=0, show_default=True, type=click.IntRange(min=0), help="Scene seed."
)
@click.option("--width", default=480, show_default=True, type=click.IntRange(64, 8192))
@click.option("--height", default=356, show_default=True, type=click.IntRange(64, 8192))
@click.option(
    "--lighting",
    default=",".join(LIGHTINGS),
    show_default=True,
    help="Comma-separated lighting conditions, assigned to frames in turn.",
)
@click.option("--overwrite", is_flag=True, help="Replace an existing folder with other data.")
@click.option(
    "--video",
    default=None,
    type=click.Path(dir_okay=False, path_type=Path),
    help="Also write the frames, in order, as an MPEG-4 video (10 frames/s).",
)
@click.option("--quiet", "-q", is_flag=True, help="No progress indicator.")
def synth_command(
    out: Path,
    frames: int,
    seed: int,
    width: int,
    height: int,
    lighting: str,
    overwrite: bool,
    video: Path | None,
    quiet: bool,
) -> None:
    """Render FRAMES road scenes with lit signal lenses of known centre, radius and state.

    Same arguments give byte-identical files. Frames alternate day / dusk / night (or the
    --lighting list) and are split 50/50 into train and test.

    \b
    Examples:
      tsrkit datasets synth --out synth/ --frames 200 --seed 3
      tsrkit datasets synth --out night/ --lighting night --width 1280 --height 720
      tsrkit datasets synth --out clip/ --frames 60 --video clip.mp4
    """
    conditions = tuple(c.strip() for c in lighting.split(",") if c.strip())
    # when the verb runs: ``tsrkit --help`` stays fast
    from tsrkit.reporting.report import ProgressBar

    if video is not None:
        refuse_special(video, "--video")

    try:
        with (
            locked_file(out),
            ProgressBar(frames, not quiet and Console(stderr=True).is_terminal, "synth") as bar,
        ):
            dataset = generate(
                out, frames, seed, width, height, overwrite=overwrite, lighting=conditions,
                on_frame=bar.advance,
            )  # fmt: skip
    except ValueError as exc:  # bad option values: one line, like every TsrkitError
        raise TsrkitError(str(exc)) from None
    states = Counter(a.state for s in dataset for a in s.annotations)
    click.echo(
        f"wrote {len(dataset)} frames, {sum(states.values())} lit lenses "
        f"({', '.join(f'{k} {v}' for k, v in sorted(states.items()))}) to {out}"
    )
    if video is not None:
        # when the verb runs: ``tsrkit --help`` stays fast
        from tsrkit.synth.video import write_video

        click.echo(f"video: {write_video(dataset, video)}")
