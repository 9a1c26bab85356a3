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
from skimage.feature._hoghistogram import hog_histograms

from tsrkit.geometry import Box
from tsrkit.types import Candidate

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
#: Version of the feature layout; a model trained on another layout is refused.
FEATURE_VERSION = 2

COLOUR_NAMES = ("L", "a", "b", "S", "V", "hue_cos", "hue_sin", "chroma")
RINGS = ("lens", "annulus", "surround")


def _ring_masks(size: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Lens disk (radius 1), annulus (1-2) and surround (2-3), in lens radii, of the context."""
    unit = size / CONTEXT
    yy, xx = np.mgrid[0:size, 0:size] + 0.5
    dist = np.hypot(xx - size / 2, yy - size / 2) / unit
    return dist <= 1.0, (dist > 1.0) & (dist <= 2.0), (dist > 2.0) & (dist <= 3.0)


RING_MASKS = _ring_masks(LENS_PX)


def lens_context_box(c: Candidate) -> Box:
    """The square of ``CONTEXT`` radii around the lens (the housing fallback)."""
    half = max(c.radius, 1.0) * CONTEXT / 2
    return (c.x - half, c.y - half, c.x + half, c.y + half)


def housing_box(c: Candidate) -> Box:
    """The candidate's housing, or its lens context when no housing stage fitted one."""
    return c.housing if c.housing is not None else lens_context_box(c)


def sample_boxes(
    image: np.ndarray, boxes: np.ndarray, size: tuple[int, int], upright: bool = False
) -> np.ndarray:
    """Bilinear samples of every box of ``image`` at ``size`` (width, height), stacked.

    One ``cv2.remap`` over the whole stack; pixels outside the frame replicate its border.
    With ``upright``, a box wider than tall is read transposed, so its long side runs down.

    Returns
    -------
    ndarray of shape (N, height, width, channels)
    """
    width, height = size
    n = len(boxes)
    x0, y0, x1, y1 = (boxes[:, k, None, None] for k in range(4))
    v, u = np.mgrid[0:height, 0:width].astype(np.float32) + 0.5
    map_x = x0 + u * (x1 - x0) / width - 0.5
    map_y = y0 + v * (y1 - y0) / height - 0.5
    if upright:
        wide = (boxes[:, 2] - boxes[:, 0] > boxes[:, 3] - boxes[:, 1])[:, None, None]
        map_x = np.where(wide, x0 + v * (x1 - x0) / height - 0.5, map_x)
        map_y = np.where(wide, y0 + u * (y1 - y0) / width - 0.5, map_y)
    out = cv2.remap(
        image,
        map_x.reshape(n * height, width).astype(np.float32),
        map_y.reshape(n * height, width).astype(np.float32),
        cv2.INTER_LINEAR,
        borderMode=cv2.BORDER_REPLICATE,
    )
    return out.reshape(n, height, width, -1)


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
    one array operation: the same numbers, which ``tests/test_verifier.py`` checks against
    ``hog`` itself (and so against a change of that private routine).
    """
    n, height, width = lightness.shape
    small = cv2.resize(
        np.ascontiguousarray(lightness.reshape(n * height, width), np.float32) / 255.0,
        (width // HOG_SHRINK, n * height // HOG_SHRINK),
        interpolation=cv2.INTER_AREA,
    ).reshape(n, height // HOG_SHRINK, width // HOG_SHRINK)
    framed = np.pad(small, ((0, 0), (2, 2), (0, 0)))
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


#: Cosine and sine of every OpenCV 8-bit hue (0-179, 2 degrees a step).
_HUE_COS = np.cos(np.arange(180) * (np.pi / 90.0)).astype(np.float32)
_HUE_SIN = np.sin(np.arange(180) * (np.pi / 90.0)).astype(np.float32)


def colour_planes(*patches: np.ndarray) -> list[np.ndarray]:
    """Per-pixel L, a, b, S, V, saturation-weighted hue cosine and sine, and chroma of each
    BGR stack in ``patches`` (one Lab and one HSV conversion for all of them).

    Returns
    -------
    list of ndarray
        One float32 array per input, shaped like it with 8 channels (:data:`COLOUR_NAMES`).
    """
    flat = np.concatenate([p.reshape(-1, 3) for p in patches])[None]  # one row: fastest
    lab = cv2.cvtColor(flat, cv2.COLOR_BGR2LAB)[0].T.astype(np.float32)
    hsv = cv2.cvtColor(flat, cv2.COLOR_BGR2HSV)[0].T
    hue, saturation = hsv[0], hsv[1].astype(np.float32) / 255.0
    a, b = lab[1] - 128.0, lab[2] - 128.0
    planes = np.stack(
        [
            *lab,
            hsv[1].astype(np.float32),
            hsv[2].astype(np.float32),
            _HUE_COS[hue] * saturation,
            _HUE_SIN[hue] * saturation,
            np.sqrt(a * a + b * b),
        ],
        axis=-1,
    )
    ends = np.cumsum([0] + [p.size // 3 for p in patches])
    return [
        planes[start:end].reshape(*p.shape[:-1], len(COLOUR_NAMES))
        for p, start, end in zip(patches, ends[:-1], ends[1:])
    ]


def colour_features(lens: np.ndarray, housing: np.ndarray) -> np.ndarray:
    """Lab / HSV statistics of lens, annulus, surround and housing, and surround darkness.

    ``lens`` (N, 16, 16, 8) and ``housing`` (N, 22, 12, 8) are :func:`colour_planes` of the
    samples. Hue enters as its cosine and sine weighted by saturation, so red near 0 and 180
    is one colour.
    """
    rings = [lens[:, m].mean(axis=1) for m in RING_MASKS]
    lens_l = lens[..., 0][:, RING_MASKS[0]]
    lens_v = lens[..., 4][:, RING_MASKS[0]]
    peak = np.column_stack([lens_l.max(axis=1), lens_l.std(axis=1), (lens_v > 240).mean(axis=1)])
    house = housing.reshape(len(housing), -1, len(COLOUR_NAMES))
    light = house[..., 0]
    house_stats = np.column_stack(
        [
            house.mean(axis=1),
            light.std(axis=1),
            np.percentile(light, 25, axis=1),
            (house[..., 4] < 60).mean(axis=1),
        ]
    )
    lens_mean_l = rings[0][:, 0] + 1.0
    darkness = np.column_stack(
        [
            rings[0][:, 0] - rings[1][:, 0],
            rings[0][:, 0] - rings[2][:, 0],
            (rings[2][:, 0] + 1.0) / lens_mean_l,
            (house_stats[:, 0] + 1.0) / lens_mean_l,
        ]
    )
    return np.column_stack([*rings, peak, house_stats, darkness]).astype(np.float32)


def geometry_features(
    candidates: Sequence[Candidate], boxes: np.ndarray, width: int, height: int
) -> np.ndarray:
    """Radius, housing shape in lens radii, the lens's place in its housing, the frame
    position, and the detector's score (raw, relative to the frame's best, and rank)."""
    xyrs = np.array(
        [
            (
                c.x,
                c.y,
                max(c.radius, 0.5),
                c.score,
                -1.0 if c.housing_score is None else c.housing_score,
                c.housing is not None,
            )
            for c in candidates
        ],
        np.float64,
    )
    x, y, radius, score, fit, has_housing = xyrs.T
    hw = np.maximum(boxes[:, 2] - boxes[:, 0], 1e-3)
    hh = np.maximum(boxes[:, 3] - boxes[:, 1], 1e-3)
    best = float(np.max(np.abs(score))) or 1.0
    rank = np.empty(len(score))
    rank[np.argsort(-score, kind="stable")] = np.arange(len(score))
    return np.column_stack(
        [
            radius,
            radius / height,
            hw / radius,
            hh / radius,
            np.log(hh / hw),
            (x - boxes[:, 0]) / hw,
            (y - boxes[:, 1]) / hh,
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
    lens_boxes = np.array([lens_context_box(c) for c in candidates], np.float32)
    house_boxes = np.array([housing_box(c) for c in candidates], np.float32)
    lens, housing = colour_planes(
        sample_boxes(image, lens_boxes, (LENS_PX, LENS_PX)),
        sample_boxes(image, house_boxes, HOUSING_PX, upright=True),
    )
    height, width = image.shape[:2]
    return np.column_stack(
        [
            stacked_hog(lens[..., 0], 1),
            stacked_hog(housing[..., 0], 3),
            colour_features(lens, housing),
            geometry_features(candidates, house_boxes, width, height),
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
        "housing_w_radii",
        "housing_h_radii",
        "housing_log_aspect",
        "lens_x_in_housing",
        "lens_y_in_housing",
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
