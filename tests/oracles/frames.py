"""Real and synthetic frames the batched-vs-oracle tests compare on."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from tsrkit.core.types import Candidate
from tsrkit.datasets import open_dataset
from tsrkit.synth import SynthOptions, render_frame

#: The real detection sets: lens boxes (KR) and housing boxes (cinTA, DTLD), three cameras.
CAMERAS = ("roboflow_cinta_v2_id", "dtld_fridtjofs", "roboflow_traffic_light_kr")


def annotated_frames(root: Path) -> list[tuple[np.ndarray, list[Candidate]]]:
    """Two frames of each set in :data:`CAMERAS` under ``root``, with their annotated boxes as
    candidates, and two synthetic 1280x720 scenes without candidates."""
    out = []
    for name in CAMERAS:
        for sample in list(open_dataset(root / name, format="normalized"))[:2]:
            boxes = [Candidate.from_box(a.bbox, 1.0) for a in sample.annotations]
            out.append((sample.load().image, boxes))
    out += [(render_frame(seed, 7, 1280, 720, SynthOptions())[0], []) for seed in (3, 4)]
    return out
