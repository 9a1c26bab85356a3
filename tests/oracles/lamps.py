"""Synthetic lamps: lit disks on a dark housing, as samples (state-classifier tests) or on a
street frame (detector tests)."""

from __future__ import annotations

import cv2
import numpy as np

from tsrkit.core.types import Annotation, Frame, Sample

#: Pure lamp colours (BGR) as a camera roughly images them.
COLOURS = {"red": (40, 30, 230), "yellow": (20, 200, 240), "green": (170, 220, 30)}


def lamp(colour, size: int = 24, radius: int = 8, core=None, seed: int = 0) -> np.ndarray:
    """A ``size`` x ``size`` dark patch with a lit disk of ``colour`` (BGR) at its centre and,
    optionally, a ``core`` colour filling the inner half of the disk (a night halo)."""
    rng = np.random.default_rng(seed)
    image = np.full((size, size, 3), 35, np.uint8)
    centre = (size // 2, size // 2)
    cv2.circle(image, centre, radius, tuple(int(c) for c in colour), -1)
    if core is not None:
        cv2.circle(image, centre, radius // 2, tuple(int(c) for c in core), -1)
    noise = rng.integers(-6, 7, image.shape)
    return np.clip(image.astype(int) + noise, 0, 255).astype(np.uint8)


def housing(colour, lit: int, lights: int = 3, width: int = 20, vertical: bool = True):
    """A grey housing of ``lights`` dark lenses with lens number ``lit`` lit in ``colour``."""
    image = np.full((width * lights, width, 3), 60, np.uint8)
    for i in range(lights):
        fill = colour if i == lit else (25, 25, 25)
        cv2.circle(
            image,
            (width // 2, width * i + width // 2),
            width * 4 // 10,
            tuple(int(c) for c in fill),
            -1,
        )
    return image if vertical else np.ascontiguousarray(image.transpose(1, 0, 2))


def crop_sample(image: np.ndarray, state: str, name: str = "crop") -> Sample:
    """A crop sample: one annotation covering the whole image."""
    h, w = image.shape[:2]
    return Sample(name, (Annotation((0.0, 0.0, float(w), float(h)), state),), w, h, image=image)


def training_set(per_state: int = 4, radii=(5, 7, 9)) -> list[Sample]:
    """Lens crops of every colour, several sizes and noise seeds (deterministic)."""
    samples = []
    for state, colour in COLOURS.items():
        for i in range(per_state):
            r = radii[i % len(radii)]
            samples.append(
                crop_sample(lamp(colour, size=2 * r, radius=r, seed=i), state, f"{state}{i}")
            )
    return samples


def street(lamps=(), size=(120, 160)) -> Frame:
    """A grey frame with a darker housing band and lit discs ``(x, y, radius, bgr)``."""
    image = np.full((*size, 3), 95, np.uint8)
    cv2.rectangle(image, (10, 20), (150, 60), (35, 35, 35), -1)
    for x, y, radius, colour in lamps:
        cv2.circle(image, (x, y), radius, colour, -1, lineType=cv2.LINE_AA)
    return Frame(image, "synthetic")
