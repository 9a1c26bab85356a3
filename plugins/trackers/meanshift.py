"""Lee's kernel mean-shift tracker on hue-saturation histograms.

A detection that passes the start condition becomes the target: a 20x20 hue-saturation histogram
weighted by an Epanechnikov profile times a colour mask. Each later frame moves the window by
mean shift at five growing kernel scales and keeps the scale with the best Bhattacharyya
coefficient. Lee 2017, section 3.3 (Eq. 3.2-3.4) and the start condition of 3.6.2.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, replace

import cv2
import numpy as np

from tsrkit.api import Candidate, Detection, Frame, Param, Tracker, hookimpl


@dataclass(frozen=True)
class Window:
    """An elliptical kernel window: centre and half axes in pixels."""

    cx: float
    cy: float
    ax: float
    ay: float

    @classmethod
    def from_box(cls, bbox: Sequence[float]) -> Window:
        x0, y0, x1, y1 = bbox
        return cls((x0 + x1) / 2, (y0 + y1) / 2, (x1 - x0) / 2, (y1 - y0) / 2)

    def scaled(self, factor: float) -> Window:
        return replace(self, ax=self.ax * factor, ay=self.ay * factor)

    def moved(self, cx: float, cy: float) -> Window:
        return replace(self, cx=cx, cy=cy)

    @property
    def bbox(self) -> tuple[float, float, float, float]:
        return (self.cx - self.ax, self.cy - self.ay, self.cx + self.ax, self.cy + self.ay)


@dataclass(frozen=True)
class ColourPlanes:
    """Per-pixel histogram bin and colour mask of a frame region starting at ``(x0, y0)``."""

    bins: np.ndarray
    mask: np.ndarray
    x0: int
    y0: int


def colour_planes(
    image: np.ndarray, region: tuple[int, int, int, int], n_bins: Sequence[int], min_saturation: int
) -> ColourPlanes:
    """Quantise hue and saturation of ``image[y0:y1, x0:x1]`` into ``n_h x n_s`` bins (3.3).

    The bin of a pixel is ``n_s * j + k`` for hue bin ``j`` and saturation bin ``k`` (Eq. 3.2,
    zero-based). The mask keeps pixels with saturation >= ``min_saturation``: a Detection does
    not carry its detector's segmentation, so this reading rebuilds the "mask of the detected
    sign" as its coloured pixels.
    """
    x0, y0, x1, y1 = region
    hsv = cv2.cvtColor(image[y0:y1, x0:x1], cv2.COLOR_BGR2HSV_FULL)
    n_h, n_s = n_bins
    hue = (hsv[..., 0].astype(np.intp) * n_h) >> 8
    sat = (hsv[..., 1].astype(np.intp) * n_s) >> 8
    return ColourPlanes(hue * n_s + sat, hsv[..., 1] >= min_saturation, x0, y0)


def epanechnikov_profile(dist2: np.ndarray) -> np.ndarray:
    """The Epanechnikov profile ``k(x) = 1 - x`` for ``x <= 1``, else 0 (constant c_k dropped)."""
    return np.clip(1.0 - dist2, 0.0, None)


def window_pixels(planes: ColourPlanes, window: Window):
    """Pixel coordinates, squared normalised distances, bins and mask inside ``window``."""
    h, w = planes.bins.shape
    xa = max(int(np.floor(window.cx - window.ax)) - planes.x0, 0)
    xb = min(int(np.ceil(window.cx + window.ax)) + 1 - planes.x0, w)
    ya = max(int(np.floor(window.cy - window.ay)) - planes.y0, 0)
    yb = min(int(np.ceil(window.cy + window.ay)) + 1 - planes.y0, h)
    ys, xs = np.mgrid[ya : max(yb, ya), xa : max(xb, xa)]
    xs, ys = (xs + planes.x0).ravel(), (ys + planes.y0).ravel()
    dist2 = ((xs - window.cx) / window.ax) ** 2 + ((ys - window.cy) / window.ay) ** 2
    inside = dist2 <= 1.0
    local = (ys[inside] - planes.y0, xs[inside] - planes.x0)
    return xs[inside], ys[inside], dist2[inside], planes.bins[local], planes.mask[local]


def kernel_histogram(bins: np.ndarray, weights: np.ndarray, n_bins: int) -> np.ndarray:
    """Lee Eq. 3.2: ``t_b = C sum_i K(||p_i||^2) H(p_i, b)``, C making it sum to 1.

    An empty window (no weight) gives all zeros.
    """
    hist = np.bincount(bins, weights=weights, minlength=n_bins)
    total = hist.sum()
    return hist / total if total > 0 else hist


def bhattacharyya(target: np.ndarray, candidate: np.ndarray) -> float:
    """The Bhattacharyya coefficient ``B(t, c) = sum_b sqrt(t_b c_b)`` (3.3)."""
    return float(np.sqrt(target * candidate).sum())


def pixel_weights(target: np.ndarray, candidate: np.ndarray, bins: np.ndarray) -> np.ndarray:
    """Lee's w_i (after Eq. 3.3): ``sqrt(t_b / c_b(z))`` for the bin ``b`` of each pixel."""
    ratio = np.divide(target, candidate, out=np.zeros_like(target), where=candidate > 0)
    return np.sqrt(ratio)[bins]


def mean_shift_step(
    xs: np.ndarray, ys: np.ndarray, weights: np.ndarray, mask: np.ndarray
) -> tuple[float, float] | None:
    """Lee Eq. 3.4: ``z_new = sum p_i w_i mask_i / sum w_i mask_i`` (None when the sum is 0).

    With the Epanechnikov profile the kernel derivative is constant inside the window, so the
    sums run over the pixels of the window.
    """
    wm = weights * mask
    total = wm.sum()
    if total <= 0:
        return None
    return float(xs @ wm / total), float(ys @ wm / total)


def candidate_model(planes: ColourPlanes, window: Window, n_bins: int):
    """The candidate histogram c(z) of ``window`` (Eq. 3.2 at the new centre) and its pixels."""
    xs, ys, dist2, bins, mask = window_pixels(planes, window)
    hist = kernel_histogram(bins, epanechnikov_profile(dist2) * mask, n_bins)
    return hist, (xs, ys, bins, mask)


def track_scale(
    planes: ColourPlanes, target: np.ndarray, window: Window, max_iter: int, epsilon: float
) -> tuple[Window, float]:
    """Mean-shift ``window`` until it moves less than ``epsilon`` px or ``max_iter`` steps."""
    for _ in range(max_iter):
        hist, (xs, ys, bins, mask) = candidate_model(planes, window, target.size)
        step = mean_shift_step(xs, ys, pixel_weights(target, hist, bins), mask)
        if step is None:
            return window, 0.0
        moved = np.hypot(step[0] - window.cx, step[1] - window.cy)
        window = window.moved(*step)
        if moved < epsilon:
            break
    return window, bhattacharyya(target, candidate_model(planes, window, target.size)[0])


class MeanShift(Tracker):
    """Kernel mean-shift tracking of one sign at a time (Lee 2017, 3.3 and 3.6.2)."""

    name = "meanshift"
    summary = "Kernel mean shift on 20x20 hue-saturation histograms, five kernel scales"
    section = "Lee 2017, 3.3 (Eq. 3.2-3.4), 3.6.2"
    PARAMS = (
        Param(
            "bins",
            "ints",
            (20, 20),
            min=2,
            max=256,
            length=2,
            help="hue and saturation bins n_h, n_s",
            section="3.3",
        ),
        Param(
            "scales",
            "floats",
            (0, 2, 5, 7, 10),
            min=-50,
            max=100,
            help="kernel size increases tried each frame, percent",
            section="3.3",
        ),
        Param("max_iter", "int", 20, min=1, help="mean-shift iteration cap", section="3.3"),
        Param(
            "epsilon",
            "float",
            0.5,
            min=0,
            help="stop when the shift is below this, px",
            section="3.3",
        ),
        Param(
            "min_saturation",
            "int",
            50,
            min=0,
            max=255,
            help="colour mask: pixels at least this saturated (0-255)",
        ),
        Param(
            "min_similarity",
            "float",
            0.6,
            min=0,
            max=1,
            help="the track ends when the best Bhattacharyya coefficient drops below this",
        ),
        Param(
            "min_size",
            "float",
            10,
            min=1,
            help="start condition: the box's width and height reach this, px",
            section="3.6.2",
        ),
        Param(
            "aspect",
            "floats",
            (0.5, 2.0),
            min=0,
            length=2,
            help="start condition: width / height within this range",
            section="3.6.2",
        ),
    )

    def __init__(self, **params):
        super().__init__(**params)
        self._next_id = 0
        self.reset()

    def reset(self) -> None:
        self._target: np.ndarray | None = None
        self._window: Window | None = None
        self._detection: Detection | None = None

    def needs_detection(self) -> bool:
        return self._target is None

    def starts(self, detection: Detection) -> bool:
        """The start condition of 3.6.2: minimum size and an aspect ratio range."""
        x0, y0, x1, y1 = detection.candidate.bbox
        w, h = x1 - x0, y1 - y0
        lo, hi = self.params["aspect"]
        return min(w, h) >= self.params["min_size"] and lo <= w / h <= hi

    def _planes(self, frame: Frame, window: Window, reach: float) -> ColourPlanes:
        x0, y0, x1, y1 = window.scaled(reach).bbox
        region = (
            max(int(x0), 0),
            max(int(y0), 0),
            min(int(np.ceil(x1)) + 1, frame.width),
            min(int(np.ceil(y1)) + 1, frame.height),
        )
        return colour_planes(
            frame.image, region, self.params["bins"], self.params["min_saturation"]
        )

    def _start(self, frame: Frame, detection: Detection) -> bool:
        window = Window.from_box(detection.candidate.bbox)
        n_bins = int(np.prod(self.params["bins"]))
        target, _ = candidate_model(self._planes(frame, window, 1.0), window, n_bins)
        if target.sum() == 0:
            return False
        self._target, self._window = target, window
        self._detection = replace(detection, track_id=self._next_id)
        self._next_id += 1
        return True

    def _follow(self, frame: Frame) -> Detection | None:
        target, last, start = self._target, self._window, self._detection
        assert target is not None and last is not None and start is not None  # a track is on
        grow = 1 + max(self.params["scales"]) / 100
        planes = self._planes(frame, last, 2.0 * grow)
        best, score = last, -1.0
        for percent in self.params["scales"]:
            window = last.scaled(1 + percent / 100)
            window, similarity = track_scale(
                planes, target, window, self.params["max_iter"], self.params["epsilon"]
            )
            if similarity > score:
                best, score = window, similarity
        inside = 0 <= best.cx < frame.width and 0 <= best.cy < frame.height
        if score < self.params["min_similarity"] or not inside:
            self.reset()
            return None
        self._window = best
        return replace(
            start,
            candidate=Candidate.from_box(best.bbox, score, start.candidate.state),
            origin="tracked",
        )

    def update(self, frame: Frame, detections: Sequence[Detection]) -> list[Detection]:
        """Start a track from the first detection passing :meth:`starts`, else follow it."""
        if self._target is not None:
            followed = self._follow(frame)
            return [followed] if followed is not None else []
        out = list(detections)
        for i, detection in enumerate(out):
            if self.starts(detection) and self._start(frame, detection):
                assert self._detection is not None  # _start set it
                out[i] = self._detection
                break
        return out


@hookimpl
def register_trackers(register):
    register(MeanShift)
