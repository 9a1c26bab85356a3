"""tsrkit's own synthetic data: road scenes rendered with exact labels.

``scenes`` renders the deterministic day / dusk / night road scenes with lit traffic lights
that make the bundled sample (:func:`sample_path`) and ``tsrkit datasets synth``. Other
renderers (for example Sun-lit scenes or drives along a GPS path) live beside it.
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
