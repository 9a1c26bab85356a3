"""Synthetic road scenes with traffic signals of known state, centre and radius.

``generate`` renders deterministic driving-video-like frames (480x356 by default, as the video of
Zheng 2016, 4.2) and writes them as JPEG plus normalised and COCO annotations; ``sample_path``
gives the bundled default sample, generated on first use into a cache folder.

What is simulated
    A sky gradient with clouds or a sun glare, buildings with windows, trees, a perspective road
    with lane markings, cars seen from behind, street lamps, a red-ringed road sign, and signal
    housings (dark, three lenses vertical or horizontal, on mast arms or poles, some far and
    tiny) with one lit lens of radius about 1.5-9 px (Zheng 4.2). Three lighting conditions:
    ``day`` (the lit lens may be washed out towards white against a bright sky), ``dusk`` and
    ``night``, where the lens radiance saturates the sensor, leaving a near-white core and the
    colour only in the halo around it (Zheng 4.2, Figure 4-6c "blooming"). Distractors: white and
    orange (sodium) street lamps, red tail and brake lights in pairs low in the frame, oncoming
    headlights, lit windows, bright sky patches, light reflected on a wet road, specular glints,
    saturated green foliage and red signs. The camera adds a white-balance cast, vignetting,
    optical blur (applied to the scene radiance before clipping, so bright lights bloom), sensor
    noise, and compression artefacts of a low-quality video (one JPEG round trip at quality 40-75)
    before the frame is stored as JPEG (quality 90).

What is not simulated
    Lens distortion, motion between frames (every frame is an independent scene), arrow lenses,
    pedestrian signals, occlusion of lenses, rain, fog, rolling shutter and LED flicker.

Measured on 300 frames of seed 0: the mean V (Mascetti 3.2) of day frames is 118-150, dusk
54-83, night 15-24, so the label ``lighting`` and the Table 4 classes agree (very high or high,
high or mid, mid). Lens radii follow ``lens_radius``; about 3 % of frames have no lit lens.

Coordinates follow the COCO convention: pixel ``(i, j)`` covers ``[i, i+1) x [j, j+1)``, so
a lens centred at ``(x, y)`` lies over pixel ``(floor(x), floor(y))``. Annotation boxes are
lens boxes ``(x-r, y-r, x+r, y+r)``; ``attributes["radius"]`` holds ``r`` exactly. "Off"
housings (no lit lens) are drawn but not annotated.
"""

from __future__ import annotations

import functools
import itertools
import json
import math
import os
import shutil
import tempfile
from collections.abc import Callable
from dataclasses import asdict, dataclass, replace
from pathlib import Path

import cv2
import numpy as np

from tsrkit.core.atomic import json_text
from tsrkit.core.errors import TsrkitError
from tsrkit.core.types import Annotation, Dataset, Sample
from tsrkit.datasets.writing import write_dataset

__all__ = [
    "ANNOTATION_FILES",
    "GENERATOR_VERSION",
    "LENS_BGR",
    "LENS_ORDER",
    "LIGHTING",
    "LIGHTINGS",
    "SAMPLE_FRAMES",
    "SAMPLE_SEED",
    "STAMP_FILE",
    "WINDOW_BGR",
    "Canvas",
    "Housing",
    "Lighting",
    "SynthOptions",
    "add_glow",
    "cache_dir",
    "compress",
    "draw_buildings",
    "draw_cars",
    "draw_lamps",
    "draw_road",
    "draw_sign",
    "draw_signals",
    "draw_sky",
    "draw_trees",
    "encode_jpeg",
    "expose",
    "frame_lighting",
    "frame_split",
    "generate",
    "housing_layout",
    "lens_radius",
    "noise_field",
    "place_signals",
    "render_dataset",
    "render_frame",
    "retroreflection",
    "sample_path",
    "vignette",
    "write_annotations",
]

#: Bumped whenever the rendered pixels or annotations change; names the sample cache folder.
GENERATOR_VERSION = 2
LIGHTINGS = ("day", "dusk", "night")
#: Lens order in a housing: top to bottom, or left to right.
LENS_ORDER = ("red", "yellow", "green")
#: Emitted lens colours, BGR in [0, 1] (OpenCV hue about 176, 20 and 78).
LENS_BGR = {"red": (0.12, 0.08, 1.0), "yellow": (0.0, 0.62, 1.0), "green": (0.66, 1.0, 0.14)}
SAMPLE_FRAMES = 48
SAMPLE_SEED = 0
STAMP_FILE = "synth.json"
_BASE_HEIGHT = 356.0
_NOISE_SLACK = 1 << 16
#: Lit window colours, BGR: warm tungsten, warmer, and cool white.
WINDOW_BGR = np.array(((0.45, 0.75, 1.0), (0.3, 0.6, 1.0), (0.95, 0.95, 0.9)))


@dataclass(frozen=True)
class SynthOptions:
    """Options of :func:`generate` beyond size, count and seed.

    Parameters
    ----------
    lighting : tuple of str
        Conditions assigned in turn to frames ``0, 1, 2, ...`` (balanced by construction).
    quality : int
        JPEG quality of the stored frames.
    off_fraction : float
        Probability that a housing shows no lit lens (drawn, not annotated).
    """

    lighting: tuple[str, ...] = LIGHTINGS
    quality: int = 90
    off_fraction: float = 0.08

    def __post_init__(self):
        lighting = tuple(self.lighting)
        object.__setattr__(self, "lighting", lighting)
        unknown = [c for c in lighting if c not in LIGHTINGS]
        if not lighting or unknown:
            raise ValueError(
                f"lighting must be a non-empty selection of {LIGHTINGS}; got {self.lighting!r}"
            )
        if not 1 <= int(self.quality) <= 100:
            raise ValueError(f"quality must be in 1..100; got {self.quality!r}")
        if not 0.0 <= float(self.off_fraction) < 1.0:
            raise ValueError(f"off_fraction must be in [0, 1); got {self.off_fraction!r}")


@dataclass(frozen=True)
class Lighting:
    """How one lighting condition exposes the scene; radiances are relative to sensor full scale.

    ``ambient`` scales every reflecting surface; ``lens_core`` and ``lens_halo`` are the ranges
    of a lit lens's disk and halo radiance (above 1 the sensor clips: the white core of Zheng
    4.2); ``washout`` is the largest white mixed into a lens colour by day; ``noise`` the sensor
    noise (std); ``lamps_on``, ``windows_lit`` and ``wet_road`` are probabilities.
    """

    name: str
    ambient: float
    sky_top: tuple[float, float, float]
    sky_horizon: tuple[float, float, float]
    lens_core: tuple[float, float]
    lens_halo: tuple[float, float]
    washout: float
    noise: float
    lamps_on: float
    windows_lit: float
    wet_road: float


LIGHTING = {
    "day": Lighting(
        "day",
        ambient=1.0,
        sky_top=(0.82, 0.56, 0.30),
        sky_horizon=(0.96, 0.90, 0.84),
        lens_core=(0.95, 1.25),
        lens_halo=(0.10, 0.22),
        washout=0.45,
        noise=0.010,
        lamps_on=0.0,
        windows_lit=0.0,
        wet_road=0.0,
    ),
    "dusk": Lighting(
        "dusk",
        ambient=0.42,
        sky_top=(0.40, 0.22, 0.18),
        sky_horizon=(0.40, 0.62, 0.95),
        lens_core=(1.6, 3.0),
        lens_halo=(0.30, 0.55),
        washout=0.0,
        noise=0.018,
        lamps_on=0.7,
        windows_lit=0.25,
        wet_road=0.3,
    ),
    "night": Lighting(
        "night",
        ambient=0.10,
        sky_top=(0.07, 0.035, 0.02),
        sky_horizon=(0.16, 0.13, 0.11),
        lens_core=(5.0, 12.0),
        lens_halo=(0.65, 1.1),
        washout=0.0,
        noise=0.028,
        lamps_on=1.0,
        windows_lit=0.35,
        wet_road=0.5,
    ),
}


@dataclass
class Canvas:
    """The scene being rendered: reflected light (``base``) and emitted light (``light``)."""

    base: np.ndarray
    light: np.ndarray
    horizon: float
    scale: float
    keep_out: list

    @property
    def height(self) -> int:
        return self.base.shape[0]

    @property
    def width(self) -> int:
        return self.base.shape[1]

    def free(self, box, margin: float = 0.0) -> bool:
        """True when ``box`` (grown by ``margin``) overlaps no signal housing."""
        x0, y0, x1, y1 = box
        return all(
            x1 + margin < a or x0 - margin > c or y1 + margin < b or y0 - margin > d
            for a, b, c, d in self.keep_out
        )


# --------------------------------------------------------------------------- light sources


def add_glow(
    light: np.ndarray,
    x: float,
    y: float,
    color,
    core_radius: float,
    core: float,
    halo_sigma: float,
    halo: float,
    stretch: float = 1.0,
) -> None:
    """Add an emitting disk with a Gaussian halo to ``light`` (in place).

    The disk is anti-aliased (coverage ``clip(r + 0.5 - d, 0, 1)`` per pixel, pixel centres at
    ``i + 0.5``); the halo ``halo * exp(-d^2 / 2 sigma^2)`` models the light diffused around a
    lens. ``stretch`` > 1 elongates the halo vertically (a reflection on a wet road).
    """
    h, w = light.shape[:2]
    reach_x = max(core_radius + 1.0, 3.0 * halo_sigma)
    reach_y = max(core_radius + 1.0, 3.0 * halo_sigma * stretch)
    x0, x1 = max(int(x - reach_x), 0), min(int(x + reach_x) + 2, w)
    y0, y1 = max(int(y - reach_y), 0), min(int(y + reach_y) + 2, h)
    if x0 >= x1 or y0 >= y1:
        return
    dx = np.arange(x0, x1, dtype=np.float32) + 0.5 - x
    dy = np.arange(y0, y1, dtype=np.float32)[:, None] + 0.5 - y
    dist = np.sqrt(dx * dx + dy * dy)
    weight = core * np.clip(core_radius + 0.5 - dist, 0.0, 1.0)
    if halo > 0 and halo_sigma > 0:
        weight += halo * np.exp(-(dx * dx + (dy / stretch) ** 2) / (2.0 * halo_sigma**2))
    light[y0:y1, x0:x1] += weight[..., None] * np.asarray(color, np.float32)


def _disk(image: np.ndarray, x: float, y: float, r: float, color) -> None:
    """Fill an anti-aliased disk with sub-pixel centre (OpenCV fixed-point, 4 fractional bits)."""
    cv2.circle(
        image,
        (int(round(x * 16 - 8)), int(round(y * 16 - 8))),
        max(int(round(r * 16)), 1),
        tuple(float(c) for c in color),
        -1,
        cv2.LINE_AA,
        4,
    )


def _rect(image: np.ndarray, box, color) -> None:
    """Fill ``box`` (x0, y0, x1, y1), rounded to whole pixels."""
    x0, y0, x1, y1 = (int(round(v)) for v in box)
    cv2.rectangle(image, (x0, y0), (x1 - 1, y1 - 1), tuple(float(c) for c in color), -1)


def _line(image: np.ndarray, p, q, color, thickness: float) -> None:
    """An anti-aliased line from ``p`` to ``q``, at least one pixel thick."""
    cv2.line(
        image,
        (int(round(p[0])), int(round(p[1]))),
        (int(round(q[0])), int(round(q[1]))),
        tuple(float(c) for c in color),
        max(int(round(thickness)), 1),
        cv2.LINE_AA,
    )


# --------------------------------------------------------------------------- background


def draw_sky(canvas: Canvas, rng: np.random.Generator, lit: Lighting) -> None:
    """Vertical gradient from ``sky_top`` to ``sky_horizon``, plus clouds or a sun glare."""
    rows = int(math.ceil(canvas.horizon))
    t = (np.arange(rows, dtype=np.float32) / max(rows - 1, 1)) ** 1.4
    top = np.asarray(lit.sky_top, np.float32) * rng.uniform(0.85, 1.1)
    bottom = np.asarray(lit.sky_horizon, np.float32) * rng.uniform(0.9, 1.05)
    if lit.name == "day" and rng.random() < 0.3:  # overcast
        top = bottom = np.full(3, rng.uniform(0.72, 0.9), np.float32)
    canvas.base[:rows] = (top + (bottom - top) * t[:, None])[:, None, :]
    for _ in range(rng.integers(0, 6) if lit.name == "day" else 0):
        x, y = rng.uniform(0, canvas.width), rng.uniform(0, canvas.horizon * 0.7)
        s = rng.uniform(15, 50) * canvas.scale
        if canvas.free((x - 2 * s, y - s, x + 2 * s, y + s), 6 * canvas.scale):
            cv2.ellipse(
                canvas.base,
                (int(x), int(y)),
                (int(2 * s), int(s * 0.6)),
                0,
                0,
                360,
                (0.97, 0.97, 0.97),
                -1,
                cv2.LINE_AA,
            )
    if lit.name == "dusk" or (lit.name == "day" and rng.random() < 0.25):
        _sun(canvas, rng, lit)


def _sun(canvas: Canvas, rng: np.random.Generator, lit: Lighting) -> None:
    """A bright, partly saturated sky patch: the sun low in the sky, or its glare."""
    s = rng.uniform(8, 20) * canvas.scale
    x = rng.uniform(0, canvas.width)
    y = canvas.horizon - rng.uniform(0.1, 0.6) * canvas.horizon
    if not canvas.free((x - 6 * s, y - 6 * s, x + 6 * s, y + 6 * s)):
        return
    color = (0.85, 0.95, 1.0) if lit.name == "day" else (0.5, 0.8, 1.0)
    add_glow(canvas.base, x, y, color, s, 1.5, 2.0 * s, 0.6)  # behind what is drawn later


def draw_buildings(canvas: Canvas, rng: np.random.Generator, lit: Lighting) -> None:
    """A skyline of boxes standing on the horizon, with window grids (some lit at night)."""
    x = rng.uniform(-40, 0) * canvas.scale
    while x < canvas.width:
        w = rng.uniform(30, 110) * canvas.scale
        top = canvas.horizon - rng.uniform(0.15, 0.95) * canvas.horizon
        tone = rng.uniform(0.35, 0.8)
        color = np.array([tone, tone, tone]) * rng.uniform(0.85, 1.1, 3) * lit.ambient
        box = (x, top, x + w, canvas.horizon + 4 * canvas.scale)
        if rng.random() < 0.8:
            _rect(canvas.base, box, color)
            _windows(canvas, rng, lit, box)
        x += w + rng.uniform(-5, 25) * canvas.scale


def _windows(canvas: Canvas, rng: np.random.Generator, lit: Lighting, box) -> None:
    """A grid of windows over a building: dark glass, or lit (warm or cool) in the dark."""
    x0, y0, x1, y1 = box
    step = rng.uniform(7, 12) * canvas.scale
    size = max(int(step * rng.uniform(0.35, 0.6)), 1)
    xs = np.arange(x0 + step * 0.5, x1 - step * 0.5, step).astype(int)
    ys = np.arange(y0 + step * 0.6, y1 - step, step).astype(int)
    grid = (len(ys), len(xs))
    glass = np.array((0.45, 0.35, 0.30)) * lit.ambient * rng.uniform(0.7, 1.2, grid + (1,))
    lamp = WINDOW_BGR[rng.integers(0, 3, grid)] * rng.uniform(0.3, 0.8, grid + (1,))
    lit_now = rng.random(grid) < lit.windows_lit
    for (i, wy), (j, wx) in itertools.product(enumerate(ys), enumerate(xs)):
        cell = (wx, wy, wx + size, wy + int(size * 1.3))
        if lit_now[i, j] and canvas.free(cell, 2 * canvas.scale):
            cv2.rectangle(
                canvas.light, cell[:2], (cell[2] - 1, cell[3] - 1), lamp[i, j].tolist(), -1
            )
        else:
            cv2.rectangle(
                canvas.base, cell[:2], (cell[2] - 1, cell[3] - 1), glass[i, j].tolist(), -1
            )


def draw_road(canvas: Canvas, rng: np.random.Generator, lit: Lighting) -> float:
    """Ground, asphalt trapezoid towards a vanishing point, lane markings; returns its x."""
    h, w, hz = canvas.height, canvas.width, canvas.horizon
    ground = np.array((0.35, 0.45, 0.42)) * rng.uniform(0.8, 1.1) * lit.ambient
    canvas.base[int(hz) :] = ground
    vx = w * rng.uniform(0.35, 0.65)
    left, right = vx - w * rng.uniform(0.7, 1.1), vx + w * rng.uniform(0.7, 1.1)
    asphalt = np.array((0.36, 0.36, 0.37)) * rng.uniform(0.75, 1.15) * lit.ambient
    poly = np.array(
        [[vx - 3 * canvas.scale, hz], [vx + 3 * canvas.scale, hz], [right, h], [left, h]],
        np.float32,
    )
    cv2.fillPoly(
        canvas.base, [np.round(poly * 16).astype(np.int32)], asphalt.tolist(), cv2.LINE_AA, 4
    )
    paint = np.array((0.85, 0.85, 0.85)) * lit.ambient
    for frac in np.linspace(0.0, 1.0, rng.integers(3, 6))[1:-1]:
        _dashes(canvas, vx, left + (right - left) * frac, paint)
    centre = np.array((0.1, 0.7, 0.85)) * lit.ambient  # yellow centre line
    _line(canvas.base, (vx, hz), (vx + (left - vx) * 0.05, h), centre, 2 * canvas.scale)
    return vx


def _dashes(canvas: Canvas, vx: float, bottom_x: float, color) -> None:
    """Dashed lane line from the bottom edge to the vanishing point (dashes shrink with depth)."""
    hz, h = canvas.horizon, canvas.height
    for depth in np.arange(1.0, 12.0, 1.0):
        t0, t1 = 1.0 / depth, 1.0 / (depth + 0.45)
        p = (vx + (bottom_x - vx) * t0, hz + (h - hz) * t0)
        q = (vx + (bottom_x - vx) * t1, hz + (h - hz) * t1)
        _line(canvas.base, p, q, color, 3 * t0 * canvas.scale)


def draw_trees(canvas: Canvas, rng: np.random.Generator, lit: Lighting) -> None:
    """Roadside trees: trunks and canopies of overlapping green disks (foliage distractor)."""
    for _ in range(rng.integers(1, 6)):
        x = rng.uniform(0, canvas.width)
        size = rng.uniform(12, 45) * canvas.scale
        base_y = canvas.horizon + rng.uniform(0, 25) * canvas.scale
        top = base_y - size * 2.2
        if not canvas.free((x - size, top - size, x + size, base_y)):
            continue
        _line(
            canvas.base,
            (x, base_y),
            (x, top),
            np.array((0.12, 0.18, 0.25)) * lit.ambient,
            size * 0.15,
        )
        green = np.array((rng.uniform(0.05, 0.45), rng.uniform(0.4, 0.7), rng.uniform(0.05, 0.3)))
        for _ in range(12):
            cx, cy = x + rng.normal(0, size * 0.4), top + rng.normal(0, size * 0.4)
            _disk(
                canvas.base,
                cx,
                cy,
                size * rng.uniform(0.3, 0.6),
                green * rng.uniform(0.5, 1.1) * lit.ambient,
            )


# --------------------------------------------------------------------------- distractors


def draw_cars(canvas: Canvas, rng: np.random.Generator, lit: Lighting, vx: float) -> None:
    """Cars ahead (red tail or brake light pairs) and, at dusk and night, oncoming headlights."""
    h, hz = canvas.height, canvas.horizon
    for t in np.sort(rng.uniform(0.08, 0.6, rng.integers(0, 5))):  # 1 / depth, far first
        y = hz + (h - hz) * t
        cx = vx + rng.uniform(-0.8, 0.8) * canvas.width * t
        cw = canvas.width * 0.32 * t
        ch = cw * 0.75
        if not canvas.free((cx - cw / 2, y - ch, cx + cw / 2, y), cw * 0.3):
            continue
        grey = rng.uniform(0.05, 0.8)
        body = (grey + (rng.uniform(0.05, 0.8, 3) - grey) * 0.5) * lit.ambient
        _rect(canvas.base, (cx - cw / 2, y - ch, cx + cw / 2, y), body)
        _rect(
            canvas.base,
            (cx - cw * 0.4, y - ch * 0.95, cx + cw * 0.4, y - ch * 0.6),
            np.array((0.2, 0.15, 0.12)) * lit.ambient,
        )
        braking = rng.random() < 0.4
        power = 1.6 if lit.lamps_on else (0.9 if braking else 0.25)
        for side in (-1, 1):
            lx, ly = cx + side * cw * 0.38, y - ch * 0.45
            add_glow(
                canvas.light,
                lx,
                ly,
                (0.15, 0.1, 1.0),
                max(cw * 0.06, 0.8),
                power,
                max(cw * 0.08, 0.8),
                power * 0.35,
            )
            if lit.lamps_on and rng.random() < lit.wet_road:
                add_glow(
                    canvas.light,
                    lx,
                    y + ch * 0.4,
                    (0.15, 0.1, 1.0),
                    0,
                    0,
                    max(cw * 0.05, 0.8),
                    0.25,
                    stretch=4.0,
                )
        if lit.lamps_on and rng.random() < 0.5:
            _headlights(canvas, 2 * vx - cx, y * 0.98 + hz * 0.02, cw)
    if lit.name == "day":
        _glints(canvas, rng)


def _headlights(canvas: Canvas, x: float, y: float, width: float) -> None:
    """The overexposed white pair of an oncoming car of ``width`` pixels."""
    for side in (-1, 1):
        add_glow(
            canvas.light,
            x + side * width * 0.35,
            y - width * 0.25,
            (0.9, 0.95, 1.0),
            max(width * 0.05, 0.7),
            4.0,
            max(width * 0.1, 0.8),
            0.8,
        )


def _glints(canvas: Canvas, rng: np.random.Generator) -> None:
    """Specular reflections of the sun: small saturated white spots below the horizon."""
    for _ in range(rng.integers(0, 4)):
        x = rng.uniform(0, canvas.width)
        y = rng.uniform(canvas.horizon, canvas.height)
        if canvas.free((x, y, x, y), 6 * canvas.scale):
            add_glow(
                canvas.light,
                x,
                y,
                (1.0, 1.0, 1.0),
                rng.uniform(0.8, 2.0) * canvas.scale,
                1.5,
                1.5 * canvas.scale,
                0.4,
            )


def draw_lamps(canvas: Canvas, rng: np.random.Generator, lit: Lighting, vx: float) -> None:
    """Street lamps along both road sides: white (LED) or orange (sodium) heads."""
    sodium = rng.random() < 0.5
    for depth in np.arange(1.2, 9.0, rng.uniform(1.2, 2.5)):
        t = 1.0 / depth
        for side in (-1, 1):
            if rng.random() < 0.35:
                continue
            foot_x = vx + side * canvas.width * 0.75 * t
            foot_y = canvas.horizon + (canvas.height - canvas.horizon) * t
            head_x = foot_x - side * canvas.width * 0.12 * t
            head_y = foot_y - canvas.height * 0.9 * t
            size = max(6 * t, 0.8) * canvas.scale
            box = (min(foot_x, head_x), head_y, max(foot_x, head_x), foot_y)
            if head_y < 2 or not canvas.free(box, 5 * size + 2):
                continue
            pole = np.array((0.35, 0.35, 0.35)) * lit.ambient
            _line(canvas.base, (foot_x, foot_y), (foot_x, head_y), pole, 3 * t * canvas.scale)
            _line(canvas.base, (foot_x, head_y), (head_x, head_y), pole, 2 * t * canvas.scale)
            _lamp_head(canvas, rng, lit, head_x, head_y + 2 * t * canvas.scale, size, sodium)


def _lamp_head(
    canvas: Canvas,
    rng: np.random.Generator,
    lit: Lighting,
    x: float,
    y: float,
    size: float,
    sodium: bool,
) -> None:
    if rng.random() >= lit.lamps_on:
        _disk(canvas.base, x, y, size, np.array((0.6, 0.6, 0.6)) * lit.ambient)
        return
    color = (0.25, 0.65, 1.0) if sodium else (1.0, 0.97, 0.9)
    add_glow(canvas.light, x, y, color, size, 6.0, size * 1.5, 0.9)
    if rng.random() < lit.wet_road:
        road_y = canvas.horizon + (canvas.height - canvas.horizon) * rng.uniform(0.3, 0.9)
        add_glow(canvas.light, x, road_y, color, 0, 0, size, 0.35, stretch=5.0)


def retroreflection(lit: Lighting) -> float:
    """Brightness of retro-reflective paint: as bright as the scene by day, brighter in the dark
    (headlights light it back towards the camera)."""
    return lit.ambient if lit.ambient > 0.5 else lit.ambient * 3.0


def draw_sign(canvas: Canvas, rng: np.random.Generator, lit: Lighting) -> None:
    """A circular prohibition sign (white with a red ring) on a pole: a red distractor."""
    r = rng.uniform(4, 11) * canvas.scale
    x = rng.uniform(r, canvas.width - r)
    y = rng.uniform(0.35, 0.9) * canvas.horizon
    if not canvas.free((x - r, y - r, x + r, canvas.horizon), 4 * canvas.scale):
        return
    _line(
        canvas.base,
        (x, y),
        (x, canvas.horizon + 10 * canvas.scale),
        np.array((0.4, 0.4, 0.4)) * lit.ambient,
        max(r * 0.2, 1),
    )
    gain = retroreflection(lit)
    _disk(canvas.base, x, y, r, np.array((0.1, 0.1, 0.85)) * gain)
    _disk(canvas.base, x, y, r * 0.72, np.array((0.92, 0.92, 0.92)) * gain)


# --------------------------------------------------------------------------- signals


def lens_radius(rng: np.random.Generator, scale: float) -> float:
    """A lens radius in pixels: 1.5-9 px at 356 rows (Zheng 4.2), smaller ones more frequent."""
    return round((1.5 + 7.5 * rng.random() ** 1.6) * scale, 2)


def housing_layout(x: float, y: float, r: float, vertical: bool):
    """Housing box and the three lens centres for a housing whose first lens is at ``(x, y)``."""
    pitch, pad = 2.5 * r, 0.75 * r + 0.5
    step = (0.0, pitch) if vertical else (pitch, 0.0)
    centres = [(x + k * step[0], y + k * step[1]) for k in range(3)]
    box = (x - r - pad, y - r - pad, centres[2][0] + r + pad, centres[2][1] + r + pad)
    return box, centres


@dataclass(frozen=True)
class Housing:
    """A placed signal housing: its box, lens centres and radius, mount and lit state."""

    box: tuple[float, float, float, float]
    centres: list
    radius: float
    vertical: bool
    mount: str
    state: str | None

    def annotation(self) -> Annotation:
        """The lens box of the lit lens, with its exact radius."""
        if self.state is None:
            raise ValueError("a dark head has no lit lens to annotate")
        x, y = self.centres[LENS_ORDER.index(self.state)]
        r = self.radius
        return Annotation(
            (round(x - r, 3), round(y - r, 3), round(x + r, 3), round(y + r, 3)),
            self.state,
            {
                "radius": r,
                "orientation": "vertical" if self.vertical else "horizontal",
                "mount": self.mount,
                "housing": [round(v, 3) for v in self.box],
            },
        )


def place_signals(canvas: Canvas, rng: np.random.Generator, options: SynthOptions) -> list[Housing]:
    """Choose 1-4 non-overlapping housings and reserve their boxes from the distractors."""
    state = LENS_ORDER[rng.integers(0, 3)]
    vertical = bool(rng.random() < 0.6)
    housings = []
    for _ in range(rng.integers(1, 5)):
        if rng.random() < 0.2:
            state = LENS_ORDER[rng.integers(0, 3)]
        placed = _place_housing(canvas, rng, vertical)
        if placed is None:
            continue
        box, centres, r = placed
        far = r < 2.5 * canvas.scale
        mount = "far" if far else ("mast" if rng.random() < 0.6 else "pole")
        lit_state = None if rng.random() < options.off_fraction else state
        housings.append(Housing(box, centres, r, vertical, mount, lit_state))
        canvas.keep_out.append(tuple(v + d for v, d in zip(box, (-r, -r, r, r))))
    return housings


def draw_signals(
    canvas: Canvas, rng: np.random.Generator, lit: Lighting, housings: list[Housing]
) -> list[Annotation]:
    """Draw the mounts, then the housings over them; return the lit lenses' annotations."""
    for housing in housings:
        _draw_mount(canvas, rng, lit, housing)
    for housing in housings:
        _draw_housing(canvas, rng, lit, housing)
    return [h.annotation() for h in housings if h.state is not None]


def _place_housing(canvas: Canvas, rng: np.random.Generator, vertical: bool):
    """Try a few random positions for a housing that fits the frame and overlaps none."""
    for _ in range(8):
        r = lens_radius(rng, canvas.scale)
        height_px = r * rng.uniform(10, 26)  # height above the horizon grows with size
        x = round(rng.uniform(0.05, 0.95) * canvas.width, 2)
        y = round(max(canvas.horizon - height_px, 3 * r + 2), 2)
        box, centres = housing_layout(x, y, r, vertical)
        if (
            box[0] >= 1
            and box[1] >= 1
            and box[2] <= canvas.width - 1
            and box[3] <= canvas.horizon + r
            and canvas.free(box, 2 * r + 3)
        ):
            return box, centres, r
    return None


def _draw_mount(canvas: Canvas, rng: np.random.Generator, lit: Lighting, housing: Housing) -> None:
    """A mast arm reaching from a roadside pole, or a pole under the housing."""
    x0, y0, x1, y1 = housing.box
    radius, mount = housing.radius, housing.mount
    color = np.array((0.3, 0.3, 0.32)) * rng.uniform(0.6, 1.0) * lit.ambient
    thick = max(radius * 0.5, 1)
    cx = (x0 + x1) / 2
    if mount == "mast":
        pole_x = cx + rng.choice((-1, 1)) * rng.uniform(0.2, 0.6) * canvas.width
        pole_x = float(np.clip(pole_x, 2, canvas.width - 2))
        _line(canvas.base, (pole_x, y0 - thick), (cx, y0 - thick), color, thick * 1.2)
        foot = canvas.horizon + (canvas.height - canvas.horizon) * rng.uniform(0.05, 0.4)
        _line(canvas.base, (pole_x, y0 - thick * 3), (pole_x, foot), color, thick * 2.2)
        _line(canvas.base, (cx, y0 - thick), (cx, y0 + 1), color, thick)
    else:
        _line(canvas.base, (cx, y1), (cx, canvas.horizon + 8 * canvas.scale), color, thick * 1.5)


def _draw_housing(
    canvas: Canvas, rng: np.random.Generator, lit: Lighting, housing: Housing
) -> None:
    """Dark housing, dim unlit lenses and the lit lens (overexposed at night, Zheng 4.2)."""
    box, r = housing.box, housing.radius
    dark = rng.uniform(0.03, 0.12)
    if r > 3.5 * canvas.scale and rng.random() < 0.3:  # backplate with a light border
        x0, y0, x1, y1 = box
        grow = r * 0.9
        _rect(
            canvas.base,
            (x0 - grow, y0 - grow, x1 + grow, y1 + grow),
            np.array((0.1, 0.75, 0.85)) * retroreflection(lit),
        )
        _rect(
            canvas.base,
            (x0 - grow + 1, y0 - grow + 1, x1 + grow - 1, y1 + grow - 1),
            (dark, dark, dark),
        )
    _rect(canvas.base, box, np.array((dark, dark, dark * 1.1)))
    for colour_name, (x, y) in zip(LENS_ORDER, housing.centres):
        tint = np.asarray(LENS_BGR[colour_name]) * 0.06 + 0.02
        _disk(canvas.base, x, y, r, tint)
        if colour_name == housing.state:
            _lit_lens(canvas, rng, lit, x, y, r, LENS_BGR[colour_name])


def _lit_lens(
    canvas: Canvas, rng: np.random.Generator, lit: Lighting, x: float, y: float, r: float, color
) -> None:
    """The emitted light of a lit lens: a disk plus halo; at day possibly washed out to white."""
    color = np.asarray(color, np.float32)
    if lit.washout and rng.random() < 0.5:
        white = rng.uniform(0.0, lit.washout)
        color = color * (1 - white) + white
    core = rng.uniform(*lit.lens_core)
    halo = rng.uniform(*lit.lens_halo)
    add_glow(canvas.light, x, y, color, r, core, max(r * rng.uniform(0.9, 1.4), 1.0), halo)


# --------------------------------------------------------------------------- camera


def expose(canvas: Canvas, rng: np.random.Generator, lit: Lighting) -> np.ndarray:
    """Camera: white balance, vignetting, optical blur, sensor clipping and noise -> BGR uint8."""
    radiance = cv2.add(canvas.base, canvas.light)
    cv2.multiply(radiance, vignette(*radiance.shape[:2]), dst=radiance)
    cv2.multiply(radiance, (*rng.uniform(0.92, 1.08, 3), 0.0), dst=radiance)
    sigma = rng.uniform(0.5, 1.0) * canvas.scale
    radiance = cv2.GaussianBlur(radiance, (0, 0), sigma)
    if rng.random() < 0.3:  # short motion blur
        kernel = np.zeros((3, 3), np.float32)
        kernel[1, :] = 1.0 / 3.0
        radiance = cv2.filter2D(radiance, -1, kernel if rng.random() < 0.5 else kernel.T)
    cv2.min(radiance, (1.0,) * 4, dst=radiance)  # the sensor saturates
    noise = noise_field(radiance.shape, int(rng.integers(0, _NOISE_SLACK)))
    cv2.scaleAdd(noise, lit.noise, radiance, dst=radiance)
    return cv2.multiply(radiance, (255.0,) * 4, dtype=cv2.CV_8U)  # rounds, saturates


@functools.lru_cache(maxsize=4)
def vignette(height: int, width: int) -> np.ndarray:
    """Relative illumination of the lens: 1 at the centre, 0.875 in the corners."""
    yy, xx = np.ogrid[:height, :width]
    falloff = 1.0 - 0.25 * (((xx - width / 2) / width) ** 2 + ((yy - height / 2) / height) ** 2)
    return np.repeat(falloff.astype(np.float32)[..., None], 3, axis=2)


@functools.lru_cache(maxsize=4)
def _noise_bank(size: int) -> np.ndarray:
    return np.random.default_rng(20160421).standard_normal(size + _NOISE_SLACK, np.float32)


def noise_field(shape: tuple[int, ...], offset: int) -> np.ndarray:
    """Unit Gaussian sensor noise of ``shape``: a window at ``offset`` into a fixed bank.

    Drawing a fresh field per frame costs more than the rest of the camera model; a window
    at a random offset of one cached field is as noisy and deterministic.
    """
    size = int(np.prod(shape))
    return _noise_bank(size)[offset : offset + size].reshape(shape)


def encode_jpeg(image: np.ndarray, quality: int) -> np.ndarray:
    """JPEG bytes of a BGR image (libjpeg through OpenCV: deterministic for equal input)."""
    ok, data = cv2.imencode(".jpg", image, [cv2.IMWRITE_JPEG_QUALITY, int(quality)])
    if not ok:
        raise TsrkitError("JPEG encoding failed")
    return data


def compress(image: np.ndarray, quality: int) -> np.ndarray:
    """One JPEG round trip: the block and chroma artefacts of a low-quality video."""
    decoded = cv2.imdecode(encode_jpeg(image, quality), cv2.IMREAD_COLOR)
    if decoded is None:
        raise TsrkitError("JPEG decoding failed")
    return decoded


# --------------------------------------------------------------------------- frames


def frame_lighting(index: int, options: SynthOptions) -> str:
    """Lighting of frame ``index``: the options' conditions in turn (balanced)."""
    return options.lighting[index % len(options.lighting)]


def frame_split(index: int, options: SynthOptions) -> str:
    """Train/test split of frame ``index``: alternating blocks, 50/50 within each lighting."""
    return ("train", "test")[(index // len(options.lighting)) % 2]


def render_frame(
    index: int, seed: int, width: int, height: int, options: SynthOptions
) -> tuple[np.ndarray, list[Annotation], str]:
    """Render frame ``index`` of the scene sequence ``seed``: image, lit lenses, lighting.

    Each frame draws from its own generator seeded by ``(seed, index)``, so a frame does not
    depend on the others and any subset renders identically.
    """
    rng = np.random.default_rng([int(seed), int(index), GENERATOR_VERSION])
    condition = frame_lighting(index, options)
    lit = LIGHTING[condition]
    scale = height / _BASE_HEIGHT
    horizon = height * rng.uniform(0.42, 0.6)
    canvas = Canvas(
        np.zeros((height, width, 3), np.float32),
        np.zeros((height, width, 3), np.float32),
        horizon,
        scale,
        [],
    )
    housings = place_signals(canvas, rng, options)
    draw_sky(canvas, rng, lit)
    draw_buildings(canvas, rng, lit)
    vx = draw_road(canvas, rng, lit)
    draw_trees(canvas, rng, lit)
    draw_cars(canvas, rng, lit, vx)
    draw_lamps(canvas, rng, lit, vx)
    if rng.random() < 0.5:
        draw_sign(canvas, rng, lit)
    annotations = draw_signals(canvas, rng, lit, housings)
    image = compress(expose(canvas, rng, lit), int(rng.integers(40, 76)))
    return image, annotations, condition


# --------------------------------------------------------------------------- datasets on disk


def _check_size(frames: int, width: int, height: int) -> None:
    if int(frames) < 1:
        raise ValueError(f"frames must be at least 1; got {frames!r}")
    if not (64 <= int(width) <= 8192 and 64 <= int(height) <= 8192):
        raise ValueError(f"width and height must be in 64..8192; got {width}x{height}")


def _stamp(frames: int, seed: int, width: int, height: int, options: SynthOptions) -> dict:
    return {
        "generator": "tsrkit.synth",
        "version": GENERATOR_VERSION,
        "frames": int(frames),
        "seed": int(seed),
        "width": int(width),
        "height": int(height),
        "options": {**asdict(options), "lighting": list(options.lighting)},
    }


def _read_stamp(folder: Path) -> dict | None:
    try:
        return json.loads((folder / STAMP_FILE).read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return None


def render_dataset(
    folder: Path, frames: int, seed: int, width: int, height: int, options: SynthOptions,
    on_frame: Callable[[], None] | None = None,
) -> Dataset:  # fmt: skip
    """Render every frame into ``folder/images`` and return the dataset (paths in ``folder``);
    ``on_frame`` is called after each frame (a progress bar's ``advance``)."""
    images = folder / "images"
    images.mkdir(parents=True, exist_ok=True)
    samples = []
    for index in range(frames):
        image, annotations, condition = render_frame(index, seed, width, height, options)
        path = images / f"{index:06d}.jpg"
        path.write_bytes(encode_jpeg(image, options.quality).tobytes())
        samples.append(
            Sample(
                str(path),
                tuple(annotations),
                width,
                height,
                frame_split(index, options),
                {"lighting": condition, "seed": int(seed), "frame": index},
            )
        )
        if on_frame is not None:
            on_frame()
    info = {
        "box_convention": "lens",
        "licence": "generated by tsrkit (MIT, as the code)",
        "generator_version": GENERATOR_VERSION,
        "seed": int(seed),
    }
    return Dataset(f"synth-{seed}", tuple(samples), "normalized", str(folder), info)


#: The annotation files of a generated set, and the dataset format each is written in.
ANNOTATION_FILES = {"annotations.json": "normalized", "coco.json": "coco"}


def write_annotations(dataset: Dataset, folder: Path) -> None:
    """Write the :data:`ANNOTATION_FILES` of ``dataset`` into ``folder``."""
    for file, format_name in ANNOTATION_FILES.items():
        write_dataset(dataset, format_name, folder / file)


def _relocate(dataset: Dataset, old: Path, new: Path) -> Dataset:
    """The same dataset with image paths moved from folder ``old`` to folder ``new``."""
    samples = tuple(
        replace(s, source=str(new / Path(s.source).relative_to(old))) for s in dataset.samples
    )
    info = {**dataset.info, "annotation_file": str(new / "annotations.json")}
    return replace(dataset, samples=samples, root=str(new), info=info)


def _open_permissions(folder: Path) -> None:
    """Make the folder 0755 and its top-level files 0644 (mkdtemp and mkstemp give 0700/0600)."""
    folder.chmod(0o755)
    for path in folder.iterdir():
        if path.is_file():
            path.chmod(0o644)


def _occupied(out: Path) -> TsrkitError:
    return TsrkitError(
        f"{out} already exists and holds other data; choose another folder "
        "or pass overwrite=True (--overwrite)"
    )


def _publish(tmp: Path, out: Path, stamp: dict, overwrite: bool) -> None:
    """Rename ``tmp`` to ``out``; a concurrent identical result is accepted as is."""
    try:
        os.rename(tmp, out)
        return
    except OSError:
        if not out.is_dir():
            raise
    if _read_stamp(out) == stamp:  # another process generated the same data first
        shutil.rmtree(tmp, ignore_errors=True)
        return
    if not overwrite:
        shutil.rmtree(tmp, ignore_errors=True)
        raise _occupied(out)
    trash = Path(tempfile.mkdtemp(prefix=f".{out.name}.old.", dir=out.parent))
    os.rename(out, trash / out.name)
    os.rename(tmp, out)
    shutil.rmtree(trash, ignore_errors=True)


def generate(
    out,
    frames: int,
    seed: int,
    width: int = 480,
    height: int = 356,
    overwrite: bool = False,
    on_frame: Callable[[], None] | None = None,
    **options,
) -> Dataset:
    """Render a synthetic dataset into the folder ``out`` and return it.

    Writes ``out/images/NNNNNN.jpg``, ``out/annotations.json`` (normalised JSON),
    ``out/coco.json`` and ``out/synth.json`` (the arguments). The folder is built beside
    ``out`` and renamed into place, so concurrent calls are safe; identical arguments give
    byte-identical files.

    Parameters
    ----------
    out : str or Path
        Output folder; must not exist (or be empty) unless it holds the same data or
        ``overwrite`` is true.
    frames : int
        Number of frames.
    seed : int
        Scene seed.
    width, height : int
        Frame size; geometry and lens radii scale with ``height / 356``.
    overwrite : bool
        Replace an existing folder that holds other data.
    on_frame : callable, optional
        Called after each rendered frame (progress).
    **options
        Fields of :class:`SynthOptions` (``lighting``, ``quality``, ``off_fraction``).

    Returns
    -------
    Dataset
        Samples with image paths inside ``out``; ``metadata["lighting"]`` per sample and
        ``split`` ``"train"`` or ``"test"``.

    Examples
    --------
    >>> ds = generate(tmp / "synth", frames=3, seed=1)  # doctest: +SKIP
    >>> [s.metadata["lighting"] for s in ds]            # doctest: +SKIP
    ['day', 'dusk', 'night']
    """
    _check_size(frames, width, height)
    try:
        opts = SynthOptions(**options)
    except TypeError as exc:
        raise ValueError(f"unknown synth option: {exc}") from None
    out = Path(out).expanduser().absolute()
    stamp = _stamp(frames, seed, width, height, opts)
    if out.is_dir() and any(out.iterdir()) and _read_stamp(out) != stamp and not overwrite:
        raise _occupied(out)
    out.parent.mkdir(parents=True, exist_ok=True)
    tmp = Path(tempfile.mkdtemp(prefix=f".{out.name}.", suffix=".tmp", dir=out.parent))
    try:
        dataset = render_dataset(
            tmp, int(frames), int(seed), int(width), int(height), opts, on_frame
        )
        write_annotations(dataset, tmp)
        (tmp / STAMP_FILE).write_text(json_text(stamp, indent=2) + "\n", encoding="utf-8")
        _open_permissions(tmp)
        _publish(tmp, out, stamp, overwrite)
    except BaseException:
        shutil.rmtree(tmp, ignore_errors=True)
        raise
    return _relocate(dataset, tmp, out)


def cache_dir() -> Path:
    """``$TSRKIT_CACHE_DIR`` or ``~/.cache/tsrkit``."""
    return Path(os.environ.get("TSRKIT_CACHE_DIR") or Path.home() / ".cache" / "tsrkit")


def sample_path() -> Path:
    """Path of ``annotations.json`` of the bundled sample, generating it on first use.

    The sample is 48 frames of seed 0 (16 each of day, dusk and night) in
    ``cache_dir()/sample-v<GENERATOR_VERSION>/``; racing processes are safe (see
    :func:`generate`).
    """
    folder = cache_dir() / f"sample-v{GENERATOR_VERSION}"
    target = folder / "annotations.json"
    if not target.is_file():
        generate(folder, SAMPLE_FRAMES, SAMPLE_SEED)
    return target
