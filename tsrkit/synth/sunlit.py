"""Road scenes lit by a Sun at a known position, for the Sun-compensated colour model (Lee
2017, chapter 4), which no public data set supports (none records time, place and heading with
its colour labels).

Each frame is rendered in linear radiance, then exposed by a fixed camera (fixed exposure and
white balance, as Lee fixed his in 4.2) that clips each channel at saturation. A surface of
albedo ``rho`` facing the camera receives the Sun's light, tinted by Planck's law (Eq. 4.7) at a
colour temperature falling towards the horizon, times ``cos(theta_i)`` (the incident angle,
Eq. 4.9 with the camera facing the target), plus blue sky light; it reflects

* a diffuse **body** reflection ``rho (E_sun cos(theta_i) + E_sky)``,
* a **surface** (specular) reflection of the illuminant's own colour, ``k_s E_sun cos(theta_h)^n``
  over a sheen patch of the surface (Lee's Figure 4.8 labels such regions apart),
* a **retro**-reflection ``k_r rho E_sun exp(-(theta_o / 2 deg)^2)`` in the narrow cone of the
  observation angle (Figure 4.4).

Targets are orange work-zone diamonds (state ``orange``) and red stop octagons (``red``),
facing the camera; distractors are orange cones, a red car, brick facades, trees and a glare
veil when the camera looks towards a low Sun. On request a frame also holds traffic lights
(state ``light_red``, ``light_yellow`` or ``light_green``, boxed on the lit lens, the housing in
``attributes``): the lit lamp **emits** its colour whatever the Sun does, bright enough that its
core clips to white; the unlit lenses are dark tinted glass over a reflector, so with the Sun
behind the camera their retro-reflection makes them glow in their own colour (the "phantom"
lamps of Lee 4.1.2). And channelizers (state ``channelizer``): Lee 3.5's vertical panels, 45-degree
orange and retro-reflective white stripes on a post. Some signs are partly shaded by a pole or a
building (Lee's Figure 4.11). Frames carry the metadata the model reads: ``utc``, ``lat``,
``lon``, ``heading_deg`` (and, for checking, ``relative_azimuth_deg_true``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from datetime import UTC, datetime

import cv2
import numpy as np

from tsrkit.core.types import Annotation, Dataset, Sample
from tsrkit.sun.geometry import sun_position
from tsrkit.sun.radiance import blackbody_bgr

__all__ = [
    "ALBEDO",
    "DEFAULT_PLACE",
    "EXPOSURE",
    "LENSES",
    "Illumination",
    "Layers",
    "expose",
    "illumination",
    "render_frame",
    "sweep",
]

#: Albedos (B, G, R) of the painted or sheeted surfaces.
ALBEDO = {
    "orange": (0.05, 0.32, 0.85),
    "red": (0.06, 0.05, 0.62),
    "white": (0.8, 0.8, 0.8),
    "black": (0.04, 0.04, 0.04),
    "brick": (0.14, 0.2, 0.42),
    "asphalt": (0.11, 0.11, 0.12),
    "grass": (0.06, 0.3, 0.14),
    "tree": (0.05, 0.2, 0.09),
    "pole": (0.3, 0.3, 0.3),
    "car_red": (0.05, 0.04, 0.5),
    "concrete": (0.45, 0.47, 0.5),
    "housing": (0.05, 0.05, 0.05),
}
#: Traffic-light lenses by state: (BGR emission when lit, BGR albedo of the unlit tinted glass).
LENSES = {
    "light_red": ((0.12, 0.25, 3.0), (0.02, 0.02, 0.12)),
    "light_yellow": ((0.2, 1.6, 3.0), (0.02, 0.08, 0.14)),
    "light_green": ((2.2, 3.0, 0.5), (0.1, 0.12, 0.03)),
}
#: Pittsburgh, near Lee's test route (4.4.1).
DEFAULT_PLACE = (40.4433, -79.9436)
#: Camera exposure: a white surface lit head-on by a high Sun gives about 1.25 (saturated).
EXPOSURE = 1.7


@dataclass(frozen=True)
class Illumination:
    """What lights a frame: Sun and sky irradiance (BGR, camera units before exposure), the
    Sun's elevation and its azimuth relative to the camera (Lee 4.2, degrees)."""

    sun: np.ndarray
    sky: np.ndarray
    elevation: float
    relative_azimuth: float

    @property
    def incidence_cos(self) -> float:
        """``cos(theta_i)`` on a surface facing the camera: ``cos(elevation) cos(rel)``."""
        return math.cos(math.radians(self.elevation)) * math.cos(
            math.radians(self.relative_azimuth)
        )


def illumination(elevation: float, relative_azimuth: float) -> Illumination:
    """Sun and sky light for a Sun at ``elevation`` degrees: the Sun dims and reddens through
    more air mass near the horizon (colour temperature 5800 K high, about 3300 K at the
    horizon); the sky is a 12000 K black body of a fifth of the high Sun's strength."""
    el = max(elevation, 0.0)
    strength = math.exp(-0.25 / max(math.sin(math.radians(el)), 0.05)) / math.exp(-0.25)
    temperature = 5800.0 - 2500.0 * math.exp(-el / 10.0)
    sun = strength * blackbody_bgr(temperature) if elevation > 0 else np.zeros(3)
    sky = (0.08 + 0.14 * min(el, 30.0) / 30.0) * blackbody_bgr(12000.0)
    return Illumination(sun, sky, elevation, relative_azimuth)


def _polygon(kind: str, cx: float, cy: float, half: float) -> np.ndarray:
    if kind == "orange":  # diamond
        points = [(cx, cy - half), (cx + half, cy), (cx, cy + half), (cx - half, cy)]
    else:  # octagon
        points = [
            (cx + half * math.cos(a), cy + half * math.sin(a))
            for a in np.radians(np.arange(22.5, 360.0, 45.0))
        ]
    return np.array(points, np.float64)


class Layers:
    """The linear scene description of one frame: albedo, surface kind and shading per pixel."""

    SKY, FACING, GROUND = 0, 1, 2

    def __init__(self, height: int, width: int):
        self.albedo = np.zeros((height, width, 3), np.float32)
        self.kind = np.zeros((height, width), np.uint8)
        self.lit = np.ones((height, width), np.float32)
        self.sheen = np.zeros((height, width), np.float32)
        self.retro = np.zeros((height, width), np.float32)
        self.emit = np.zeros((height, width, 3), np.float32)

    def fill(self, points: np.ndarray, albedo, kind: int, **extra: float) -> np.ndarray:
        """Paint a polygon (x, y vertices) and return its mask."""
        mask = np.zeros(self.kind.shape, np.uint8)
        cv2.fillPoly(mask, [np.round(points * 8).astype(np.int32)], 1, cv2.LINE_8, shift=3)
        on = mask.astype(bool)
        self.albedo[on] = albedo
        self.kind[on] = kind
        self.lit[on] = 1.0
        self.sheen[on] = extra.get("sheen", 0.0)
        self.retro[on] = extra.get("retro", 0.0)
        return on


def _box(x0, y0, x1, y1) -> np.ndarray:
    return np.array([(x0, y0), (x1, y0), (x1, y1), (x0, y1)], np.float64)


def _background(layers: Layers, rng: np.random.Generator, horizon: int) -> None:
    height, width = layers.kind.shape
    layers.fill(_box(0, horizon, width, height), ALBEDO["asphalt"], Layers.GROUND)
    layers.fill(_box(0, horizon, width * 0.18, height), ALBEDO["grass"], Layers.GROUND)
    x = -rng.uniform(0, 60)
    while x < width:
        w = rng.uniform(60, 180)
        top = horizon - rng.uniform(40, 0.45 * height)
        material = ["brick", "concrete", "tree"][rng.integers(3)]
        layers.fill(_box(x, top, x + w, horizon + 2), ALBEDO[material], Layers.FACING)
        x += w + rng.uniform(0, 50)


def _cone(layers: Layers, rng: np.random.Generator, horizon: int) -> None:
    height, width = layers.kind.shape
    y = rng.uniform(horizon + 20, height - 5)
    size = 6 + 40 * (y - horizon) / (height - horizon)
    x = rng.uniform(0.15 * width, 0.95 * width)
    tri = np.array([(x, y - 2.2 * size), (x + size / 2, y), (x - size / 2, y)])
    layers.fill(tri, ALBEDO["orange"], Layers.FACING, sheen=0.3)
    layers.fill(_box(x - size / 3, y - 1.3 * size, x + size / 3, y - 1.0 * size),
                ALBEDO["white"], Layers.FACING)  # fmt: skip


def _car(layers: Layers, rng: np.random.Generator, horizon: int) -> None:
    width = layers.kind.shape[1]
    w = rng.uniform(80, 200)
    x = rng.uniform(0.2 * width, 0.9 * width - w)
    y = horizon + rng.uniform(10, 50)
    layers.fill(_box(x, y - 0.55 * w, x + w, y), ALBEDO["car_red"], Layers.FACING, sheen=0.6)
    layers.fill(_box(x + 0.12 * w, y - 0.5 * w, x + 0.88 * w, y - 0.3 * w), ALBEDO["black"],
                Layers.FACING, sheen=0.8)  # fmt: skip


def _sign(
    layers: Layers, rng: np.random.Generator, kind: str, cx: float, cy: float, half: float
) -> Annotation:
    height = layers.kind.shape[0]
    layers.fill(_box(cx - 2, cy, cx + 2, min(height, cy + 5 * half)), ALBEDO["pole"], Layers.FACING)
    outline = _polygon(kind, cx, cy, half)
    if kind == "red":
        layers.fill(outline, ALBEDO["white"], Layers.FACING, sheen=0.5, retro=0.6)
        face = _polygon(kind, cx, cy, 0.88 * half)
    else:
        layers.fill(outline, ALBEDO["black"], Layers.FACING, sheen=0.5)
        face = _polygon(kind, cx, cy, 0.9 * half)
    on = layers.fill(face, ALBEDO[kind], Layers.FACING, retro=0.6)
    # A sheen band: part of the face shows the surface reflection (Lee's Figure 4.8).
    yy, xx = np.nonzero(on)
    angle = rng.uniform(0, np.pi)
    band = (
        np.abs((xx - cx) * np.cos(angle) + (yy - cy) * np.sin(angle)) < rng.uniform(0.2, 0.6) * half
    )
    layers.sheen[yy, xx] = np.where(band, rng.uniform(0.5, 1.0), 0.1)
    legend = (cx - 0.12 * half, cy - 0.35 * half, cx + 0.12 * half, cy + 0.35 * half)
    layers.fill(_box(*legend), ALBEDO["black" if kind == "orange" else "white"], Layers.FACING,
                sheen=0.2)  # fmt: skip
    if rng.random() < 0.15:  # a shadow of a pole or a building over part of the sign
        x_cut = cx + rng.uniform(-0.6, 0.6) * half
        shade = np.zeros_like(on)
        shade[:, : max(int(x_cut), 0)] = True
        layers.lit[on & shade] = 0.0
    x0, y0 = outline.min(axis=0)
    x1, y1 = outline.max(axis=0)
    return Annotation(
        (float(x0), float(y0), float(x1), float(y1)), kind, {"polygon": outline.round(2).tolist()}
    )


def _traffic_light(
    layers: Layers, rng: np.random.Generator, cx: float, cy: float, radius: float
) -> Annotation:
    """A vertical three-lens head (red, yellow, green from the top) whose lens ``lit`` (drawn at
    random) emits; ``(cx, cy)`` is the centre of the middle lens. Returns the lit lens's box."""
    height = layers.kind.shape[0]
    pitch = 2.8 * radius
    housing = _box(cx - pitch / 2, cy - 1.5 * pitch, cx + pitch / 2, cy + 1.5 * pitch)
    layers.fill(_box(cx - 2, cy + 1.5 * pitch, cx + 2, height), ALBEDO["pole"], Layers.FACING)
    layers.fill(housing, ALBEDO["housing"], Layers.FACING, sheen=0.3)
    states = list(LENSES)
    lit = states[rng.integers(len(states))]
    box: tuple[float, float, float, float] = (0.0, 0.0, 0.0, 0.0)
    for k, state in enumerate(states):
        y = cy + (k - 1) * pitch
        angles = np.radians(np.arange(0.0, 360.0, 15.0))
        disc = np.stack([cx + radius * np.cos(angles), y + radius * np.sin(angles)], axis=1)
        emission, glass = LENSES[state]
        on = layers.fill(disc, glass, Layers.FACING, sheen=0.9, retro=1.0)
        if state == lit:  # brighter at the centre: a clipped white core, a coloured rim
            yy, xx = np.nonzero(on)
            falloff = 1.0 - 0.6 * ((xx - cx) ** 2 + (yy - y) ** 2) / radius**2
            layers.emit[yy, xx] = np.asarray(emission, np.float32) * falloff[:, None]
            box = (cx - radius, y - radius, cx + radius, y + radius)
    corners = [float(v) for v in (*housing.min(axis=0), *housing.max(axis=0))]
    return Annotation(box, lit, {"object": "traffic_light", "housing": corners})


def _channelizer(
    layers: Layers, rng: np.random.Generator, cx: float, bottom: float, panel_h: float
) -> Annotation:
    """Lee 3.5's vertical panel (24 x 10 in) on a post standing at image row ``bottom``: 45-degree
    orange and white stripes (4 in wide), both retro-reflective sheeting."""
    panel_w = panel_h * 10.0 / 24.0
    top = bottom - 1.3 * panel_h
    layers.fill(_box(cx - 1.5, top + panel_h, cx + 1.5, bottom), ALBEDO["pole"], Layers.FACING)
    on = layers.fill(
        _box(cx - panel_w / 2, top, cx + panel_w / 2, top + panel_h),
        ALBEDO["white"], Layers.FACING, sheen=0.4, retro=0.8,
    )  # fmt: skip
    yy, xx = np.nonzero(on)
    stripe = panel_h * 4.0 / 24.0 * math.sqrt(2.0)
    flip = 1.0 if rng.random() < 0.5 else -1.0
    orange = np.floor((flip * (xx - cx) + (yy - top)) / stripe) % 2 == 0
    layers.albedo[yy[orange], xx[orange]] = ALBEDO["orange"]
    box = (float(cx - panel_w / 2), float(top), float(cx + panel_w / 2), float(top + panel_h))
    return Annotation(box, "channelizer", {"object": "channelizer"})


def expose(layers: Layers, light: Illumination, rng: np.random.Generator) -> np.ndarray:
    """Radiance of every pixel, through the fixed camera: exposure, clipping at saturation,
    sensor noise and the sRGB-like gamma; BGR uint8."""
    height = layers.kind.shape[0]
    cos_i = max(light.incidence_cos, 0.0)
    theta_i = math.degrees(math.acos(min(max(light.incidence_cos, -1.0), 1.0)))
    half_angle_cos = math.cos(math.radians(theta_i / 2)) if light.incidence_cos > 0 else 0.0
    ground_cos = max(math.sin(math.radians(light.elevation)), 0.0)
    direct = (
        np.where(layers.kind == Layers.GROUND, ground_cos, cos_i)[..., None] * layers.lit[..., None]
    )
    body = layers.albedo * (light.sun * direct + light.sky)
    surface = 0.5 * layers.sheen[..., None] * light.sun * direct * half_angle_cos**40
    retro = (
        2.0
        * layers.retro[..., None]
        * layers.albedo
        * light.sun
        * direct
        * math.exp(-((theta_i / 2.0) ** 2))
    )
    rows = np.linspace(1.0, 0.6, height, dtype=np.float32)[:, None, None]
    sky = (light.sky * 3.0 + 0.15 * light.sun) * rows
    radiance = np.where((layers.kind == Layers.SKY)[..., None], sky, body + surface + retro)
    radiance = radiance + layers.emit
    # Looking towards a low Sun: a veil of scattered light over the whole frame (Lee 4.4.2).
    into_sun = max(-math.cos(math.radians(light.relative_azimuth)), 0.0) ** 4
    veil = 0.5 * into_sun * math.exp(-max(light.elevation, 0.0) / 20.0) * light.sun
    signal = EXPOSURE * (radiance + veil)
    signal = cv2.GaussianBlur(signal.astype(np.float32), (0, 0), 0.7)
    signal = signal + rng.normal(0.0, 0.008, signal.shape).astype(np.float32)
    return np.round(255.0 * np.clip(signal, 0.0, 1.0) ** (1 / 2.2)).astype(np.uint8)


def render_frame(
    rng: np.random.Generator, light: Illumination, width: int = 640, height: int = 480,
    lights: int = 0, channelizers: int = 0,
) -> tuple[np.ndarray, tuple[Annotation, ...]]:  # fmt: skip
    """One frame with one to three signs (orange diamonds and red octagons) and distractors,
    plus ``lights`` traffic lights hanging above the road and ``channelizers`` panels along its
    edge (drawn after the rest, so a frame without them is the frame rendered before they
    existed)."""
    layers = Layers(height, width)
    horizon = int(height * rng.uniform(0.42, 0.52))
    _background(layers, rng, horizon)
    for _ in range(rng.integers(0, 3)):
        _cone(layers, rng, horizon)
    if rng.random() < 0.5:
        _car(layers, rng, horizon)
    annotations = []
    for slot in rng.permutation(3)[: rng.integers(1, 4)]:
        kind = "orange" if rng.random() < 0.6 else "red"
        half = rng.uniform(12, 40)
        cx = (slot + rng.uniform(0.25, 0.75)) * width / 3
        cy = horizon - rng.uniform(0.5, 2.5) * half
        annotations.append(_sign(layers, rng, kind, cx, cy, half))
    for _ in range(lights):
        radius = rng.uniform(3.0, 9.0)
        cx = rng.uniform(0.1, 0.9) * width
        cy = rng.uniform(0.1, 0.8) * (horizon - 5 * radius) + 1.5 * 2.8 * radius
        annotations.append(_traffic_light(layers, rng, cx, cy, radius))
    for _ in range(channelizers):
        bottom = rng.uniform(horizon + 15, height - 5)
        panel_h = 8 + 60 * (bottom - horizon) / (height - horizon)
        cx = rng.uniform(0.1, 0.9) * width
        annotations.append(_channelizer(layers, rng, cx, bottom, panel_h))
    return expose(layers, light, rng), tuple(annotations)


def sweep(
    relative_azimuths, frames_each: int = 8, seed: int = 0, width: int = 640, height: int = 480,
    day: str = "2016-06-20", place: tuple[float, float] = DEFAULT_PLACE, split: str | None = None,
    lights: int = 0, channelizers: int = 0,
) -> Dataset:  # fmt: skip
    """Lee's 4.2 protocol as a data set: for each relative azimuth, ``frames_each`` frames at
    hours through ``day`` (so at the Sun's elevations of that day), the camera heading turned
    so that the Sun lies at that relative azimuth. Frames with the Sun below the horizon are
    not rendered. Each sample's metadata holds ``utc``, ``lat``, ``lon``, ``heading_deg``;
    ``lights`` and ``channelizers`` are passed to :func:`render_frame`."""
    rng = np.random.default_rng(seed)
    lat, lon = place
    start = datetime.fromisoformat(day).replace(tzinfo=UTC).timestamp()
    samples = []
    for rel in relative_azimuths:
        done = 0
        while done < frames_each:
            utc = start + rng.uniform(10.0, 24.0) * 3600.0 + 4.0 * 3600.0 * (lon < -30)
            azimuth, elevation = (float(v) for v in sun_position(utc, lat, lon))
            if elevation < 5.0:
                continue
            heading = (azimuth + 180.0 - rel * rng.choice([-1.0, 1.0])) % 360.0
            image, annotations = render_frame(
                rng, illumination(elevation, rel), width, height, lights, channelizers
            )
            stamp = datetime.fromtimestamp(utc, UTC).isoformat().replace("+00:00", "Z")
            metadata = {
                "utc": stamp, "lat": lat, "lon": lon, "heading_deg": round(float(heading), 3),
                "relative_azimuth_deg_true": float(rel), "sun_elevation_deg": elevation,
            }  # fmt: skip
            samples.append(Sample(f"sunlit/rel{rel:05.1f}_{done:03d}", annotations, width, height,
                                  split, metadata, image))  # fmt: skip
            done += 1
    return Dataset(
        "sunlit", tuple(samples), "synthetic", "", {"boxes": "object", "exhaustive": True}
    )
