"""Features of a candidate and its housing that the learned ``verifier`` reads.

Every candidate is sampled twice at a fixed size: its lens context (a square of ``CONTEXT``
lens radii centred on the lens) and its housing (``Candidate.housing`` when a housing stage
fitted one, else the lens context), turned upright when wider than tall. Fixed sizes make the
lens, annulus and surround masks constants, and let one ``cv2.remap``, one colour conversion and
one ``skimage.feature.hog`` call serve every candidate of a frame at once.
"""

from __future__ import annotations

from collections.abc import Sequence

import cv2
import numpy as np
from numba import njit
from skimage.feature._hoghistogram import hog_histograms

from tsrkit.api import Candidate
from tsrkit_plugins.verifiers.reductions import pairwise_sum

#: Side of the lens context, in lens radii (lens disk: 1 radius, annulus 1-2, surround 2-3).
CONTEXT = 6.0
#: Sampled lens context, square, in pixels.
LENS_PX = 16
#: Sampled housing (width, height) after turning it upright (its HOG: 11 rows + 4 framing
#: rows = 3 cells of 5).
HOUSING_PX = (12, 22)
#: HOG reads both samples at half size (its cost grows with the pixel count): the lens context
#: as one cell, the housing as three cells, top, middle and bottom (the lamps of a 3-lamp head).
HOG_SHRINK = 2
ORIENTATIONS = 9
#: Version of the feature layout; a model trained on another layout is refused (3: the housing's
#: shape and the lens's place in it read upright, as the samples are, so that a horizontal head
#: and the same head turned vertical give the same geometry).
FEATURE_VERSION = 3

COLOUR_NAMES = ("L", "a", "b", "S", "V", "hue_cos", "hue_sin", "chroma")
RINGS = ("lens", "annulus", "surround")


def _ring_masks(size: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Lens disk (radius 1), annulus (1-2) and surround (2-3), in lens radii, of the context."""
    unit = size / CONTEXT
    yy, xx = np.mgrid[0:size, 0:size] + 0.5
    dist = np.hypot(xx - size / 2, yy - size / 2) / unit
    return dist <= 1.0, (dist > 1.0) & (dist <= 2.0), (dist > 2.0) & (dist <= 3.0)


RING_MASKS = _ring_masks(LENS_PX)


#: Columns of :func:`candidate_table`.
TABLE = ("x", "y", "radius", "score", "housing_score", "has_housing", "hx0", "hy0", "hx1", "hy1")
_NO_BOX = (np.nan,) * 4


def candidate_table(candidates: Sequence[Candidate]) -> np.ndarray:
    """What the features read of each candidate, one pass over them: an (N, 10) float64 table
    of :data:`TABLE` (housing score -1 and housing box NaN where no housing stage fitted one)."""
    return np.array(
        [
            (
                c.x,
                c.y,
                c.radius,
                c.score,
                -1.0 if c.housing_score is None else c.housing_score,
                c.housing is not None,
                *(_NO_BOX if c.housing is None else c.housing),
            )
            for c in candidates
        ],
        np.float64,
    ).reshape(-1, len(TABLE))


def context_boxes(table: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The lens context of each candidate of a :func:`candidate_table` (the square of
    ``CONTEXT`` radii around the lens, at least 1 px) and its housing box (the fitted housing,
    else the lens context), as (N, 4) float32 boxes."""
    x, y, radius = table[:, 0], table[:, 1], table[:, 2]
    half = np.maximum(radius, 1.0) * CONTEXT / 2
    lens = np.column_stack([x - half, y - half, x + half, y + half])
    housing = np.where(table[:, 5:6] > 0, table[:, 6:10], lens)
    return lens.astype(np.float32), housing.astype(np.float32)


#: Widest row of sample points handed to one ``cv2.remap`` (which refuses 32767 or more).
REMAP_ROW = 32000


@njit(cache=True, nogil=True)
def fill_maps(
    boxes: np.ndarray, width: int, height: int, upright: bool, map_x: np.ndarray, map_y: np.ndarray
) -> None:
    """:func:`box_maps` into ``map_x`` and ``map_y`` (N, height, width), in float32 as numpy
    computes them on float32 arrays: ``x0 + u * (x1 - x0) / width - 0.5``, left to right."""
    w, h, half = np.float32(width), np.float32(height), np.float32(0.5)
    for i in range(len(boxes)):
        x0, y0, x1, y1 = boxes[i, 0], boxes[i, 1], boxes[i, 2], boxes[i, 3]
        wide = upright and x1 - x0 > y1 - y0
        for row in range(height):
            v = np.float32(row) + half
            for col in range(width):
                u = np.float32(col) + half
                if wide:
                    map_x[i, row, col] = x0 + v * (x1 - x0) / h - half
                    map_y[i, row, col] = y0 + u * (y1 - y0) / w - half
                else:
                    map_x[i, row, col] = x0 + u * (x1 - x0) / w - half
                    map_y[i, row, col] = y0 + v * (y1 - y0) / h - half


def box_maps(
    boxes: np.ndarray, size: tuple[int, int], upright: bool = False
) -> tuple[np.ndarray, np.ndarray]:
    """The sample points (x, y), flat float32, of every box of ``boxes`` (float32) at ``size``
    (width, height), box after box, row by row: pixel centres of the box scaled to ``size``
    (one compiled pass, :func:`fill_maps`). With ``upright``, a box wider than tall is read
    transposed, so its long side runs down."""
    width, height = size
    map_x = np.empty((len(boxes), height, width), np.float32)
    map_y = np.empty_like(map_x)
    fill_maps(np.ascontiguousarray(boxes, np.float32), width, height, upright, map_x, map_y)
    return map_x.ravel(), map_y.ravel()


def remap_points(image: np.ndarray, map_x: np.ndarray, map_y: np.ndarray) -> np.ndarray:
    """Bilinear samples of ``image`` at the flat points ``map_x``, ``map_y``; pixels outside
    the frame replicate its border.

    The points go to ``cv2.remap`` as rows of up to :data:`REMAP_ROW` (one row for 50
    candidates; its cost is mostly per row: a tall stack of 12- or 16-pixel rows takes 3x as
    long); each output pixel is a function of its own point alone, so the samples are those of
    any other layout (``tests/verifiers/test_verifier_features_oracle.py``).

    Returns
    -------
    ndarray of shape (points, channels)
    """
    count = len(map_x)
    rows = max(-(-count // REMAP_ROW), 1)
    width = max(-(-count // rows), 1)
    maps = [np.asarray(m, np.float32) for m in (map_x, map_y)]
    if rows * width != count:  # the last row filled up with points at (0, 0), cut after
        maps = [np.concatenate([m, np.zeros(rows * width - count, np.float32)]) for m in maps]
    out = cv2.remap(
        image,
        maps[0].reshape(rows, width),
        maps[1].reshape(rows, width),
        cv2.INTER_LINEAR,
        borderMode=cv2.BORDER_REPLICATE,
    )
    return out.reshape(rows * width, -1)[:count]


def stacked_hog(lightness: np.ndarray, rows: int) -> np.ndarray:
    """Per-cell HOG (L1-normalised orientation histograms) of every patch at once, equal to
    ``skimage.feature.hog`` of the stacked patches with one-cell blocks.

    ``lightness`` is (N, H, W), CIELab L of 8-bit Lab (0-255), ``H`` and ``W`` even. Each patch
    is shrunk by ``HOG_SHRINK`` (the cost of HOG grows with the pixel count), framed by two
    black rows above and below, and cut into ``rows`` full-width cells. The framed patches are
    stacked vertically: the black rows keep every gradient, and so every cell, a function of
    its own patch alone (the outer black row has no gradient, stacked or at the image border),
    and with one-cell blocks no block straddles two patches.

    The steps are ``hog``'s own (float32 central differences, then the orientation histograms
    of ``skimage.feature._hoghistogram``, the compiled routine ``hog`` calls), with its
    block-by-block L1 normalisation (a Python loop, one pass per cell) done for all cells in
    one array operation: the same numbers, which ``tests/verifiers/test_verifier.py`` checks against
    ``hog`` itself (and so against a change of that private routine).
    """
    n, height, width = lightness.shape
    small = cv2.resize(
        np.ascontiguousarray(lightness.reshape(n * height, width), np.float32) / 255.0,
        (width // HOG_SHRINK, n * height // HOG_SHRINK),
        interpolation=cv2.INTER_AREA,
    ).reshape(n, height // HOG_SHRINK, width // HOG_SHRINK)
    framed = np.zeros((n, small.shape[1] + 4, small.shape[2]), np.float32)
    framed[:, 2:-2] = small
    cell_rows, remainder = divmod(framed.shape[1], rows)
    if remainder:
        raise ValueError(f"{framed.shape[1]} framed rows do not split into {rows} cells")
    image = framed.reshape(-1, framed.shape[2])
    g_row = np.zeros_like(image)
    g_row[1:-1] = image[2:] - image[:-2]
    g_col = np.zeros_like(image)
    g_col[:, 1:-1] = image[:, 2:] - image[:, :-2]
    cells = np.zeros((n * rows, 1, ORIENTATIONS))
    hog_histograms(
        g_col.astype(float),
        g_row.astype(float),
        image.shape[1],
        cell_rows,
        image.shape[1],
        image.shape[0],
        1,
        n * rows,
        ORIENTATIONS,
        cells,
    )
    blocks = (cells / (np.abs(cells).sum(axis=-1, keepdims=True) + 1e-5)).astype(np.float32)
    return blocks.reshape(n, -1)


#: Cosine and sine of every OpenCV 8-bit hue (0-179, 2 degrees a step; 0 past 179, where
#: OpenCV puts no hue).
_HUE_COS = np.zeros(256, np.float32)
_HUE_SIN = np.zeros(256, np.float32)
_HUE_COS[:180] = np.cos(np.arange(180) * (np.pi / 90.0))
_HUE_SIN[:180] = np.sin(np.arange(180) * (np.pi / 90.0))


@njit(cache=True, nogil=True)
def fill_planes(lab: np.ndarray, hsv: np.ndarray, out: np.ndarray) -> None:
    """The :data:`COLOUR_NAMES` planes of the 8-bit ``lab`` and ``hsv`` pixels (P, 3) of a
    (K, N, 8) ``out``'s N samples of K pixels each, sample after sample, into ``out`` pixel
    after pixel, sample inside; every value in float32 as numpy computes it on float32 arrays
    (the saturation a float32 quotient by 255, the chroma the float32 root of a float32
    ``a * a + b * b``)."""
    pixels, samples = out.shape[0], out.shape[1]
    for i in range(samples):
        for p in range(pixels):
            at = i * pixels + p
            a = np.float32(lab[at, 1]) - np.float32(128.0)
            b = np.float32(lab[at, 2]) - np.float32(128.0)
            saturation = np.float32(hsv[at, 1]) / np.float32(255.0)
            row = out[p, i]
            row[0], row[1], row[2] = lab[at, 0], lab[at, 1], lab[at, 2]
            row[3], row[4] = hsv[at, 1], hsv[at, 2]
            row[5] = _HUE_COS[hsv[at, 0]] * saturation
            row[6] = _HUE_SIN[hsv[at, 0]] * saturation
            row[7] = np.sqrt(a * a + b * b)


def colour_planes(points: np.ndarray, samples: int, sizes: Sequence[int]) -> list[np.ndarray]:
    """Per-pixel L, a, b, S, V, saturation-weighted hue cosine and sine, and chroma of BGR
    ``points`` (P, 3): one block per entry ``K`` of ``sizes``, of ``samples`` samples of ``K``
    pixels each, sample after sample (one Lab and one HSV conversion for all of them, the
    planes by :func:`fill_planes`).

    Returns
    -------
    list of ndarray
        One float32 (K, ``samples``, 8) array per block, pixel after pixel with the samples
        inside (:data:`COLOUR_NAMES`).
    """
    row = np.ascontiguousarray(points, np.uint8)[None]  # one row: fastest
    lab = cv2.cvtColor(row, cv2.COLOR_BGR2LAB)[0]
    hsv = cv2.cvtColor(row, cv2.COLOR_BGR2HSV)[0]
    out = []
    start = 0
    for size in sizes:
        planes = np.empty((size, samples, len(COLOUR_NAMES)), np.float32)
        end = start + size * samples
        fill_planes(lab[start:end], hsv[start:end], planes)
        out.append(planes)
        start = end
    return out


#: The pixels of each of :data:`RING_MASKS`, as flat indices into the lens context (row-major).
RING_AT = tuple(np.flatnonzero(m) for m in RING_MASKS)


def row_percentile(values: np.ndarray, q: float) -> np.ndarray:
    """``np.percentile(values, q, axis=1)`` of a 2-D array, to the bit, by one partition.

    numpy's default (linear) rule: the rank ``q / 100 * (n - 1)`` between the sorted values
    ``a`` and ``b`` at its floor and the next, at fraction ``t``, gives ``a + (b - a) t`` when
    ``t < 0.5``, else ``b - (b - a) (1 - t)``, in the values' own type.

    Examples
    --------
    >>> row_percentile(np.array([[4.0, 1.0, 3.0, 2.0, 5.0]], np.float32), 30).tolist()
    [2.200000047683716]
    """
    n = values.shape[1]
    rank = q / 100 * (n - 1)
    low = int(rank)
    high = min(low + 1, n - 1)
    t = rank - low
    ordered = np.partition(values, (low, high), axis=1)
    a, b = ordered[:, low], ordered[:, high]
    kind = values.dtype.type
    return b - (b - a) * kind(1 - t) if t >= 0.5 else a + (b - a) * kind(t)


@njit(cache=True, nogil=True)
def deviation(values: np.ndarray, pairwise: bool) -> np.float32:
    """The float32 standard deviation of ``values`` as numpy's ``std`` takes it along an axis:
    the mean, the squared deviations and their mean, each sum :func:`pairwise_sum` where numpy
    reduces a contiguous run (``pairwise``), else one value after the other."""
    n = np.float32(len(values))
    if pairwise:
        mean = pairwise_sum(values) / n
        squares = (values - mean) * (values - mean)
        return np.sqrt(pairwise_sum(squares) / n)
    total = np.float32(0.0)
    for v in values:
        total += v
    mean = total / n
    total = np.float32(0.0)
    for v in values:
        total += (v - mean) * (v - mean)
    return np.sqrt(total / n)


@njit(cache=True, nogil=True)
def pixel_means(planes: np.ndarray, at: np.ndarray) -> np.ndarray:
    """The (N, 8) float32 mean over the pixels ``at`` of ``planes`` (pixels, N, 8), adding them
    one after the other as numpy adds along an outer axis (whole rows of candidates)."""
    total = np.zeros(planes.shape[1:], np.float32)
    for p in at:
        total += planes[p]
    return total / np.float32(len(at))


@njit(cache=True, nogil=True)
def fill_colour(lens: np.ndarray, housing: np.ndarray, rings: tuple, out: np.ndarray) -> None:
    """:func:`colour_features` into ``out`` (N, 42), but for the housing's lower-quartile
    lightness (column 36): each value by numpy's float operations in numpy's order (see there).
    """
    for k, at in enumerate(rings):
        out[:, 8 * k : 8 * k + 8] = pixel_means(lens, at)
    out[:, 27:35] = pixel_means(housing, np.arange(housing.shape[0]))
    disk = rings[0]
    for i in range(lens.shape[1]):
        light = lens[disk, i, 0].copy()
        out[i, 24] = light.max()
        # one candidate: numpy reduces the lone column as a contiguous run (pairwise)
        out[i, 25] = deviation(light, lens.shape[1] == 1)
        out[i, 26] = np.count_nonzero(lens[disk, i, 4] > 240) / len(disk)
        out[i, 35] = deviation(housing[:, i, 0].copy(), True)
        out[i, 37] = np.count_nonzero(housing[:, i, 4] < 60) / housing.shape[0]
        lens_mean_l = out[i, 0] + np.float32(1.0)
        out[i, 38] = out[i, 0] - out[i, 8]
        out[i, 39] = out[i, 0] - out[i, 16]
        out[i, 40] = (out[i, 16] + np.float32(1.0)) / lens_mean_l
        # the housing's mean lightness is a float64 column there: float64 arithmetic
        out[i, 41] = (np.float64(out[i, 27]) + 1.0) / np.float64(lens_mean_l)


def colour_features(lens: np.ndarray, housing: np.ndarray) -> np.ndarray:
    """Lab / HSV statistics of lens, annulus, surround and housing, and surround darkness.

    ``lens`` (256, N, 8) and ``housing`` (264, N, 8) are :func:`colour_planes` of the samples,
    pixel after pixel (row-major in the 16 x 16 and 22 x 12 samples), candidate inside. The
    values are those of numpy's means, deviations and shares over the pixels (the
    patch-by-patch computation before it), to the bit
    (``tests/verifiers/test_verifier_features_oracle.py``), in one compiled pass
    (:func:`fill_colour`): a mean over the pixels adds them one after the
    other, as numpy adds along an outer axis; the lightness deviations follow numpy's
    reductions of the layouts the patch-by-patch computation had (lens: candidate innermost,
    so pixel after pixel, but pairwise for a single candidate; housing: a row per candidate,
    summed pairwise). Hue enters as its cosine and sine weighted by saturation, so red near 0
    and 180 is one colour.
    """
    out = np.empty((lens.shape[1], 42), np.float32)
    fill_colour(lens, housing, RING_AT, out)
    out[:, 36] = row_percentile(np.ascontiguousarray(housing[:, :, 0].T), 25)
    return out


def geometry_features(table: np.ndarray, boxes: np.ndarray, width: int, height: int) -> np.ndarray:
    """Radius, housing shape in lens radii, the lens's place in its housing, the frame
    position, and the detector's score (raw, relative to the frame's best, and rank), of the
    candidates of a :func:`candidate_table` and their housing ``boxes``. The housing is read
    upright, as its samples are (:func:`box_maps`): its size across and along its long side, and
    the lens's place across and along it, whichever way the head hangs."""
    x, y, score, fit, has_housing = table[:, [0, 1, 3, 4, 5]].T
    radius = np.maximum(table[:, 2], 0.5)
    hw = np.maximum(boxes[:, 2] - boxes[:, 0], 1e-3)
    hh = np.maximum(boxes[:, 3] - boxes[:, 1], 1e-3)
    # the housing read upright (as the samples are): along its long side, across its short one
    wide = hw > hh
    along, across = np.where(wide, hw, hh), np.where(wide, hh, hw)
    at_x, at_y = (x - boxes[:, 0]) / hw, (y - boxes[:, 1]) / hh
    best = float(np.max(np.abs(score))) or 1.0
    rank = np.empty(len(score))
    rank[np.argsort(-score, kind="stable")] = np.arange(len(score))
    return np.column_stack(
        [
            radius,
            radius / height,
            across / radius,
            along / radius,
            np.log(along / across),
            np.where(wide, at_y, at_x),
            np.where(wide, at_x, at_y),
            fit,
            has_housing,
            x / width,
            y / height,
            score,
            score / best,
            rank,
            np.full(len(score), len(score)),
        ]
    ).astype(np.float32)


def candidate_features(image: np.ndarray, candidates: Sequence[Candidate]) -> np.ndarray:
    """The feature matrix, one row per candidate, of ``candidates`` on ``image`` (BGR uint8).

    Columns (:func:`feature_names`): HOG of the lightness (CIELab L) of the lens context (one
    cell) and of the upright housing (top, middle, bottom cells), colour statistics
    (:func:`colour_features`) and geometry (:func:`geometry_features`).
    """
    if image.ndim == 2:
        image = cv2.cvtColor(image, cv2.COLOR_GRAY2BGR)
    if not candidates:
        return np.zeros((0, len(feature_names())), np.float32)
    table = candidate_table(candidates)
    lens_boxes, house_boxes = context_boxes(table)
    n = len(candidates)
    # both stacks sampled by one remap (candidate after candidate: near points, near in memory),
    # then read pixel after pixel, candidate inside (see colour_features)
    lens_x, lens_y = box_maps(lens_boxes, (LENS_PX, LENS_PX))
    house_x, house_y = box_maps(house_boxes, HOUSING_PX, upright=True)
    points = remap_points(
        image, np.concatenate([lens_x, house_x]), np.concatenate([lens_y, house_y])
    )
    lens, housing = colour_planes(points, n, (LENS_PX * LENS_PX, HOUSING_PX[0] * HOUSING_PX[1]))
    height, width = image.shape[:2]
    return np.column_stack(
        [
            stacked_hog(lens[:, :, 0].T.reshape(n, LENS_PX, LENS_PX), 1),
            stacked_hog(housing[:, :, 0].T.reshape(n, HOUSING_PX[1], HOUSING_PX[0]), 3),
            colour_features(lens, housing),
            geometry_features(table, house_boxes, width, height),
        ]
    )


def layout() -> dict:
    """The feature layout a model is trained on: version, sizes and column names."""
    return {
        "version": FEATURE_VERSION,
        "context": CONTEXT,
        "lens_px": LENS_PX,
        "housing_px": list(HOUSING_PX),
        "hog_shrink": HOG_SHRINK,
        "orientations": ORIENTATIONS,
        "names": feature_names(),
    }


def feature_names() -> list[str]:
    """The name of every column of :func:`candidate_features`, in order."""
    hog_lens = [f"hog_lens_{o}" for o in range(ORIENTATIONS)]
    hog_housing = [
        f"hog_housing_{cell}_{o}"
        for cell in ("top", "middle", "bottom")
        for o in range(ORIENTATIONS)
    ]
    rings = [f"{ring}_{name}" for ring in RINGS for name in COLOUR_NAMES]
    peak = ["lens_L_max", "lens_L_std", "lens_overexposed"]
    house = [f"housing_{name}" for name in COLOUR_NAMES] + [
        "housing_L_std",
        "housing_L_p25",
        "housing_dark",
    ]
    darkness = [
        "lens_minus_annulus_L",
        "lens_minus_surround_L",
        "surround_over_lens_L",
        "housing_over_lens_L",
    ]
    geometry = [
        "radius",
        "radius_over_height",
        "housing_across_radii",
        "housing_along_radii",
        "housing_log_elongation",
        "lens_across_in_housing",
        "lens_along_in_housing",
        "housing_fit",
        "has_housing",
        "x_over_width",
        "y_over_height",
        "score",
        "score_over_best",
        "score_rank",
        "candidates",
    ]
    return hog_lens + hog_housing + rings + peak + house + darkness + geometry
