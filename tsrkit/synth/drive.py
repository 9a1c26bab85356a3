"""A rendered drive through signalised intersections: the video, its GPS log, an OpenStreetMap
extract and per-frame ground truth, the test bed of Zheng 2016's spatiotemporal framework (3.4).

What is simulated
    A Manhattan grid of streets (blocks of ``block`` metres, roads 14 m wide with lane marks,
    stop lines and sidewalks, buildings with windows) seen by a pinhole camera 1.3 m above the
    right lane of a car that follows a route of through / left / right movements. The car
    cruises, slows for turns and stops at the stop line for a red (or a yellow it can stop
    for). Every signalised intersection has two vertical three-lens heads per approach on a mast
    arm 12 m past the junction centre, 5.5 m high; the two phases (north-south and east-west)
    cycle green, yellow, red (and an optional all-red clearance) on a known schedule with a
    per-intersection offset; on a chosen share of visits the driver ignores the signal and runs
    the amber or red (``run_share``). Heads facing the camera show their lit lens
    (``heads.render_head``); others show a dark housing. A box truck overtakes in the next lane
    on every leg and occludes heads (depth-tested). The camera adds pitch vibration, optical
    blur and sensor noise; the video is MPEG-4. The GPS log (CSV, 1 Hz) carries Gaussian
    position noise.

What is not simulated
    Lens distortion, rolling shutter, lighting other than day, heads seen at an angle (shown
    dark), pedestrian signals in the image (the map has one ``crossing=traffic_signals`` node
    that the framework must ignore), other traffic than the trucks.

Coordinates: metres east (x) and north (y) of the first intersection, projected to latitude and
longitude with :class:`tsrkit.geo.LocalProjection` about ``(lat0, lon0)``. Image coordinates
follow the COCO convention of :mod:`tsrkit.datasets.scenes` (pixel centres at ``i + 0.5``).
"""

from __future__ import annotations

import math
import os
from collections.abc import Iterator
from dataclasses import asdict, dataclass, field, replace
from pathlib import Path

import cv2
import numpy as np

from tsrkit.core.atomic import atomic_open, json_line, write_json
from tsrkit.datasets.scenes import LENS_BGR, add_glow
from tsrkit.geo.projection import LocalProjection
from tsrkit.spatiotemporal.points import frame_status
from tsrkit.synth.heads import LAMP_COLOURS, render_head
from tsrkit.synth.video import video_writer

__all__ = [
    "CAMERA_HEIGHT",
    "DIRECTIONS",
    "HALF_ROAD",
    "HEAD_HEIGHT",
    "HEAD_PAST",
    "LANE",
    "LENS_PITCH",
    "LENS_RADIUS",
    "MOVEMENTS",
    "SIDEWALK",
    "SKY_HORIZON",
    "SKY_TOP",
    "STATE_LENS",
    "STEP",
    "TURN_RADIUS",
    "Camera",
    "Drive",
    "DriveOptions",
    "Face",
    "Light",
    "Node",
    "Route",
    "Truck",
    "block_faces",
    "bloom",
    "build_route",
    "draw_signals",
    "drive_profile",
    "facade_colour",
    "gps_log",
    "ground_colour",
    "junctions",
    "light_state",
    "mark_runners",
    "osm_extract",
    "plan_drive",
    "plan_nodes",
    "plan_trucks",
    "render_drive",
    "render_frames",
    "render_scene",
    "summary",
    "to_latlon",
    "truck_faces",
]

MOVEMENTS = ("through", "left", "right")
#: Lane centre (m right of the street's centre line) the camera drives in; the trucks use 5.25.
LANE = 1.75
HALF_ROAD, SIDEWALK, HEAD_PAST = 7.0, 10.0, 12.0
CAMERA_HEIGHT, HEAD_HEIGHT, LENS_RADIUS = 1.3, 5.5, 0.15
#: Lens pitch along the housing (``render_head`` draws 2.8 radii per lens).
LENS_PITCH = 2.8 * LENS_RADIUS
TURN_RADIUS = {"left": 11.0, "right": 7.0}
STATE_LENS = {"red": 0, "yellow": 1, "green": 2}
DIRECTIONS = {"N": (0, 1), "E": (1, 0), "S": (0, -1), "W": (-1, 0)}
SKY_TOP, SKY_HORIZON = np.array((0.80, 0.62, 0.45)), np.array((0.93, 0.88, 0.82))


@dataclass(frozen=True)
class DriveOptions:
    """What to render (see the module notes).

    Parameters
    ----------
    route : tuple of str
        The movement at each intersection in turn; every one of them is signalised.
    random_nodes : int
        When > 0, a random route of this many intersections instead (60 % through), about
        ``signal_fraction`` of them signalised: the long drives of the benchmarks.
    light_offset : float or None
        Seconds into the signal cycle at time 0 for every intersection; None draws one each.
    green_s, yellow_s, all_red_s : float
        The signal timings: each phase shows green, then yellow (amber), then red; both phases
        show red for ``all_red_s`` after each yellow (the all-red clearance interval; 0 keeps
        the two-phase cycle ``2 * (green_s + yellow_s)``).
    run_share : float
        Share of the signalised traversals where the driver ignores the signal and keeps going
        (through an amber or a red, whatever it shows); drawn from its own random stream, so
        0 (the default) leaves every drive as it was.
    """

    width: int = 480
    height: int = 356
    fps: float = 14.0
    route: tuple[str, ...] = ("through",)
    random_nodes: int = 0
    signal_fraction: float = 0.6
    block: float = 150.0
    lead_m: float = 80.0
    tail_m: float = 40.0
    cruise: float = 12.0
    green_s: float = 10.0
    yellow_s: float = 3.0
    all_red_s: float = 0.0
    run_share: float = 0.0
    light_offset: float | None = None
    gps_noise_m: float = 1.0
    noise: float = 3.0
    vibration_px: float = 0.5
    trucks: bool = True
    lat0: float = 47.6
    lon0: float = -122.15
    start_utc: float = 1780315200.0  # 2026-06-01 12:00:00 UTC

    def __post_init__(self):
        if self.width < 64 or self.height < 48:
            raise ValueError(f"size must be at least 64x48; got {self.width}x{self.height}")
        if not 1 <= self.fps <= 120:
            raise ValueError(f"fps must be in 1..120; got {self.fps}")
        bad = [m for m in self.route if m not in MOVEMENTS]
        if bad or not (self.route or self.random_nodes):
            raise ValueError(f"route must be movements from {MOVEMENTS}; got {self.route!r}")
        if min(self.green_s, self.yellow_s) <= 0 or self.all_red_s < 0:
            raise ValueError("green_s and yellow_s must be > 0 and all_red_s >= 0")
        if not 0 <= self.run_share <= 1:
            raise ValueError(f"run_share must be in 0..1; got {self.run_share}")
        if self.block < 60:
            raise ValueError("block must be at least 60 m (signals merge within 50 m)")

    @property
    def focal(self) -> float:
        """Focal length in pixels: a horizontal field of view of about 58 degrees."""
        return 0.9 * self.width

    @property
    def cycle(self) -> float:
        """The signal cycle (s): two phases of green, yellow and all-red."""
        return 2 * (self.green_s + self.yellow_s + self.all_red_s)


@dataclass(frozen=True)
class Node:
    """A route intersection: grid indices, the direction driven in and out, the movement;
    ``runs`` when the driver ignores its signal on this visit."""

    i: int
    j: int
    into: str
    out: str
    movement: str
    signalised: bool
    offset: float
    runs: bool = False


@dataclass
class Route:
    """The car's lane path sampled every ``STEP`` metres, and the intersections it passes."""

    x: np.ndarray
    y: np.ndarray
    s: np.ndarray
    heading: np.ndarray
    limit: np.ndarray
    nodes: list[Node] = field(default_factory=list)
    stops: list[float] = field(default_factory=list)


STEP = 0.1


def _turn(direction: str, movement: str) -> str:
    order = "NESW"
    shift = {"through": 0, "right": 1, "left": -1}[movement]
    return order[(order.index(direction) + shift) % 4]


def plan_nodes(options: DriveOptions, rng: np.random.Generator) -> list[Node]:
    """The intersections of the route, driven north from the first one at (0, 0); a junction
    the route meets again keeps its signals and their offset."""
    if options.random_nodes:
        moves = rng.choice(MOVEMENTS, options.random_nodes, p=(0.6, 0.2, 0.2)).tolist()
        signals = (rng.random(len(moves)) < options.signal_fraction).tolist()
    else:
        moves, signals = list(options.route), [True] * len(options.route)
    cycle = options.cycle
    nodes, i, j, heading = [], 0, 0, "N"
    seen: dict[tuple[int, int], tuple[bool, float]] = {}  # a revisit meets the same junction
    for move, signalised in zip(moves, signals):
        out = _turn(heading, move)
        if (i, j) not in seen:
            offset = (
                options.light_offset if options.light_offset is not None else rng.uniform(0, cycle)
            )
            seen[i, j] = (bool(signalised), float(offset))
        signalised, offset = seen[i, j]
        nodes.append(Node(i, j, heading, out, str(move), signalised, offset))
        di, dj = DIRECTIONS[out]
        i, j, heading = i + di, j + dj, out
    return nodes


def mark_runners(options: DriveOptions, nodes: list[Node], seed: int) -> list[Node]:
    """``nodes`` with ``runs`` set on about ``options.run_share`` of the signalised visits,
    drawn from a stream of their own (the route's draws stay as they were)."""
    if not options.run_share:
        return nodes
    rng = np.random.default_rng((seed, 3 << 20))
    draws = rng.random(len(nodes))
    return [
        replace(node, runs=bool(node.signalised and draw < options.run_share))
        for node, draw in zip(nodes, draws)
    ]


def _right(direction: str) -> np.ndarray:
    dx, dy = DIRECTIONS[direction]
    return np.array((dy, -dx), float)


def build_route(options: DriveOptions, nodes: list[Node]) -> Route:
    """The lane path: straight legs between intersections, turns rounded with
    :data:`TURN_RADIUS`, sampled every :data:`STEP` m, with speed limits for the turns."""
    block = options.block
    first, last = nodes[0], nodes[-1]
    d0, d1 = np.array(DIRECTIONS[first.into], float), np.array(DIRECTIONS[last.out], float)
    start = np.array((first.i, first.j)) * block - options.lead_m * d0 + LANE * _right(first.into)
    end = np.array((last.i, last.j)) * block + options.tail_m * d1 + LANE * _right(last.out)
    pieces: list[np.ndarray] = [start[None]]
    limits: list[np.ndarray] = [np.array([options.cruise])]
    cursor = start
    for node in nodes:
        if node.movement == "through":
            continue
        a, b = np.array(DIRECTIONS[node.into], float), np.array(DIRECTIONS[node.out], float)
        corner = np.array((node.i, node.j)) * block + LANE * (_right(node.into) + _right(node.out))
        radius = TURN_RADIUS[node.movement]
        t1, t2 = corner - radius * a, corner + radius * b
        pieces.append(_segment(cursor, t1))
        limits.append(np.full(len(pieces[-1]), options.cruise))
        normal = np.array((-a[1], a[0])) if node.movement == "left" else np.array((a[1], -a[0]))
        centre = t1 + radius * normal
        start_angle = math.atan2(t1[1] - centre[1], t1[0] - centre[0])
        sweep = math.pi / 2 if node.movement == "left" else -math.pi / 2
        angles = start_angle + sweep * np.linspace(0, 1, int(radius * math.pi / 2 / STEP) + 1)[1:]
        pieces.append(centre + radius * np.column_stack([np.cos(angles), np.sin(angles)]))
        limits.append(np.full(len(angles), min(options.cruise, math.sqrt(2.5 * radius))))
        cursor = t2
    pieces.append(_segment(cursor, end))
    limits.append(np.full(len(pieces[-1]), options.cruise))
    points = np.concatenate(pieces)
    limit = np.concatenate(limits)
    step = np.hypot(*np.diff(points, axis=0).T)
    s = np.concatenate([[0.0], np.cumsum(step)])
    dx, dy = np.gradient(points[:, 0]), np.gradient(points[:, 1])
    for k in range(len(limit) - 2, -1, -1):  # brake ahead of a turn at 2.5 m/s^2
        limit[k] = min(limit[k], math.sqrt(limit[k + 1] ** 2 + 5.0 * step[k]))
    route = Route(points[:, 0], points[:, 1], s, np.arctan2(dy, dx), limit, nodes)
    for node in nodes:
        a = np.array(DIRECTIONS[node.into], float)
        along = (points - np.array((node.i, node.j)) * block) @ a
        near = np.hypot(*(points - np.array((node.i, node.j)) * block).T) < block / 2
        ahead = np.flatnonzero(near & (along >= -(HEAD_PAST + 1.0)))
        route.stops.append(float(s[ahead[0]]) if node.signalised and len(ahead) else math.inf)
    return route


def _segment(p: np.ndarray, q: np.ndarray) -> np.ndarray:
    n = max(int(np.hypot(*(q - p)) / STEP), 1)
    return p + (q - p) * np.linspace(0, 1, n + 1)[1:, None]


def light_state(options: DriveOptions, node: Node, approach: str, t: float) -> str:
    """The state shown to traffic driving in direction ``approach`` at ``t`` seconds: the
    north-south phase is green, yellow, then red while the east-west one is green and yellow
    (both red during the all-red intervals)."""
    g, y, cycle = options.green_s, options.yellow_s, options.cycle
    phase = (t + node.offset) % cycle
    if approach in "EW":
        phase = (phase + cycle / 2) % cycle
    return "green" if phase < g else "yellow" if phase < g + y else "red"


def drive_profile(options: DriveOptions, route: Route) -> tuple[np.ndarray, np.ndarray]:
    """Arc length and speed of the car at every frame: start at cruise speed, slow for turns,
    stop for a red or for a yellow it can stop for at 3.5 m/s^2 (unless the node ``runs``),
    pull away at 2 m/s^2."""
    dt = 1.0 / options.fps
    s, v, t = 0.0, float(route.limit[0]), 0.0
    positions, speeds = [], []
    end = float(route.s[-1])
    while s < end:
        positions.append(s)
        speeds.append(v)
        allowed = float(np.interp(s, route.s, route.limit))
        for node, stop in zip(route.nodes, route.stops):
            gap = stop - s
            if not 0 < gap < 60 or not math.isfinite(stop):
                continue
            if node.runs:
                break
            state = light_state(options, node, node.into, t)
            if state == "red" or (state == "yellow" and v * v / (2 * gap) < 3.5):
                allowed = min(allowed, math.sqrt(max(0.0, 6.0 * (gap - 0.5))))
            break
        v = min(v + 2.0 * dt, allowed) if allowed >= v else max(allowed, v - 6.0 * dt)
        s += v * dt
        t += dt
    return np.array(positions), np.array(speeds)


@dataclass(frozen=True)
class Camera:
    """A level pinhole camera: position (m), heading (radians counter-clockwise from east)."""

    x: float
    y: float
    heading: float
    focal: float
    width: int
    height: int

    @property
    def forward(self) -> np.ndarray:
        return np.array((math.cos(self.heading), math.sin(self.heading)))

    def project(self, point) -> tuple[float, float, float]:
        """Image ``(u, v)`` and depth along the optical axis of a world point ``(x, y, z)``."""
        dx, dy, dz = point[0] - self.x, point[1] - self.y, point[2] - CAMERA_HEIGHT
        f = self.forward
        depth = dx * f[0] + dy * f[1]
        side = dx * f[1] - dy * f[0]
        if depth <= 1e-6:
            return math.nan, math.nan, depth
        return (
            self.width / 2 + self.focal * side / depth,
            self.height / 2 - self.focal * dz / depth,
            depth,
        )

    def rays(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Per column the horizontal ray (x, y) with unit forward part, per row the drop."""
        a = (np.arange(self.width) + 0.5 - self.width / 2) / self.focal
        b = (np.arange(self.height) + 0.5 - self.height / 2) / self.focal
        f = self.forward
        return f[0] + a * f[1], f[1] - a * f[0], b


def _wave(x: np.ndarray, y: np.ndarray, seed: int) -> np.ndarray:
    """Smooth procedural texture in [-1, 1]: a few oblique sinusoids (no aliasing)."""
    rng = np.random.default_rng(seed)
    x, y = np.asarray(x, np.float32), np.asarray(y, np.float32)
    total = np.zeros(np.broadcast(x, y).shape, np.float32)
    for wavelength in (1.3, 2.9, 6.1):
        angle, phase = rng.uniform(0, math.pi), rng.uniform(0, 2 * math.pi)
        k = 2 * math.pi / wavelength
        total += np.sin(
            np.float32(k * math.cos(angle)) * x
            + np.float32(k * math.sin(angle)) * y
            + np.float32(phase)
        )
    return total / 3


def ground_colour(x: np.ndarray, y: np.ndarray, block: float) -> np.ndarray:
    """Asphalt, lane marks, stop lines and sidewalks at world points (BGR in [0, 1])."""
    dx, dy = x - block * np.round(x / block), y - block * np.round(y / block)
    ax, ay = np.abs(dx), np.abs(dy)
    road_ns, road_ew = ax < HALF_ROAD, ay < HALF_ROAD
    road = road_ns | road_ew
    junction = road_ns & road_ew
    grey = np.where(road, 0.36, np.where((ax < SIDEWALK) | (ay < SIDEWALK), 0.62, 0.5))
    grey = grey + 0.04 * _wave(x, y, 1)
    colour = np.repeat(grey[..., None], 3, axis=-1).astype(np.float32)
    centre = (road_ns & ~road_ew & (ax < 0.15)) | (road_ew & ~road_ns & (ay < 0.15))
    lane = (road_ns & ~road_ew & (np.abs(ax - 3.5) < 0.07) & (np.mod(y, 9.0) < 3.0)) | (
        road_ew & ~road_ns & (np.abs(ay - 3.5) < 0.07) & (np.mod(x, 9.0) < 3.0)
    )
    stop = ~junction & (
        (road_ns & (np.abs(ay - (HEAD_PAST - 0.5)) < 0.25) & (dx * dy < 0))
        | (road_ew & (np.abs(ax - (HEAD_PAST - 0.5)) < 0.25) & (dx * dy > 0))
    )
    colour[centre] = (0.2, 0.75, 0.85)
    colour[lane | stop] = 0.9
    return colour


def facade_colour(s: np.ndarray, z: np.ndarray, base: np.ndarray) -> np.ndarray:
    """A building face: its base colour, storeys of windows, a darker ground floor."""
    ws, wz = np.mod(s, 3.2), np.mod(z, 3.4)
    window = (ws > 0.9) & (ws < 2.5) & (wz > 1.1) & (wz < 2.7) & (z > 3.4)
    shade = 0.9 + 0.1 * _wave(s, z, 2)
    colour = base[None, :] * shade[:, None]
    colour[window] = (0.42, 0.36, 0.3)
    colour[z < 3.0] *= 0.7
    return colour.astype(np.float32)


@dataclass(frozen=True)
class Face:
    """A vertical rectangle: the plane ``axis = at`` (0: x, 1: y), ``lo..hi`` along the other
    axis, ``0..top`` high, a base colour."""

    axis: int
    at: float
    lo: float
    hi: float
    top: float
    colour: tuple[float, float, float]


def block_faces(i: int, j: int, block: float, seed: int, camera: Camera) -> list[Face]:
    """The faces of the building block north-east of grid node ``(i, j)`` that turn towards
    the camera."""
    rng = np.random.default_rng((seed, i + (1 << 20), j + (1 << 20)))
    x0, x1 = i * block + SIDEWALK, (i + 1) * block - SIDEWALK
    y0, y1 = j * block + SIDEWALK, (j + 1) * block - SIDEWALK
    top = float(rng.uniform(8, 30))
    red, green, blue = (float(c) for c in rng.uniform(0.35, 0.75, 3))
    colour = (red, green, blue)
    faces = []
    if camera.x < x0 or camera.x > x1:
        faces.append(Face(0, x0 if camera.x < x0 else x1, y0, y1, top, colour))
    if camera.y < y0 or camera.y > y1:
        faces.append(Face(1, y0 if camera.y < y0 else y1, x0, x1, top, colour))
    return faces


def truck_faces(cx: float, cy: float, direction: str) -> list[Face]:
    """A box truck 2.5 m wide, 8 m long and 3.8 m high centred at ``(cx, cy)``."""
    half = (4.0, 1.25) if direction in "EW" else (1.25, 4.0)
    x0, x1, y0, y1 = cx - half[0], cx + half[0], cy - half[1], cy + half[1]
    colour = (0.82, 0.84, 0.86)
    return [
        Face(0, x0, y0, y1, 3.8, colour),
        Face(0, x1, y0, y1, 3.8, colour),
        Face(1, y0, x0, x1, 3.8, colour),
        Face(1, y1, x0, x1, 3.8, colour),
    ]


def render_scene(camera: Camera, faces: list[Face], block: float) -> tuple[np.ndarray, np.ndarray]:
    """Sky, ground and faces by ray casting: the image (float BGR) and the depth per pixel."""
    rx, ry, drop = camera.rays()
    h, w = camera.height, camera.width
    rows = np.clip((np.arange(h) + 0.5) / (h / 2), 0, 1)[:, None, None]
    image = np.broadcast_to(SKY_TOP * (1 - rows) + SKY_HORIZON * rows, (h, w, 3)).astype(np.float32)
    depth = np.full((h, w), np.inf, np.float32)
    below = np.flatnonzero(drop > 1e-4)
    if len(below):
        t = (CAMERA_HEIGHT / drop[below])[:, None]
        gx, gy = camera.x + t * rx[None, :], camera.y + t * ry[None, :]
        image[below] = ground_colour(gx, gy, block)
        depth[below] = np.broadcast_to(t, gx.shape)
    position = (camera.x, camera.y)
    for face in faces:
        along = rx if face.axis == 0 else ry
        across = ry if face.axis == 0 else rx
        with np.errstate(divide="ignore", invalid="ignore"):
            t = (face.at - position[face.axis]) / along
        s = position[1 - face.axis] + t * across
        cols = np.flatnonzero((t > 0.3) & (s >= face.lo) & (s <= face.hi))
        if not len(cols):
            continue
        tc = t[cols]
        z = CAMERA_HEIGHT - tc[None, :] * drop[:, None]
        hit = (z >= 0) & (z <= face.top) & (tc[None, :] < depth[:, cols])
        if not hit.any():
            continue
        r, c = np.nonzero(hit)
        depth[r, cols[c]] = tc[c]
        image[r, cols[c]] = facade_colour(s[cols][c], z[r, c], np.array(face.colour))
    return image, depth


@dataclass(frozen=True)
class Light:
    """The lit lens of a head facing the camera, as ground truth of one frame."""

    id: str
    node: int
    approach: str
    state: str
    x: float
    y: float
    radius: float
    status: str
    visible: float

    @property
    def bbox(self) -> tuple[float, float, float, float]:
        return (
            self.x - self.radius,
            self.y - self.radius,
            self.x + self.radius,
            self.y + self.radius,
        )

    def to_json(self) -> dict:
        out = asdict(self)
        out.update({k: round(v, 3) for k, v in out.items() if isinstance(v, float)})
        out["bbox"] = [round(v, 3) for v in self.bbox]
        return out


def _window(box, shape) -> tuple[slice, slice]:
    h, w = shape[:2]
    x0, y0 = max(int(math.floor(box[0])), 0), max(int(math.floor(box[1])), 0)
    x1, y1 = min(int(math.ceil(box[2])), w), min(int(math.ceil(box[3])), h)
    return slice(y0, max(y1, y0)), slice(x0, max(x1, x0))


def _composite(image, layer, depth, box, at_depth) -> None:
    """Copy ``layer`` into ``image`` inside ``box`` where the scene lies behind ``at_depth``."""
    rows, cols = _window(box, depth.shape)
    mask = depth[rows, cols] > at_depth
    image[rows, cols][mask] = layer[rows, cols][mask]


def _unoccluded(depth, box, at_depth) -> float:
    """The share of ``box`` (inside the image) where the scene lies behind ``at_depth``."""
    rows, cols = _window(box, depth.shape)
    part = depth[rows, cols]
    return float((part > at_depth).mean()) if part.size else 0.0


def draw_signals(
    image: np.ndarray,
    depth: np.ndarray,
    camera: Camera,
    options: DriveOptions,
    nodes: list[tuple[int, Node]],
    t: float,
) -> list[Light]:
    """Poles, mast arms and heads of the given intersections, depth-tested; the lit lenses
    facing the camera as :class:`Light` ground truth."""
    lights = []
    layer = image.copy()
    for index, node in nodes:
        centre = np.array((node.i, node.j), float) * options.block
        for approach, (ux, uy) in DIRECTIONS.items():
            along, right = np.array((ux, uy), float), _right(approach)
            base = centre + HEAD_PAST * along
            pole = base + 9.0 * right
            arm = base + 1.0 * right
            p0, p1, p2 = (
                camera.project((*pole, 0.0)),
                camera.project((*pole, 6.3)),
                camera.project((*arm, 6.3)),
            )
            if min(p0[2], p1[2], p2[2]) > 1.0:
                thick = max(1, int(round(camera.focal * 0.25 / p0[2])))
                xs, ys = (p0[0], p1[0], p2[0]), (p0[1], p1[1], p2[1])
                if max(abs(v) for v in xs + ys) < 1e5:
                    cv2.line(
                        layer,
                        (int(xs[0]), int(ys[0])),
                        (int(xs[1]), int(ys[1])),
                        (64, 64, 64),
                        thick,
                    )
                    cv2.line(
                        layer,
                        (int(xs[1]), int(ys[1])),
                        (int(xs[2]), int(ys[2])),
                        (64, 64, 64),
                        max(1, thick - 1),
                    )
                    box = (min(xs) - thick, min(ys) - thick, max(xs) + thick, max(ys) + thick)
                    _composite(image, layer, depth, box, min(p0[2], p2[2]) - 0.5)
            to_camera = np.array((camera.x, camera.y)) - base
            facing = float(-along @ to_camera) / max(float(np.hypot(*to_camera)), 1e-6) > 0.5
            state = light_state(options, node, approach, t)
            for k, offset in enumerate((LANE, LANE + 3.5)):
                head = base + offset * right
                lit = STATE_LENS[state] if facing else 1
                u, v, d = camera.project((*head, HEAD_HEIGHT + (1 - lit) * LENS_PITCH))
                if not d > 1.0:
                    continue
                radius = camera.focal * LENS_RADIUS / d
                if radius < 0.5 or not (
                    -50 < u < camera.width + 50 and -200 < v < camera.height + 200
                ):
                    continue
                colour = LAMP_COLOURS[state] if facing else (50, 50, 52)
                drawn = render_head(
                    layer, (u, v), radius, lit=lit, colour=colour, white_core=facing
                )
                _composite(image, layer, depth, drawn.housing, d)
                if facing:
                    box = (u - radius, v - radius, u + radius, v + radius)
                    lights.append(
                        Light(
                            f"{index}{approach}{k}",
                            index,
                            approach,
                            state,
                            u,
                            v,
                            radius,
                            frame_status(u, v, radius, camera.width, camera.height),
                            _unoccluded(depth, box, d),
                        )
                    )
    return lights


@dataclass(frozen=True)
class Truck:
    """A truck overtaking in the next lane: where and when it starts, its direction."""

    x: float
    y: float
    direction: str
    t0: float
    speed: float

    def faces(self, t: float) -> list[Face]:
        if not 0 <= t - self.t0 <= 30:
            return []
        ux, uy = DIRECTIONS[self.direction]
        run = self.speed * (t - self.t0)
        return truck_faces(self.x + ux * run, self.y + uy * run, self.direction)


def plan_trucks(options: DriveOptions, route: Route, times: np.ndarray, xs, ys) -> list[Truck]:
    """One truck per leg, starting 15 m behind the leg's start when the car passes it."""
    if not options.trucks:
        return []
    starts = [(route.x[0], route.y[0], route.nodes[0].into)]
    for node in route.nodes:
        if node.movement != "through":
            centre = np.array((node.i, node.j)) * options.block
            starts.append((*(centre + LANE * _right(node.out)), node.out))
    trucks = []
    for x, y, direction in starts:
        k = int(np.argmin(np.hypot(xs - x, ys - y)))
        ux, uy = DIRECTIONS[direction]
        right = _right(direction)
        trucks.append(
            Truck(
                float(x - 15 * ux + 3.5 * right[0]),
                float(y - 15 * uy + 3.5 * right[1]),
                direction,
                float(times[k]),
                options.cruise + 3.0,
            )
        )
    return trucks


@dataclass
class Drive:
    """Everything about a drive but its pixels: route, per-frame poses, trucks."""

    options: DriveOptions
    seed: int
    route: Route
    x: np.ndarray
    y: np.ndarray
    heading: np.ndarray
    speed: np.ndarray
    trucks: list[Truck]

    @property
    def frames(self) -> int:
        return len(self.x)

    @property
    def times(self) -> np.ndarray:
        return np.arange(self.frames) / self.options.fps


def junctions(nodes: list[Node]) -> dict[Node, int]:
    """Each signalised junction once (its first visit) with that visit's route index."""
    first: dict[tuple[int, int], tuple[Node, int]] = {}
    for index, node in enumerate(nodes):
        if node.signalised:
            first.setdefault((node.i, node.j), (node, index))
    return dict(first.values())


def plan_drive(options: DriveOptions, seed: int = 0) -> Drive:
    """The route, the car's pose at every frame and the trucks (no rendering)."""
    rng = np.random.default_rng(seed)
    nodes = mark_runners(options, plan_nodes(options, rng), seed)
    route = build_route(options, nodes)
    s, speed = drive_profile(options, route)
    x, y = np.interp(s, route.s, route.x), np.interp(s, route.s, route.y)
    c = np.interp(s, route.s, np.cos(route.heading))
    n = np.interp(s, route.s, np.sin(route.heading))
    times = np.arange(len(s)) / options.fps
    trucks = plan_trucks(options, route, times, x, y)
    return Drive(options, seed, route, x, y, np.arctan2(n, c), speed, trucks)


def render_frames(drive: Drive) -> Iterator[tuple[np.ndarray, list[Light]]]:
    """Each frame's image (BGR uint8) and its lit lenses."""
    options = drive.options
    block = options.block
    signalised = list(junctions(drive.route.nodes).items())
    jitter = 0.0
    for k in range(drive.frames):
        rng = np.random.default_rng((drive.seed, k))
        t = k / options.fps
        camera = Camera(
            float(drive.x[k]),
            float(drive.y[k]),
            float(drive.heading[k]),
            options.focal,
            options.width,
            options.height,
        )
        ci, cj = int(math.floor(camera.x / block)), int(math.floor(camera.y / block))
        faces = [
            face
            for i in range(ci - 1, ci + 2)
            for j in range(cj - 1, cj + 2)
            for face in block_faces(i, j, block, drive.seed, camera)
        ]
        faces += [face for truck in drive.trucks for face in truck.faces(t)]
        scene, depth = render_scene(camera, faces, block)
        image = (np.clip(scene, 0, 1) * 255).astype(np.uint8)
        near = [
            (index, node)
            for node, index in signalised
            if math.hypot(node.i * block - camera.x, node.j * block - camera.y) < 160
        ]
        lights = draw_signals(image, depth, camera, options, near, t)
        image = cv2.GaussianBlur(bloom(image, lights), (0, 0), 0.6)
        jitter = 0.8 * jitter + float(rng.normal(0, options.vibration_px))
        shift = np.array([[1.0, 0.0, 0.0], [0.0, 1.0, jitter]], np.float32)
        image = cv2.warpAffine(
            image, shift, (options.width, options.height), borderMode=cv2.BORDER_REPLICATE
        )
        noisy = image + np.float32(options.noise) * rng.standard_normal(image.shape, np.float32)
        lights = [
            replace(
                light,
                y=light.y + jitter,
                status=frame_status(
                    light.x, light.y + jitter, light.radius, options.width, options.height
                ),
            )
            for light in lights
        ]
        yield np.clip(noisy, 0, 255).astype(np.uint8), lights


def bloom(image: np.ndarray, lights: list[Light]) -> np.ndarray:
    """Add the coloured halo a lit lamp spreads around its lens (``scenes.add_glow``, sigma
    1.2 radii), scaled by the lens's unoccluded share."""
    glow = np.zeros(image.shape, np.float32)
    for light in lights:
        if light.visible > 0:
            colour = np.asarray(LENS_BGR[light.state], np.float32) * light.visible
            add_glow(glow, light.x, light.y, colour, light.radius, 0.0, 1.2 * light.radius, 0.45)
    return np.clip(image + 255 * glow, 0, 255).astype(np.uint8)


def to_latlon(options: DriveOptions, x, y) -> tuple[np.ndarray, np.ndarray]:
    """Latitude and longitude of world metres (the inverse of the local projection)."""
    forward = LocalProjection(options.lat0, options.lon0)._forward
    lon, lat = forward.transform(np.asarray(x, float), np.asarray(y, float), direction="INVERSE")
    return np.asarray(lat), np.asarray(lon)


def gps_log(drive: Drive) -> str:
    """The 1 Hz GPS log (CSV ``time,lat,lon``, UTC seconds) with the position noise."""
    options = drive.options
    rng = np.random.default_rng((drive.seed, 1 << 20))
    seconds = np.arange(0, drive.times[-1] + 1e-9, 1.0)
    x = np.interp(seconds, drive.times, drive.x) + rng.normal(0, options.gps_noise_m, len(seconds))
    y = np.interp(seconds, drive.times, drive.y) + rng.normal(0, options.gps_noise_m, len(seconds))
    lat, lon = to_latlon(options, x, y)
    lines = ["time,lat,lon"] + [
        f"{options.start_utc + t:.1f},{a:.7f},{o:.7f}" for t, a, o in zip(seconds, lat, lon)
    ]
    return "\n".join(lines) + "\n"


def osm_extract(drive: Drive) -> str:
    """OpenStreetMap XML: a ``highway=traffic_signals`` node at every signalised intersection,
    a pedestrian ``crossing=traffic_signals`` node mid-way along the first leg, and plain
    nodes at the other intersections."""
    options = drive.options
    nodes = drive.route.nodes
    first = nodes[0]
    ux, uy = DIRECTIONS[first.into]
    grid = {(n.i, n.j): n.signalised for n in nodes}
    points = [
        (i * options.block, j * options.block, "highway" if signalised else None)
        for (i, j), signalised in grid.items()
    ]
    points.append((-ux * options.block / 2, -uy * options.block / 2, "crossing"))
    lat, lon = to_latlon(options, [p[0] for p in points], [p[1] for p in points])
    body = []
    for k, ((_, _, key), a, o) in enumerate(zip(points, lat, lon)):
        tag = f'<tag k="{key}" v="traffic_signals"/>' if key else ""
        body.append(f'  <node id="{100 + k}" lat="{a:.7f}" lon="{o:.7f}">{tag}</node>')
    return (
        '<?xml version="1.0" encoding="UTF-8"?>\n<osm version="0.6">\n'
        + "\n".join(body)
        + "\n</osm>\n"
    )


def summary(drive: Drive) -> dict:
    """``drive.json``: the options, the video's facts and the true traversals (the signalised
    intersections in route order, movement, approach and the frame closest to each)."""
    options = drive.options
    traversals = []
    after = 0  # route order: each visit's closest frame comes after the previous one's
    for index, node in enumerate(drive.route.nodes):
        cx, cy = node.i * options.block, node.j * options.block
        distance = np.hypot(drive.x[after:] - cx, drive.y[after:] - cy)
        near = np.flatnonzero(distance < options.block / 2)
        run = near[: int(np.argmax(np.diff(near) > 1)) + 1] if np.any(np.diff(near) > 1) else near
        closest = after + int(run[np.argmin(distance[run])]) if len(run) else after
        after = closest + 1
        if not node.signalised:
            continue
        lat, lon = to_latlon(options, [cx], [cy])
        traversals.append(
            {
                "node": index,
                "grid": [node.i, node.j],
                "lat": float(lat[0]),
                "lon": float(lon[0]),
                "movement": node.movement,
                "approach": node.into,
                "closest_frame": closest,
            }
        )
    return {
        "seed": drive.seed,
        "options": asdict(options),
        "fps": options.fps,
        "width": options.width,
        "height": options.height,
        "frames": drive.frames,
        "start_utc": options.start_utc,
        "traversals": traversals,
    }


def render_drive(
    out: str | os.PathLike, options: DriveOptions = DriveOptions(), seed: int = 0
) -> Path:
    """Write ``drive.mp4``, ``gps.csv``, ``map.osm``, ``truth.jsonl`` (per frame: time, pose
    and lit lenses with state, centre, radius, box, in-frame status and unoccluded share),
    ``drive.json`` (:func:`summary`) and the true timelines and events of each traversal,
    ``truth_timelines.csv`` and ``truth_events.csv`` (:mod:`tsrkit.synth.behaviour`), into the
    folder ``out``; returns the folder.

    Deterministic by ``seed`` (the pixels up to the MPEG-4 encoder).
    """
    folder = Path(out)
    folder.mkdir(parents=True, exist_ok=True)
    drive = plan_drive(options, seed)
    with (
        video_writer(folder / "drive.mp4", options.fps, (options.width, options.height)) as write,
        atomic_open(folder / "truth.jsonl") as truth,
    ):
        for k, (image, lights) in enumerate(render_frames(drive)):
            write(image)
            record = {
                "frame": k,
                "time": round(options.start_utc + k / options.fps, 4),
                "x": round(float(drive.x[k]), 3),
                "y": round(float(drive.y[k]), 3),
                "heading_deg": round(math.degrees(float(drive.heading[k])), 2),
                "speed": round(float(drive.speed[k]), 3),
                "lights": [light.to_json() for light in lights],
            }
            truth.write(json_line(record) + "\n")
    with atomic_open(folder / "gps.csv") as fh:
        fh.write(gps_log(drive))
    with atomic_open(folder / "map.osm") as fh:
        fh.write(osm_extract(drive))
    write_json(folder / "drive.json", summary(drive), indent=1)
    from tsrkit.synth.behaviour import write_truth  # it reads this module's drives

    write_truth(drive, folder)
    return folder
