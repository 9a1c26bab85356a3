"""Signal heads of known geometry: a dark housing with 3 or 4 lenses, vertical or horizontal, one
lamp lit, on a textured background (the test bed of the housing stage and the verifier's rendered
positives). A head may have a light rim around its dark face, as the horizontal heads of Japan's
cameras show against dark hillsides.
"""

from __future__ import annotations

from dataclasses import dataclass

import cv2
import numpy as np

__all__ = ["LAMP_COLOURS", "RIM_WIDTH", "Head", "background", "render_head", "scatter_heads"]

#: BGR of lit lamps (a slightly orange red, amber, blue-green) by state.
LAMP_COLOURS = {"red": (40, 40, 230), "yellow": (20, 170, 250), "green": (170, 230, 40)}
#: Width of a light rim, in lens radii (the dark face is inset by it; cells stay 2.8 radii).
RIM_WIDTH = 0.35


@dataclass(frozen=True)
class Head:
    """A rendered head: the housing box and the lit lens (centre, radius), image coordinates."""

    housing: tuple[float, float, float, float]
    lens: tuple[float, float, float]


def render_head(
    image: np.ndarray,
    centre: tuple[float, float],
    radius: float,
    lenses: int = 3,
    lit: int = 0,
    vertical: bool = True,
    colour: tuple[int, int, int] = LAMP_COLOURS["red"],
    white_core: bool = False,
    rim: tuple[int, int, int] | None = None,
) -> Head:
    """Draw a head whose lamp ``lit`` (0 = top or left) has its centre at ``centre``.

    The housing is ``2.8 radius`` across and ``2.8 radius`` per lens along its axis (cells as
    wide as the housing), dark grey; unlit lenses are darker discs. With ``rim`` (a BGR colour)
    the housing's outer :data:`RIM_WIDTH` radii are drawn in that colour around the dark face.
    Drawn in place on ``image`` with 4x sub-pixel precision.
    """
    pitch = width = 2.8 * radius
    cx, cy = centre
    along0 = (cy if vertical else cx) - (lit + 0.5) * pitch
    if vertical:
        box = (cx - width / 2, along0, cx + width / 2, along0 + lenses * pitch)
    else:
        box = (along0, cy - width / 2, along0 + lenses * pitch, cy + width / 2)
    shift = 2
    scale = 1 << shift

    def fixed(v: float) -> int:
        return int(round(v * scale))

    inset = 0.0 if rim is None else RIM_WIDTH * radius
    for fill, grow in ((rim, 0.0), ((28, 28, 30), inset)):
        if fill is None:
            continue
        cv2.rectangle(
            image,
            (fixed(box[0] + grow), fixed(box[1] + grow)),
            (fixed(box[2] - grow) - 1, fixed(box[3] - grow) - 1),
            fill,
            -1,
            cv2.LINE_AA,
            shift,
        )
    for k in range(lenses):
        offset = (k - lit) * pitch
        x, y = (cx, cy + offset) if vertical else (cx + offset, cy)
        on = k == lit
        cv2.circle(
            image,
            (fixed(x), fixed(y)),
            fixed(radius),
            colour if on else (50, 50, 52),
            -1,
            cv2.LINE_AA,
            shift,
        )
        if on and white_core:
            core = (245, 245, 245)
            cv2.circle(
                image, (fixed(x), fixed(y)), fixed(0.6 * radius), core, -1, cv2.LINE_AA, shift
            )
    return Head(box, (cx, cy, radius))


def background(height: int, width: int, seed: int = 0) -> np.ndarray:
    """A sky-to-road gradient with mild noise, BGR uint8."""
    rng = np.random.default_rng(seed)
    rows = np.linspace(0, 1, height)[:, None, None]
    sky, road = np.array([215, 190, 160]), np.array([110, 115, 120])
    image = (sky * (1 - rows) + road * rows) * np.ones((1, width, 1))
    image += rng.normal(0, 6, image.shape)
    return np.clip(image, 0, 255).astype(np.uint8)


def scatter_heads(
    image: np.ndarray,
    rng: np.random.Generator,
    count: int = 5,
    horizontal: float = 0.2,
    rims: float = 0.0,
) -> list[tuple[float, float, float, float]]:
    """Draw ``count`` jittered heads on ``image`` (in place, then blurred and gamma-jittered as a
    whole) and return their housing boxes: the verifier's rendered positives.

    Each head: lens radius 2-12 px, 3 or 4 lenses, horizontal with probability ``horizontal``
    (else vertical), any lamp lit, its colour a :data:`LAMP_COLOURS` entry scaled 0.7-1.2 per
    channel, a white over-exposed core 2 times in 5, anywhere in the upper 55 % of the frame,
    with probability ``rims`` a light grey rim (grey level 140-230); then a Gaussian blur of
    sigma 0.7 (optics) and a gamma of 0.7-1.4 (exposure). ``rims`` 0 draws exactly what it
    drew before the option existed (no extra random draw).
    """
    height, width = image.shape[:2]
    boxes = []
    for _ in range(count):
        radius = float(rng.uniform(2, 12))
        lenses = int(rng.integers(3, 5))
        lit = int(rng.integers(0, lenses))
        vertical = bool(rng.random() < 1.0 - horizontal)
        base = np.array(list(LAMP_COLOURS.values())[int(rng.integers(0, 3))])
        blue, green, red = (int(c) for c in np.clip(base * rng.uniform(0.7, 1.2, 3), 0, 255))
        colour = (blue, green, red)
        centre = (float(rng.uniform(0.05, 0.95) * width), float(rng.uniform(0.05, 0.55) * height))
        core = rng.random() < 0.4
        rim = None
        if rims > 0 and rng.random() < rims:
            grey = int(rng.uniform(140, 230))
            rim = (grey, grey, grey)
        head = render_head(image, centre, radius, lenses, lit, vertical, colour, core, rim)
        boxes.append(head.housing)
    blurred = cv2.GaussianBlur(image, (0, 0), 0.7)
    gamma = rng.uniform(0.7, 1.4)
    image[:] = np.clip(255 * (blurred / 255.0) ** gamma, 0, 255).astype(np.uint8)
    return boxes
