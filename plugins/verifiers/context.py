"""Features of a candidate relative to its own frame: meant to hold on any camera.

A camera's exposure, white balance and saturation shift every pixel of a frame together, and
its resolution and distance scale every light of a frame together; the learned verifier,
trained on a few cameras, reads such shifts as evidence (issue 11: held-out sets lose most of
their lights, benchmarks/RESULTS.verifier.md). The columns here are invariant to those shifts
by construction:

* **Photometry relative to the frame** (:func:`frame_statistics`): the lens's brightness (V)
  placed between the frame's median and 99th percentile, its peak against the frame's 99th
  percentile, its saturation against the frame's 99th, and its colour after a grey-world white
  balance (Lab a, b minus the frame's mean a, b; the frame's mean is its neutral).
* **Relations among the frame's candidates**: how many other candidates sit within two lens
  radii (duplicates on one lamp), whether the candidate is the best scored of those, and how
  many others lie inside its housing box.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import cv2
import numpy as np

from tsrkit.types import Candidate

#: The frame is read at 1/``SHRINK`` of its size for its statistics (a 1280x720 frame: 160x90
#: pixels, nearest-neighbour: a sample of the frame's pixels, at 0.02 ms rather than 0.7 ms for
#: area averaging).
SHRINK = 8
#: Frame brightness percentiles: the frame's typical pixel and its brightest.
LOW, HIGH = 50.0, 99.0
#: Neighbours closer than this many lens radii (the larger of the two) are duplicates.
DUPLICATE_RADII = 2.0

CONTEXT_NAMES = (
    "lens_V_in_frame_range",
    "lens_V_max_over_frame_p99",
    "lens_S_over_frame_p99",
    "lens_a_balanced",
    "lens_b_balanced",
    "duplicates",
    "best_of_duplicates",
    "others_in_housing",
)


@dataclass(frozen=True)
class FrameStatistics:
    """Brightness and saturation percentiles (HSV, 0-255) and the grey-world neutral (the
    mean 8-bit Lab a and b, 128 = grey) of one frame."""

    v_low: float
    v_high: float
    s_high: float
    a_mean: float
    b_mean: float


def frame_statistics(image: np.ndarray) -> FrameStatistics:
    """The statistics of ``image`` (BGR uint8) read at 1/:data:`SHRINK` of its size.

    Examples
    --------
    >>> grey = np.full((80, 80, 3), 100, np.uint8)
    >>> s = frame_statistics(grey)
    >>> s.v_low, s.v_high, s.s_high, s.a_mean, s.b_mean
    (100.0, 100.0, 0.0, 128.0, 128.0)
    """
    height, width = image.shape[:2]
    small = cv2.resize(
        image,
        (max(width // SHRINK, 1), max(height // SHRINK, 1)),
        interpolation=cv2.INTER_NEAREST,
    ).reshape(1, -1, 3)
    hsv = cv2.cvtColor(small, cv2.COLOR_BGR2HSV)[0]
    lab = cv2.cvtColor(small, cv2.COLOR_BGR2LAB)[0]
    v_low, v_high = _percentiles(hsv[:, 2], (LOW, HIGH))
    (s_high,) = _percentiles(hsv[:, 1], (HIGH,))
    return FrameStatistics(
        v_low=v_low,
        v_high=v_high,
        s_high=s_high,
        a_mean=float(lab[:, 1].mean()),
        b_mean=float(lab[:, 2].mean()),
    )


def _percentiles(values: np.ndarray, percents: Sequence[float]) -> list[float]:
    """The smallest 8-bit value at or below which ``percents`` % of ``values`` lie (from one
    histogram: a third of ``np.percentile``'s time on a frame's 14,400 samples).

    Examples
    --------
    >>> _percentiles(np.array([10, 20, 30, 40], np.uint8), (50, 99))
    [20.0, 40.0]
    """
    cumulative = np.cumsum(np.bincount(values, minlength=256))
    ranks = np.asarray(percents, np.float64) / 100.0 * cumulative[-1]
    return [float(v) for v in np.searchsorted(cumulative, ranks)]


def photometric_features(lens: np.ndarray, stats: FrameStatistics) -> np.ndarray:
    """Lens brightness, saturation and colour relative to the frame (the first five columns).

    ``lens`` is (N, P, 8): the ``features.COLOUR_NAMES`` planes (8-bit L, a, b, then S, V,
    ...) of the P pixels of each candidate's lens disk.
    """
    mean = lens.mean(axis=1)
    v_span = max(stats.v_high - stats.v_low, 1.0)
    return np.column_stack(
        [
            (mean[:, 4] - stats.v_low) / v_span,
            lens[..., 4].max(axis=1) / max(stats.v_high, 1.0),
            mean[:, 3] / max(stats.s_high, 1.0),
            mean[:, 1] - stats.a_mean,
            mean[:, 2] - stats.b_mean,
        ]
    )


def relation_features(candidates: Sequence[Candidate]) -> np.ndarray:
    """Duplicates within :data:`DUPLICATE_RADII` lens radii, whether the candidate scores best
    among them (ties: the earlier), and other candidates' centres inside its housing box.

    Examples
    --------
    >>> c = [Candidate.from_circle(10, 10, 2, 0.9), Candidate.from_circle(12, 10, 2, 0.5),
    ...      Candidate.from_circle(50, 50, 2, 0.1)]
    >>> relation_features(c).tolist()
    [[1.0, 1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]
    """
    x, y, radius, score = np.array(
        [(c.x, c.y, max(c.radius, 0.5), c.score) for c in candidates], np.float64
    ).T
    n = len(x)
    distance = np.hypot(x[:, None] - x[None], y[:, None] - y[None])
    near = distance < DUPLICATE_RADII * np.maximum(radius[:, None], radius[None])
    near[np.arange(n), np.arange(n)] = False
    order = np.empty(n, int)
    order[np.argsort(-score, kind="stable")] = np.arange(n)
    beaten = near & (order[None, :] < order[:, None])
    house = np.array(
        [c.housing if c.housing is not None else (np.nan,) * 4 for c in candidates], np.float64
    )
    with np.errstate(invalid="ignore"):
        inside = (
            (x[None] >= house[:, 0, None])
            & (x[None] <= house[:, 2, None])
            & (y[None] >= house[:, 1, None])
            & (y[None] <= house[:, 3, None])
        )
    inside[np.arange(n), np.arange(n)] = False
    return np.column_stack([near.sum(axis=1), ~beaten.any(axis=1), inside.sum(axis=1)]).astype(
        np.float64
    )


def context_features(
    image: np.ndarray, candidates: Sequence[Candidate], lens: np.ndarray
) -> np.ndarray:
    """The :data:`CONTEXT_NAMES` columns of ``candidates`` on ``image`` (BGR uint8), from
    the colour planes of their lens disks ``lens`` (N, P, 8)."""
    return np.column_stack(
        [
            photometric_features(lens, frame_statistics(image)),
            relation_features(candidates),
        ]
    ).astype(np.float32)
