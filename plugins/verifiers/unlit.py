"""Synthetic road scenes in which no traffic light is lit: the verifier's negatives, and the
backgrounds of its pasted head crops (:mod:`pasting`)."""

from __future__ import annotations

from collections.abc import Iterator, Sequence

from tsrkit.api import Frame, SynthOptions, render_frame

#: Frame size of the synthetic no-light frames (a dash-cam's).
SYNTH_SIZE = (1280, 720)
SYNTH_SEED = 1011


def no_light_frames(
    count: int,
    seed: int = SYNTH_SEED,
    lighting: Sequence[str] | None = None,
    name: str = "synth-no-light",
) -> Iterator[Frame]:
    """``count`` synthetic 1280x720 road scenes in which no light is lit.

    Housings are drawn dark (``off_fraction`` near 1); a scene that still drew a lit light is
    skipped, so the frames are a deterministic function of ``count``, ``seed`` and
    ``lighting`` (the conditions drawn from, e.g. ``("day",)``; None: every one). Each frame's
    source is ``name:seed:index``.
    """
    options = SynthOptions(off_fraction=0.999)
    if lighting is not None:
        options = SynthOptions(lighting=tuple(lighting), off_fraction=0.999)
    index = 0
    made = 0
    while made < count:
        image, annotations, condition = render_frame(index, seed, *SYNTH_SIZE, options)
        index += 1
        if annotations:
            continue
        made += 1
        yield Frame(image, f"{name}:{seed}:{index - 1}", metadata={"lighting": condition})
