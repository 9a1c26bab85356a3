"""Pixel regions the state classifiers read: the lens disk A1 and annulus A3 around a candidate
(Zheng 3.3, Eq. 3.17), and the lit lens inside a box that holds the whole signal housing.

A housing box (KR, cinTA and MIT sets) is searched along its long axis for the disk with the
highest mean HSV saturation x value^2 over its non-blue pixels, i.e. the most saturated bright
disk that is not sky or a blue housing: the lit lens.
"""

from __future__ import annotations

from collections.abc import Iterable, Iterator, Sequence
from dataclasses import dataclass

import cv2
import numpy as np

from tsrkit.api import Candidate, Frame, Param, Sample, clip_box as image_box

#: How a candidate's box is read: as the lens itself, as a housing to search, or decided by shape.
REGIONS = ("lens", "housing", "auto")


def region_params(lens_fraction: float) -> tuple[Param, ...]:
    """The parameters saying how a classifier reads a candidate's box, with the plugin's own
    default ``lens_fraction`` (each classifier's is chosen by its own cross-validation)."""
    return (
        Param(
            "region",
            "str",
            "auto",
            choices=REGIONS,
            help="lens: the candidate is the lit lens; housing: search its box for the lit "
            "lens; auto: housing when the box is elongated (see elongation)",
        ),
        Param(
            "elongation",
            "float",
            1.5,
            min=1.0,
            help="auto region: a box whose long/short side ratio reaches this is a housing",
        ),
        Param(
            "lens_fraction",
            "float",
            lens_fraction,
            min=0.05,
            max=0.5,
            help="lens radius in a housing box, as a fraction of the box's short side",
        ),
    )


@dataclass(frozen=True)
class Rings:
    """A patch of the image around a lens with the masks of its disk and annulus.

    ``disk`` is A1 (distance <= r) and ``annulus`` is A3 (r < distance <= 2r), Zheng Eq. 3.17,
    both clipped to the image.
    """

    patch: np.ndarray
    disk: np.ndarray
    annulus: np.ndarray


def clip_box(bbox, width: int, height: int) -> tuple[int, int, int, int]:
    """Integer pixel box ``(x0, y0, x1, y1)`` (exclusive end) clipped to the image.

    Raises
    ------
    ValueError
        When the box does not overlap the image.
    """
    box = image_box(bbox, width, height)
    if box[2] <= box[0] or box[3] <= box[1]:
        raise ValueError(f"box {tuple(bbox)} lies outside the {width}x{height} image")
    return box


def rings(image: np.ndarray, x: float, y: float, radius: float) -> Rings:
    """The patch of ``image`` within ``2 * radius`` of ``(x, y)`` with its A1 and A3 masks.

    Pixel centres sit at integer coordinates + 0.5, so a box ``(0, 0, 20, 20)`` centres at 10.

    Examples
    --------
    >>> r = rings(np.zeros((9, 9, 3), np.uint8), 4.5, 4.5, 2)
    >>> int(r.disk.sum()), int(r.annulus.sum())
    (13, 36)
    """
    if radius <= 0:
        raise ValueError(f"lens radius must be positive; got {radius}")
    h, w = image.shape[:2]
    outer = 2 * radius
    x0, y0, x1, y1 = clip_box((x - outer, y - outer, x + outer, y + outer), w, h)
    yy, xx = np.mgrid[y0:y1, x0:x1]
    dist2 = (xx + 0.5 - x) ** 2 + (yy + 0.5 - y) ** 2
    disk = dist2 <= radius**2
    annulus = ~disk & (dist2 <= outer**2)
    return Rings(image[y0:y1, x0:x1], disk, annulus)


@dataclass(frozen=True)
class RingRuns:
    """The A1 and A3 pixels of the :func:`rings` patches of several lenses as runs along the
    patch rows (lens by lens, row by row, left to right; no run empty).

    ``boxes`` (N, 4) are the patches ``(x0, y0, x1, y1)``; per run, ``owner`` is its lens,
    ``row`` and ``col`` its first pixel, ``length`` its pixel count and ``annulus`` whether it
    lies in A3 (else in A1).
    """

    boxes: np.ndarray
    owner: np.ndarray
    row: np.ndarray
    col: np.ndarray
    length: np.ndarray
    annulus: np.ndarray

    def pixels(self) -> tuple[np.ndarray, np.ndarray]:
        """The run of every pixel of the runs laid end to end, and the pixel's offset in it.

        Per-run values reach the pixels by ``take`` (faster than ``np.repeat``).
        """
        start = np.cumsum(self.length) - self.length
        run = np.zeros(int(self.length.sum()), np.int64)
        run[start[1:]] = 1
        run = np.cumsum(run)
        return run, np.arange(len(run)) - start.take(run)


def _run(x: np.ndarray, dy2: np.ndarray, limit: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Per row, the columns ``c`` with ``(c + 0.5 - x) ** 2 + dy2 <= limit`` as ``[lo, hi)``
    (``hi <= lo``: none).

    Those columns are one run: along a row the rounded squared distance falls, then rises
    (every rounding step is monotone). Its ends are estimated with a square root, off by at
    most one column (the estimate and the test differ by rounding only, far below a pixel), and
    each is then settled by the exact test on the column beyond it and on itself.
    """

    def inside(c: np.ndarray) -> np.ndarray:
        return (c + 0.5 - x) ** 2 + dy2 <= limit

    half = np.sqrt(np.maximum(limit - dy2, 0.0))
    lo = np.ceil(x - 0.5 - half).astype(np.int64)
    lo = np.where(inside(lo - 1), lo - 1, np.where(inside(lo), lo, lo + 1))
    hi = np.floor(x - 0.5 + half).astype(np.int64)
    hi = np.where(inside(hi + 1), hi + 1, np.where(inside(hi), hi, hi - 1))
    return lo, hi + 1


def ring_runs(image: np.ndarray, lenses: Sequence[tuple[float, float, float]]) -> RingRuns:
    """The :func:`rings` patches and A1 and A3 pixels of every lens ``(x, y, radius)`` at once.

    The same pixels as :func:`rings` (one lens at a time, where its per-pixel test is the
    faster): a pixel lies in A1 when its squared distance
    ``(col + 0.5 - x) ** 2 + (row + 0.5 - y) ** 2`` is at most ``radius ** 2``, else in A3 when
    at most ``(2 radius) ** 2``. Each patch row's A1 and A3 pixels are runs of columns
    (:func:`_run`), so only the rows are computed: an A3 run left of the A1 run and one right
    of it.

    Raises
    ------
    ValueError
        A non-positive radius, or a lens whose patch lies outside the image.
    """
    h, w = image.shape[:2]
    x, y, radius = np.array(lenses, np.float64).reshape(-1, 3).T
    bad = np.flatnonzero(radius <= 0)
    if bad.size:
        raise ValueError(f"lens radius must be positive; got {lenses[bad[0]][2]}")
    outer = 2 * radius
    box = np.column_stack(
        [
            np.maximum(0, np.floor(x - outer)),
            np.maximum(0, np.floor(y - outer)),
            np.minimum(w, np.ceil(x + outer)),
            np.minimum(h, np.ceil(y + outer)),
        ]
    ).astype(np.int64)
    bad = np.flatnonzero((box[:, 2] <= box[:, 0]) | (box[:, 3] <= box[:, 1]))
    if bad.size:
        cx, cy, r = lenses[bad[0]]
        clip_box((cx - 2 * r, cy - 2 * r, cx + 2 * r, cy + 2 * r), w, h)  # raises, as rings() did
    # the squares as Python computes them (rings() did), not NumPy's x * x
    radius2, outer2 = (
        np.array([(r**2, (2 * r) ** 2) for _, _, r in lenses], np.float64).reshape(-1, 2).T
    )
    heights = box[:, 3] - box[:, 1]
    row_owner = np.repeat(np.arange(len(box)), heights)
    row_y = np.arange(len(row_owner)) + np.repeat(box[:, 1] - np.cumsum(heights) + heights, heights)
    row_x, dy2 = x[row_owner], (row_y + 0.5 - y[row_owner]) ** 2
    left, right = box[row_owner, 0], box[row_owner, 2]
    limits = np.concatenate([outer2[row_owner], radius2[row_owner]])  # A1 and A3, then A1
    both = _run(np.tile(row_x, 2), np.tile(dy2, 2), limits)
    rows = len(row_owner)
    lo, hi = (np.clip(end[:rows], left, right) for end in both)
    hi = np.maximum(hi, lo)
    disk_lo, disk_hi = (np.clip(end[rows:], lo, hi) for end in both)
    disk_hi = np.maximum(disk_hi, disk_lo)
    ends = np.column_stack([lo, disk_lo, disk_hi, hi])
    length = np.diff(ends, axis=1).ravel()
    keep = np.flatnonzero(length)
    return RingRuns(
        box,
        np.repeat(row_owner, 3)[keep],
        np.repeat(row_y, 3)[keep],
        ends[:, :3].ravel()[keep],
        length[keep],
        np.tile([True, False, True], len(lo))[keep],
    )


def is_blue(bgr: np.ndarray) -> np.ndarray:
    """Pixels whose CIELab a-b angle lies within 45 degrees of the -b axis (blue), a colour no
    signal lamp has: green lamps sit near -150 degrees, sky and blue housings near -90 to -130.
    """
    lab = cv2.cvtColor(bgr, cv2.COLOR_BGR2LAB)
    a = lab[..., 1].astype(np.int16) - 128
    b = lab[..., 2].astype(np.int16) - 128
    return -b > np.abs(a)


def lit_map(bgr: np.ndarray) -> np.ndarray:
    """Per-pixel HSV saturation x value^2 in [0, 1], 0 on blue pixels: high on a lit, coloured
    lens (the squared value keeps a bright lens ahead of a saturated but dimmer housing; blue
    sky seen through or beside a housing is left out, see :func:`is_blue`)."""
    hsv = cv2.cvtColor(bgr, cv2.COLOR_BGR2HSV)
    v = hsv[..., 2].astype(np.float32) / 255.0
    return hsv[..., 1].astype(np.float32) / 255.0 * v * v * ~is_blue(bgr)


def disk_kernel(radius: float) -> np.ndarray:
    """A normalised disk (sums to 1) of the given radius, at least one pixel."""
    half = max(int(np.floor(radius)), 0)
    yy, xx = np.mgrid[-half : half + 1, -half : half + 1]
    kernel = (xx**2 + yy**2 <= max(radius, 0.5) ** 2).astype(np.float32)
    return kernel / kernel.sum()


def find_lens(image: np.ndarray, bbox, lens_fraction: float = 0.4) -> Candidate:
    """The lit lens inside a housing box: the disk of radius ``lens_fraction * short side``
    with the highest mean :func:`lit_map`, its centre on the box's long axis.

    Returns a lens candidate whose score is that mean (in [0, 1]).
    """
    x0, y0, x1, y1 = clip_box(bbox, image.shape[1], image.shape[0])
    crop = image[y0:y1, x0:x1]
    radius = max(lens_fraction * min(x1 - x0, y1 - y0), 0.5)
    mean = cv2.filter2D(lit_map(crop), -1, disk_kernel(radius), borderType=cv2.BORDER_CONSTANT)
    vertical = (y1 - y0) >= (x1 - x0)
    line = mean[:, mean.shape[1] // 2] if vertical else mean[mean.shape[0] // 2, :]
    best = int(np.argmax(line))
    cx, cy = ((x1 - x0) / 2, best + 0.5) if vertical else (best + 0.5, (y1 - y0) / 2)
    return Candidate.from_circle(x0 + cx, y0 + cy, radius, float(line[best]))


def is_housing(candidate: Candidate, region: str, elongation: float) -> bool:
    """Whether ``candidate``'s box is read as a housing under the ``region`` setting."""
    if region not in REGIONS:
        raise ValueError(f"region must be one of {', '.join(REGIONS)}; got {region!r}")
    if region != "auto":
        return region == "housing"
    x0, y0, x1, y1 = candidate.bbox
    short, long = sorted((x1 - x0, y1 - y0))
    return short > 0 and long / short >= elongation


def lens_of(image: np.ndarray, candidate: Candidate, params) -> Candidate:
    """The lens to classify for ``candidate``, following the plugin's region parameters."""
    if is_housing(candidate, params["region"], params["elongation"]):
        return find_lens(image, candidate.bbox, params["lens_fraction"])
    return candidate


def labelled_lenses(
    samples: Iterable[Sample], states: tuple[str, ...], params
) -> Iterator[tuple[str, Frame, Candidate]]:
    """``(state, frame, lens)`` for every annotation of ``samples`` whose state is in ``states``.

    Crop samples have one annotation covering the image; detection samples give one lens per
    annotated box. Other labels (arrows, off) are passed over.
    """
    for sample in samples:
        wanted = [a for a in sample.annotations if a.state in states]
        if not wanted:
            continue
        frame = sample.load()
        for ann in wanted:
            yield ann.state, frame, lens_of(frame.image, Candidate.from_box(ann.bbox, 1.0), params)
