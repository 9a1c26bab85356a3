"""Zheng's candidate localization (2016, 3.2.2, Figure 3-10, Eq. 3.13-3.15, Algorithm 3-1).

Turns a saliency map (conspicuity, or GRAY-TOPHAT's top-hat values) into circular candidates by
iterating: normalise, threshold at h_peak, open, take 8-connected components, filter them by
shape, refine each with DRMShift, drop overlaps, check the stop rules, and clear what was found.

Reading choices: DRMShift runs on the working map (found regions already cleared) and rounds
its fractional centre to the nearest pixel to pick the window and the radius; pixels outside the
image weigh nothing. A new candidate that intersects or touches one found in an earlier (more
conspicuous) iteration is dropped; among new ones the larger is kept. Without a radius map
(GRAY-TOPHAT) each component keeps the fixed radius of the disk of its own area (the plain mean
shift that Algorithm 3-1 extends). Candidate centres are reported in pixel coordinates with pixel
``(i, j)`` centred at ``(j + 0.5, i + 0.5)``.

Building block for plugin authors: a detector with its own saliency map gets Zheng's
localization with ``from tsrkit_plugins.detectors.localization import LOCALIZATION_PARAMS,
localize`` (add the params to its schema, call ``localize(saliency, self.params)``), as
conspicuity and gray-tophat do.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from functools import lru_cache
from typing import Any

import cv2
import numpy as np
from numba import njit

from tsrkit.api import Candidate, Param

#: The localization parameters both detectors expose (Table 5-1 defaults where it gives one).
LOCALIZATION_PARAMS = (
    Param(
        "h_peak",
        "float",
        0.9,
        min=0.0,
        max=1.0,
        section="Table 5-1, Eq. 3.14",
        help="threshold on the normalised working map for peak pixels",
    ),
    Param(
        "n_top",
        "int",
        10,
        min=1,
        section="Table 5-1",
        help="number of top candidates to locate per frame",
    ),
    Param(
        "n_pi",
        "int",
        20,
        min=1,
        section="Table 5-1",
        help="stop when one iteration brings more new candidates than this",
    ),
    Param(
        "asp_min",
        "float",
        0.6,
        min=0.0,
        max=1.0,
        section="Table 5-1",
        help="minimum short/long side ratio of a component's bounding box (step 2.2)",
    ),
    Param(
        "pd_min",
        "float",
        0.0,
        min=0.0,
        max=1.0,
        section="Table 5-1",
        help="minimum share of peak pixels in a component's bounding box (step 2.2)",
    ),
    Param(
        "shift_tol",
        "float",
        0.5,
        min=0.0,
        section="Algorithm 3-1 (h_c; no default given)",
        help="DRMShift stops when the centre moves less than this (pixels)",
    ),
    Param(
        "shift_iter",
        "int",
        10,
        min=1,
        section="Algorithm 3-1 (n_max; no default given)",
        help="DRMShift iteration limit",
    ),
    Param(
        "max_iter",
        "int",
        50,
        min=1,
        section="Figure 3-10 (a safety bound of ours)",
        help="limit on localization iterations",
    ),
)

#: The optional region of interest both detectors expose.
ROI_PARAM = Param(
    "roi_top",
    "float",
    1.0,
    min=0.01,
    max=1.0,
    section="5.2.1",
    help="search only the upper fraction of the frame (the thesis used 0.6)",
)

#: Structuring element of Eq. 3.15: the disk of radius 1.
DISK_1 = cv2.getStructuringElement(cv2.MORPH_CROSS, (3, 3))


def region_of_interest(image: np.ndarray, top: float) -> np.ndarray:
    """The upper ``top`` fraction of the frame (at least one row), as a view."""
    if not 0 < top <= 1:
        raise ValueError(f"roi_top must be in (0, 1]; got {top}")
    return image[: max(1, int(round(image.shape[0] * top)))]


def normalise(wcm: np.ndarray, peak: float | None = None, copy: bool = False) -> np.ndarray:
    """Eq. 3.13: divide the float32 working map by its maximum ``peak`` (found when not given)
    in place, or into a new array when ``copy``, and return the result (``wcm`` itself,
    unchanged, when the maximum is 0)."""
    peak = float(wcm.max()) if peak is None else peak
    if peak > 0:
        return np.divide(wcm, np.float32(peak), out=None if copy else wcm)
    return wcm


def peak_mask(wcm: np.ndarray, h_peak: float) -> np.ndarray:
    """Eq. 3.14: 1 where the normalised working map exceeds ``h_peak`` (uint8 mask, a view of
    the comparison's booleans)."""
    return np.greater(wcm, h_peak).view(np.uint8)


def peak_region(mask: np.ndarray) -> tuple[slice, slice]:
    """The bounding rectangle of the set pixels of ``mask`` widened by one pixel on each side
    (clipped to the image), as row and column slices (empty when nothing is set)."""
    x, y, w, h = cv2.boundingRect(mask)
    if w == 0:
        return slice(0, 0), slice(0, 0)
    return slice(max(y - 1, 0), y + h + 1), slice(max(x - 1, 0), x + w + 1)


def denoise(mask: np.ndarray) -> np.ndarray:
    """Eq. 3.15: morphological opening with the radius-1 disk.

    ``localize`` opens only :func:`peak_region` of the raw peaks: outside the set pixels'
    rectangle the opening is 0, and the rectangle's one-pixel frame of zeros (or the image
    border, handled alike) gives the pixels inside the same neighbours.
    """
    return cv2.morphologyEx(mask, cv2.MORPH_OPEN, DISK_1)


@dataclass(frozen=True)
class Components:
    """8-connected components (step 2.1): bounding boxes, areas and centroids ``(x, y)``."""

    boxes: np.ndarray
    areas: np.ndarray
    centroids: np.ndarray


def components(mask: np.ndarray, origin: tuple[int, int] = (0, 0)) -> Components:
    """Step 2.1: 8-connected components of a binary mask (background excluded), in the
    coordinates of a frame in which ``mask`` starts at ``origin`` = (x, y).

    The statistics and the order are those of ``cv2.connectedComponentsWithStats`` on the
    bounding rectangle of the set pixels (:func:`sparse_components`).
    """
    x, y, w, h = cv2.boundingRect(mask)
    if w == 0:
        return Components(np.zeros((0, 4), np.int64), np.zeros(0, np.int64), np.zeros((0, 2)))
    stats, centroids = sparse_components(np.flatnonzero(mask[y : y + h, x : x + w]), w)
    x, y = x + origin[0], y + origin[1]
    boxes = stats[:, :4] + np.array([x, y, 0, 0])
    return Components(boxes, stats[:, cv2.CC_STAT_AREA], centroids + np.array([x, y]))


@njit(cache=True, nogil=True)
def sparse_components(pixels, width):
    """8-connected components of the set pixels ``pixels`` (flat indices, ascending) of a mask
    ``width`` pixels wide: OpenCV's statistics rows (left, top, width, height, area; int32)
    and centroids (x, y; float64), in OpenCV's label order.

    ``cv2.connectedComponentsWithStats`` (8-connectivity, Spaghetti) labels 2x2 blocks in
    raster order, so a component's label ranks by the first block holding one of its pixels;
    here the components come from a union-find over the set pixels only (the peaks are
    sparse; labelling the whole rectangle took most of the localization's time at 1280x720)
    and are sorted by that block. Sums of coordinates are exact integers, so the centroids are
    OpenCV's.
    """
    count = pixels.size
    parent = np.arange(count)
    above = 0
    for i in range(count):
        row, col = divmod(pixels[i], width)
        if col > 0 and i > 0 and pixels[i - 1] == pixels[i] - 1:
            _union(parent, i, i - 1)
        while above < i and pixels[above] < pixels[i] - width - 1:
            above += 1
        j = above
        while j < i and pixels[j] <= pixels[i] - width + 1:
            other_row, other_col = divmod(pixels[j], width)
            if other_row == row - 1 and abs(other_col - col) <= 1:
                _union(parent, i, j)
            j += 1
    blocks_per_row = (width + 1) // 2
    first_block = np.full(count, np.iinfo(np.int64).max)
    for i in range(count):
        root = _find(parent, i)
        row, col = divmod(pixels[i], width)
        first_block[root] = min(first_block[root], (row // 2) * blocks_per_row + col // 2)
    roots = np.flatnonzero(first_block < np.iinfo(np.int64).max)
    roots = roots[np.argsort(first_block[roots])]
    index = np.empty(count, np.int64)
    index[roots] = np.arange(roots.size)
    stats = np.zeros((roots.size, 5), np.int32)
    stats[:, 0] = stats[:, 1] = np.iinfo(np.int32).max
    sums = np.zeros((roots.size, 2), np.int64)
    right_bottom = np.zeros((roots.size, 2), np.int64)
    for i in range(count):
        k = index[_find(parent, i)]
        row, col = divmod(pixels[i], width)
        stats[k, 0] = min(stats[k, 0], col)
        stats[k, 1] = min(stats[k, 1], row)
        right_bottom[k, 0] = max(right_bottom[k, 0], col)
        right_bottom[k, 1] = max(right_bottom[k, 1], row)
        stats[k, 4] += 1
        sums[k, 0] += col
        sums[k, 1] += row
    centroids = np.empty((roots.size, 2))
    for k in range(roots.size):
        stats[k, 2] = right_bottom[k, 0] - stats[k, 0] + 1
        stats[k, 3] = right_bottom[k, 1] - stats[k, 1] + 1
        centroids[k, 0] = np.float64(sums[k, 0]) / np.float64(stats[k, 4])
        centroids[k, 1] = np.float64(sums[k, 1]) / np.float64(stats[k, 4])
    return stats, centroids


@njit(cache=True, nogil=True)
def _find(parent, i):
    """The root of ``i`` (the smallest index of its set), halving the path on the way."""
    while parent[i] != i:
        parent[i] = parent[parent[i]]
        i = parent[i]
    return i


@njit(cache=True, nogil=True)
def _union(parent, i, j):
    """Join the sets of ``i`` and ``j`` under the smaller root."""
    a, b = _find(parent, i), _find(parent, j)
    if a != b:
        parent[max(a, b)] = min(a, b)


def shape_filter(found: Components, asp_min: float, pd_min: float) -> np.ndarray:
    """Step 2.2: keep components whose box aspect ratio (short/long side) >= ``asp_min`` and
    pixel density (component pixels over box pixels) >= ``pd_min``; returns a boolean mask."""
    width, height = found.boxes[:, 2], found.boxes[:, 3]
    aspect = np.minimum(width, height) / np.maximum(width, height)
    density = found.areas / (width * height)
    return (aspect >= asp_min) & (density >= pd_min)


def nearest_cells(centres: np.ndarray, shape: tuple[int, ...]) -> np.ndarray:
    """Fractional ``(row, col)`` centres rounded to the nearest pixel inside ``shape``."""
    cells = np.rint(centres).astype(np.int64)
    cells[:, 0] = cells[:, 0].clip(0, shape[0] - 1)
    cells[:, 1] = cells[:, 1].clip(0, shape[1] - 1)
    return cells


@lru_cache(maxsize=8)
def _window_offsets(reach: int) -> tuple[np.ndarray, np.ndarray]:
    dy, dx = np.mgrid[-reach : reach + 1, -reach : reach + 1]
    return dy.ravel(), dx.ravel()


def drmshift(
    cm: np.ndarray,
    starts: np.ndarray,
    radius_map: np.ndarray | None = None,
    radii: np.ndarray | None = None,
    tol: float = 0.5,
    n_max: int = 10,
    reach: int | None = None,
) -> tuple[np.ndarray, np.ndarray]:
    """Algorithm 3-1 (dynamic radius mean shift) for many start points at once.

    Parameters
    ----------
    cm : ndarray
        Non-negative weights (the conspicuity map), shape (H, W).
    starts : ndarray
        Start centres ``(row, col)``, shape (N, 2), float.
    radius_map : ndarray, optional
        The radius map RM; the window radius is read at each rounded centre (line 9).
    radii : ndarray, optional
        Fixed window radii, shape (N,), used when ``radius_map`` is None.
    tol : float
        Converge threshold ``h_c``: stop when the centre moves less than this.
    n_max : int
        Maximum number of iterations.
    reach : int, optional
        The largest window radius (the maximum of ``radius_map`` or ``radii``), when the caller
        knows it already.

    Returns
    -------
    centres : ndarray
        Final ``(row, col)``, shape (N, 2).
    radius : ndarray
        Final window radius per point, shape (N,).
    """
    centres = np.asarray(starts, dtype=np.float64).reshape(-1, 2).copy()
    if radius_map is None:
        if radii is None:
            raise ValueError("drmshift needs a radius_map or fixed radii")
        fixed = np.asarray(radii, dtype=np.int64).reshape(-1)
        reach = int(fixed.max(initial=0)) if reach is None else reach
    elif reach is None:
        reach = int(radius_map.max(initial=0))
    dy, dx = _window_offsets(reach)
    active = np.ones(len(centres), bool)
    radius = np.zeros(len(centres), np.int64)
    for _ in range(n_max):
        idx = np.flatnonzero(active)
        if idx.size == 0:
            break
        cell = nearest_cells(centres[idx], cm.shape)
        r = fixed[idx] if radius_map is None else radius_map[cell[:, 0], cell[:, 1]]
        radius[idx] = r
        inside = dy * dy + dx * dx <= (r * r)[:, None]
        rows = cell[:, :1] + dy
        cols = cell[:, 1:] + dx
        inside &= (rows >= 0) & (rows < cm.shape[0]) & (cols >= 0) & (cols < cm.shape[1])
        weight = cm[rows.clip(0, cm.shape[0] - 1), cols.clip(0, cm.shape[1] - 1)] * inside
        m00 = weight.sum(axis=1)
        moved = m00 > 0
        new = np.stack([(weight * rows).sum(axis=1), (weight * cols).sum(axis=1)], axis=1)
        new[moved] /= m00[moved, None]
        new[~moved] = centres[idx][~moved]
        shift = np.hypot(*(new - centres[idx]).T)
        centres[idx] = new
        active[idx] = moved & (shift >= tol)
    if radius_map is not None:
        final = nearest_cells(centres, cm.shape)
        radius = radius_map[final[:, 0], final[:, 1]].astype(np.int64)
    return centres, radius


def non_overlapping(
    centres: np.ndarray, radius: np.ndarray, kept_centres: np.ndarray, kept_radius: np.ndarray
) -> np.ndarray:
    """Indices of new circles that intersect or touch neither each other nor kept ones.

    Larger new circles win; a new circle touching a kept (earlier) one is dropped (3.2.2).
    """
    order = np.argsort(-radius, kind="stable")
    chosen: list[int] = []
    others_c = [tuple(c) for c in kept_centres]
    others_r = list(kept_radius)
    for i in order:
        if others_c:
            gap = np.hypot(*(np.asarray(others_c) - centres[i]).T)
            if np.any(gap <= np.asarray(others_r) + radius[i]):
                continue
        chosen.append(int(i))
        others_c.append(tuple(centres[i]))
        others_r.append(radius[i])
    return np.asarray(sorted(chosen), dtype=np.int64)


def too_many(new_count: int, found_count: int, n_pi: int) -> bool:
    """The two stop checks before step 4.2: more than ``N_pi`` new candidates (absolute), or
    more new candidates than all found so far (relative)."""
    return new_count > n_pi or (found_count > 0 and new_count > found_count)


def clear_found(
    wcm: np.ndarray,
    raw_peaks: np.ndarray,
    centres: np.ndarray,
    radius: np.ndarray,
    region: tuple[slice, slice] | None = None,
) -> None:
    """Steps 3.1-3.2: zero the raw peak pixels and the new candidate disks in the working map
    (the disks drawn with value 0 straight into it); ``region`` (:func:`peak_region`), when
    given, holds every raw peak pixel."""
    rows, cols = (slice(None), slice(None)) if region is None else region
    np.putmask(wcm[rows, cols], raw_peaks[rows, cols], 0)
    for (row, col), r in zip(np.rint(centres).astype(int), radius):
        cv2.circle(wcm, (int(col), int(row)), int(r), 0, -1)


def localize(
    cm: np.ndarray, params: Mapping[str, Any], radius_map: np.ndarray | None = None
) -> list[Candidate]:
    """Figure 3-10: the iterative extraction of candidates from a saliency map.

    Parameters
    ----------
    cm : ndarray
        The (aggregated) conspicuity map or any non-negative saliency map, shape (H, W).
    params : mapping
        ``h_peak, n_top, n_pi, asp_min, pd_min, shift_tol, shift_iter, max_iter``
        (see :data:`LOCALIZATION_PARAMS`).
    radius_map : ndarray, optional
        Per-pixel lens radius (Eq. 3.2's arg-max); without it each component's own size is used.

    Returns
    -------
    list of Candidate
        At most ``n_top``, best score first; score is ``cm`` at the candidate's centre.
    """
    source = np.asarray(cm, dtype=np.float32)
    found_c = np.zeros((0, 2))
    found_r = np.zeros(0, np.int64)
    reach = None if radius_map is None else int(radius_map.max(initial=0))
    for iteration in range(params["max_iter"]):
        peak = float(source.max())
        if not peak > 0:
            break
        # The first normalisation is the working copy of ``cm`` (one pass, not two).
        wcm = source = normalise(source, peak, iteration == 0)
        raw = peak_mask(wcm, params["h_peak"])
        region = peak_region(raw)
        opened = denoise(np.ascontiguousarray(raw[region]))
        blobs = components(opened, (region[1].start, region[0].start))
        keep = shape_filter(blobs, params["asp_min"], params["pd_min"])
        starts = blobs.centroids[keep][:, ::-1]
        sizes = np.maximum(1, np.rint(np.sqrt(blobs.areas[keep] / np.pi))).astype(np.int64)
        centres, radius = drmshift(
            wcm, starts, radius_map, sizes, params["shift_tol"], params["shift_iter"], reach
        )
        chosen = non_overlapping(centres, radius, found_c, found_r)
        if too_many(len(chosen), len(found_r), params["n_pi"]):
            break
        found_c = np.concatenate([found_c, centres[chosen]])
        found_r = np.concatenate([found_r, radius[chosen]])
        if len(found_r) >= params["n_top"]:
            break
        clear_found(wcm, raw, centres[chosen], radius[chosen], region)
    return best_candidates(cm, found_c, found_r, params["n_top"])


def best_candidates(
    cm: np.ndarray, centres: np.ndarray, radius: np.ndarray, n_top: int
) -> list[Candidate]:
    """Candidates scored by ``cm`` at their rounded centre, the ``n_top`` best first."""
    cells = nearest_cells(centres, cm.shape)
    scores = cm[cells[:, 0], cells[:, 1]]
    order = np.argsort(-scores, kind="stable")[:n_top]
    return [
        Candidate.from_circle(centres[i, 1] + 0.5, centres[i, 0] + 0.5, radius[i], scores[i])
        for i in order
    ]
