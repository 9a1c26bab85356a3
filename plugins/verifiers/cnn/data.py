"""Training crops: a detector's candidates on labelled scenes, cut wide and labelled.

Each candidate is labelled by Zheng's centre rule (2016, 5.2.1: its centre lies in the minimum
enclosing circle of a ground-truth box of its frame, :func:`tsrkit.api.centre_hits`):

- **light** 1 when it hits a box; 0 when it hits none on an exhaustively labelled scene; on a
  scene that is not exhaustively labelled (DTLD, Japan, Traffic-pi: unboxed far, side-facing
  and pedestrian heads) only a candidate in the lowest :data:`LOW_BAND` of the rows that hits
  no box is a negative (brake lights, reflections on the road and cars; no signal head hangs
  there), every other unboxed candidate is left out, so that an unlabelled light is never
  taught as a negative;
- **box**: the hit box in window units (:mod:`.windows`) when it boxes a housing (long side at
  least :data:`HOUSING_ASPECT` times the short side; a lens box, as KR's, gives none: NaN);
- **state**: the index in :data:`STATE_NAMES` of the hit box's state, -1 when unknown.

A candidate hitting several boxes takes the one whose centre is nearest.
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from dataclasses import dataclass

import numpy as np

from tsrkit.api import Candidate, Detector, Frame, centre_hits
from tsrkit_plugins.verifiers.cnn.windows import INPUT, TRAIN_MARGIN, Window, crops

#: The states the network reads, in the order of its state output.
STATE_NAMES = ("red", "yellow", "green", "red_yellow", "off")
#: A box this elongated boxes a housing (a lens box is about square).
HOUSING_ASPECT = 1.5
#: On scenes not exhaustively labelled, unboxed candidates below this share of the rows from
#: the top are negatives.
LOW_BAND = 0.65


@dataclass(frozen=True)
class Scene:
    """A labelled frame: its boxes and their states, and whether every lit light is boxed."""

    frame: Frame
    boxes: Sequence[Sequence[float]]
    states: Sequence[str | None]
    exhaustive: bool = True
    camera: str = ""


@dataclass
class CropSet:
    """Training crops (``(N, S, S, 3)`` uint8, :data:`~.windows.TRAIN_MARGIN` times the
    window) and their labels: light (1/0), box (window units of the inner window, NaN when
    unknown), state (index or -1), the scene index and the camera of each."""

    crops: np.ndarray
    light: np.ndarray
    box: np.ndarray
    state: np.ndarray
    scene: np.ndarray
    camera: np.ndarray

    @classmethod
    def concat(cls, parts: Sequence[CropSet]) -> CropSet:
        """All parts stacked (empty when there are none)."""
        if not parts:
            size = int(round(INPUT * TRAIN_MARGIN))
            return cls(
                np.zeros((0, size, size, 3), np.uint8),
                np.zeros(0, np.int8),
                np.zeros((0, 4), np.float32),
                np.zeros(0, np.int8),
                np.zeros(0, np.int32),
                np.zeros(0, "<U16"),
            )
        return cls(*(np.concatenate([getattr(p, f) for p in parts]) for f in cls.fields()))

    @staticmethod
    def fields() -> tuple[str, ...]:
        """The array fields, in order."""
        return ("crops", "light", "box", "state", "scene", "camera")

    def take(self, rows: np.ndarray) -> CropSet:
        """The rows ``rows`` of every field."""
        return CropSet(*(getattr(self, f)[rows] for f in self.fields()))

    def __len__(self) -> int:
        return len(self.light)


def state_index(state: str | None) -> int:
    """The index of ``state`` in :data:`STATE_NAMES`, -1 when it is none of them.

    Examples
    --------
    >>> state_index("green"), state_index("red_yellow"), state_index("unknown")
    (2, 3, -1)
    """
    return STATE_NAMES.index(state) if state in STATE_NAMES else -1


def label(scene: Scene, candidates: Sequence[Candidate]) -> tuple[np.ndarray, np.ndarray]:
    """Each candidate's light label (1, 0, or -1: left out) and the index of the box it hits
    (-1 for none), by the rules of this module."""
    n = len(candidates)
    height = scene.frame.image.shape[0]
    hit_box = np.full(n, -1)
    if scene.boxes and n:
        centres = [(c.x, c.y) for c in candidates]
        hits = np.asarray(centre_hits(centres, scene.boxes))
        boxes = np.asarray(scene.boxes, float).reshape(-1, 4)
        mid = (boxes[:, :2] + boxes[:, 2:]) / 2.0
        distance = np.hypot(*(np.asarray(centres)[:, None, :] - mid[None]).transpose(2, 0, 1))
        distance[~hits] = np.inf
        hit_box = np.where(hits.any(axis=1), distance.argmin(axis=1), -1)
    light = np.where(hit_box >= 0, 1, 0).astype(np.int8)
    if not scene.exhaustive:
        low = np.array([c.y >= LOW_BAND * height for c in candidates], bool)
        light[(hit_box < 0) & ~low] = -1
    return light, hit_box


def housing_target(window: Window, box: Sequence[float]) -> np.ndarray:
    """``box`` in units of the inner window of a training cut ``window`` (NaN when ``box``
    is not elongated enough to box a housing)."""
    w, h = box[2] - box[0], box[3] - box[1]
    if max(w, h) < HOUSING_ASPECT * max(min(w, h), 1e-6):
        return np.full(4, np.nan, np.float32)
    inner = window.side / TRAIN_MARGIN
    x0 = window.x0 + (window.side - inner) / 2.0
    y0 = window.y0 + (window.side - inner) / 2.0
    b = np.asarray(box, np.float64)
    return ((b - [x0, y0, x0, y0]) / inner).astype(np.float32)


def scene_crops(scene: Scene, candidates: Sequence[Candidate], index: int) -> CropSet:
    """The labelled training crops of one scene's candidates (those left out dropped)."""
    light, hit_box = label(scene, candidates)
    keep = np.flatnonzero(light >= 0)
    kept = [candidates[int(i)] for i in keep]
    batch, windows = crops(scene.frame.image, kept, TRAIN_MARGIN)
    box = np.full((len(kept), 4), np.nan, np.float32)
    state = np.full(len(kept), -1, np.int8)
    for row, (i, window) in enumerate(zip(keep, windows)):
        if hit_box[i] >= 0:
            box[row] = housing_target(window, scene.boxes[hit_box[i]])
            state[row] = state_index(scene.states[hit_box[i]])
    return CropSet(
        batch,
        light[keep],
        box,
        state,
        np.full(len(kept), index, np.int32),
        np.full(len(kept), scene.camera, "<U16"),
    )


def collect(scenes: Iterable[Scene], detector: Detector, start: int = 0) -> CropSet:
    """Run ``detector`` on every scene and return the labelled crops of its candidates
    (scene indices counted from ``start``)."""
    parts = []
    for index, scene in enumerate(scenes, start):
        candidates = detector.detect(scene.frame)
        if candidates:
            parts.append(scene_crops(scene, candidates, index))
    return CropSet.concat(parts)
