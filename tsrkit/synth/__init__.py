"""tsrkit's own synthetic data: road scenes rendered with exact labels, Sun-lit scenes, work
zones, drives along a GPS path and their video.

The day / dusk / night road scenes that make the bundled sample (:func:`sample_path`) and
``tsrkit datasets synth`` are rendered by :mod:`tsrkit.datasets.scenes` (the datasets room
opens the sample without this one) and re-exported here; the other renderers live here.
"""

from tsrkit.datasets.scenes import (
    LIGHTINGS,
    SAMPLE_FRAMES,
    SAMPLE_SEED,
    SynthOptions,
    generate,
    render_frame,
    sample_path,
)

__all__ = [
    "LIGHTINGS",
    "SAMPLE_FRAMES",
    "SAMPLE_SEED",
    "SynthOptions",
    "generate",
    "render_frame",
    "sample_path",
]
