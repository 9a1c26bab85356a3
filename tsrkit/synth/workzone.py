"""Work-zone road scenes with channelizers at known depths (Lee 2017, 3.5), for the channelizer
detector and depth from known height, which no open data set labels.

A pinhole camera (focal length ``focal_px``, no pitch or roll, ``camera_height_m`` above a flat
road) looks down a straight road. Vertical panels, 24 in tall and 10 in wide with 45-degree
orange and white stripes (MUTCD vertical panels, Lee's "channelizers"), stand on posts along
the lane edge at known depths; orange cones (no stripes), striped black-and-white barriers (no
orange), a diamond sign, cars, lane markings and buildings are the distractors. Every
annotation (state ``channelizer``) carries ``distance_m``; frames carry ``focal_px`` and
``horizon_y``. Deterministic from the seed.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import cv2
import numpy as np

from tsrkit.core.depth import PANEL_HEIGHT_M
from tsrkit.core.types import Annotation, Dataset, Sample

__all__ = [
    "ORANGE",
    "PANEL_BOTTOM_M",
    "PANEL_WIDTH_M",
    "STRIPE_M",
    "WHITE",
    "Camera",
    "generate",
    "render",
]

PANEL_WIDTH_M = 10 * 0.0254
#: Height of the panel's bottom edge above the road (its post), metres.
PANEL_BOTTOM_M = 0.3
STRIPE_M = 4 * 0.0254
ORANGE = (0, 110, 245)
WHITE = (235, 235, 235)


@dataclass(frozen=True)
class Camera:
    """A level pinhole camera ``height_m`` above the road; principal point at the centre."""

    width: int = 1280
    height: int = 720
    focal_px: float = 1100.0
    height_m: float = 1.4

    @property
    def centre(self) -> tuple[float, float]:
        return self.width / 2.0, self.height / 2.0

    def project(self, x: float, y_up: float, z: float) -> tuple[float, float]:
        """Image point of the road-frame point ``x`` right, ``y_up`` above the road, ``z`` ahead."""
        cx, cy = self.centre
        return cx + self.focal_px * x / z, cy + self.focal_px * (self.height_m - y_up) / z


def _poly(image: np.ndarray, points, colour) -> None:
    pts = np.round(np.asarray(points, np.float64) * 16).astype(np.int32)
    cv2.fillPoly(image, [pts], colour, cv2.LINE_AA, shift=4)


def _road(image: np.ndarray, camera: Camera, rng: np.random.Generator) -> None:
    h, w = image.shape[:2]
    cy = camera.centre[1]
    sky = np.linspace(235, 170, int(cy))[:, None, None] * np.array([1.0, 0.92, 0.8])
    image[: int(cy)] = sky.astype(np.uint8)
    image[int(cy) :] = (95, 98, 100)
    x = 0.0
    while x < w:  # buildings and trees along the horizon
        bw = rng.uniform(60, 220)
        top = cy - rng.uniform(20, 0.35 * h)
        colour = tuple(int(v) for v in rng.choice([(70, 80, 120), (150, 150, 155), (40, 90, 50)]))
        cv2.rectangle(image, (int(x), int(top)), (int(x + bw), int(cy)), colour, -1)
        x += bw + rng.uniform(0, 40)
    for lane_x in (-1.8, 1.8, 5.4):  # dashed lane markings, 3 m on, 9 m off
        for z0 in np.arange(rng.uniform(3, 12), 120, 12.0):
            corners = ((-0.07, 0), (0.07, 0), (0.07, 3), (-0.07, 3))
            quad = [camera.project(lane_x + dx, 0, z0 + dz) for dx, dz in corners]
            _poly(image, quad, (225, 225, 225))


def _panel(
    image: np.ndarray, camera: Camera, x: float, z: float, flip: bool
) -> tuple[float, float, float, float]:
    """Draw a channelizer at lateral ``x``, depth ``z``; return its panel box in pixels."""
    half = PANEL_WIDTH_M / 2
    top = PANEL_BOTTOM_M + PANEL_HEIGHT_M
    u0, v1 = camera.project(x - half, PANEL_BOTTOM_M, z)
    u1, v0 = camera.project(x + half, top, z)
    corners = ((-0.03, 0), (0.03, 0), (0.03, PANEL_BOTTOM_M), (-0.03, PANEL_BOTTOM_M))
    post = [camera.project(x + dx, up, z) for dx, up in corners]
    _poly(image, post, (60, 60, 60))
    scale = 8  # stripes drawn at 8x, then area-averaged into the panel box
    pw, ph = max(int(round((u1 - u0) * scale)), 2), max(int(round((v1 - v0) * scale)), 2)
    stripe = camera.focal_px * STRIPE_M / z * scale
    yy, xx = np.mgrid[0:ph, 0:pw]
    phase = ((xx if not flip else pw - xx) + yy) / (stripe * math.sqrt(2))
    big = np.where((np.floor(phase) % 2 == 0)[..., None], ORANGE, WHITE).astype(np.float32)
    _paste(image, big, u0, v0, u1, v1)
    return (u0, v0, u1, v1)


def _paste(image: np.ndarray, big: np.ndarray, u0, v0, u1, v1) -> None:
    """Area-resample ``big`` onto the sub-pixel box ``(u0, v0, u1, v1)`` of ``image``."""
    x0, y0 = int(math.floor(u0)), int(math.floor(v0))
    x1, y1 = int(math.ceil(u1)), int(math.ceil(v1))
    h, w = image.shape[:2]
    if x1 <= 0 or y1 <= 0 or x0 >= w or y0 >= h:
        return
    ph, pw = big.shape[:2]
    # Warp the patch onto the pixel grid with exact sub-pixel placement and coverage.
    matrix = np.array([[(u1 - u0) / pw, 0, u0 - x0], [0, (v1 - v0) / ph, v0 - y0]], np.float64)
    rgba = np.dstack([big, np.full((ph, pw), 255.0, np.float32)])
    small = cv2.warpAffine(
        cv2.resize(rgba, (pw, ph)), matrix, (x1 - x0, y1 - y0), flags=cv2.INTER_AREA
    )
    if small.ndim == 2:
        return
    cx0, cy0 = max(x0, 0), max(y0, 0)
    cx1, cy1 = min(x1, w), min(y1, h)
    part = small[cy0 - y0 : cy1 - y0, cx0 - x0 : cx1 - x0]
    alpha = part[..., 3:4] / 255.0
    region = image[cy0:cy1, cx0:cx1].astype(np.float32)
    image[cy0:cy1, cx0:cx1] = np.round(region * (1 - alpha) + part[..., :3] * alpha).astype(
        np.uint8
    )


def _cone(image: np.ndarray, camera: Camera, x: float, z: float) -> None:
    base = [camera.project(x - 0.18, 0, z), camera.project(x + 0.18, 0, z)]
    tip = camera.project(x, 0.7, z)
    _poly(image, [base[0], base[1], tip], ORANGE)


def _barrier(image: np.ndarray, camera: Camera, x: float, z: float) -> None:
    """A black-and-white striped barrier rail: diagonal edges without orange."""
    u0, v1 = camera.project(x - 1.0, 0.6, z)
    u1, v0 = camera.project(x + 1.0, 0.9, z)
    pw, ph = max(int((u1 - u0) * 4), 2), max(int((v1 - v0) * 4), 2)
    yy, xx = np.mgrid[0:ph, 0:pw]
    stripe = camera.focal_px * 0.15 / z * 4
    big = np.where((np.floor((xx + yy) / stripe) % 2 == 0)[..., None], (20, 20, 20), WHITE)
    _paste(image, big.astype(np.float32), u0, v0, u1, v1)


def render(
    rng: np.random.Generator, camera: Camera = Camera(), channelizers: tuple[int, int] = (2, 7)
) -> tuple[np.ndarray, tuple[Annotation, ...]]:
    """One work-zone frame: ``channelizers`` (a count range, default 2-6) panels along the lane
    edges at 5-60 m, distractors, camera noise; annotations of the panels with their
    ``distance_m``."""
    image = np.zeros((camera.height, camera.width, 3), np.uint8)
    _road(image, camera, rng)
    for _ in range(rng.integers(0, 3)):
        _cone(image, camera, rng.uniform(-4, 5), rng.uniform(6, 40))
    if rng.random() < 0.5:
        _barrier(image, camera, rng.uniform(-6, -3), rng.uniform(8, 30))
    placed = []
    depths = np.sort(rng.uniform(5.0, 60.0, rng.integers(*channelizers)))[
        ::-1
    ]  # far first (drawn under)
    for z in depths:
        x = rng.choice([2.2, -2.6]) + rng.uniform(-0.3, 0.3)
        box = _panel(image, camera, x, float(z), bool(rng.random() < 0.5))
        attributes = {"distance_m": float(z)}
        x0, y0, x1, y1 = (float(v) for v in box)
        placed.append(Annotation((x0, y0, x1, y1), "channelizer", attributes))
    noisy = image.astype(np.float32) + rng.normal(0, 3.0, image.shape)
    image = np.clip(noisy * rng.uniform(0.8, 1.1), 0, 255).astype(np.uint8)
    return image, tuple(placed)


def generate(frames: int = 50, seed: int = 0, camera: Camera = Camera()) -> Dataset:
    """``frames`` rendered work-zone frames as a data set (images in memory)."""
    rng = np.random.default_rng(seed)
    samples = []
    for i in range(frames):
        image, annotations = render(rng, camera)
        metadata = {"focal_px": camera.focal_px, "horizon_y": camera.centre[1]}
        samples.append(Sample(f"workzone/{seed}_{i:04d}", annotations, camera.width,
                              camera.height, None, metadata, image))  # fmt: skip
    info = {"boxes": "object", "exhaustive": True}
    return Dataset("workzone", tuple(samples), "synthetic", "", info)
