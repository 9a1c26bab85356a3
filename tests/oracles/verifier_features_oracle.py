"""The verifier's features as ``plugins/verifiers/features.py`` computed them before their speed-up:
each sample stack remapped as a tall image of its patches (one
``cv2.remap`` per stack), the HOG patches framed by ``np.pad``, the colour statistics averaged
patch by patch (8 channels last). The oracle the faster features must match to the bit. The
functions the speed-up left alone are imported."""

from __future__ import annotations

import cv2
import numpy as np
from skimage.feature._hoghistogram import hog_histograms

from tsrkit_plugins.verifiers.features import (
    COLOUR_NAMES,
    CONTEXT,
    HOG_SHRINK,
    HOUSING_PX,
    LENS_PX,
    ORIENTATIONS,
    RING_MASKS,
)

_HUE_COS = np.cos(np.arange(180) * (np.pi / 90.0)).astype(np.float32)
_HUE_SIN = np.sin(np.arange(180) * (np.pi / 90.0)).astype(np.float32)


def colour_planes(*patches):
    flat = np.concatenate([p.reshape(-1, 3) for p in patches])[None]
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


def colour_features(lens, housing):
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


def lens_context_box(c):
    """The square of ``CONTEXT`` radii around the lens (the housing fallback)."""
    half = max(c.radius, 1.0) * CONTEXT / 2
    return (c.x - half, c.y - half, c.x + half, c.y + half)


def housing_box(c):
    """The candidate's housing, or its lens context when no housing stage fitted one."""
    return c.housing if c.housing is not None else lens_context_box(c)


def geometry_features(candidates, boxes, width, height):
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


def sample_boxes(image, boxes, size, upright=False):
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


def stacked_hog(lightness, rows):
    n, height, width = lightness.shape
    small = cv2.resize(
        np.ascontiguousarray(lightness.reshape(n * height, width), np.float32) / 255.0,
        (width // HOG_SHRINK, n * height // HOG_SHRINK),
        interpolation=cv2.INTER_AREA,
    ).reshape(n, height // HOG_SHRINK, width // HOG_SHRINK)
    framed = np.pad(small, ((0, 0), (2, 2), (0, 0)))
    cell_rows = framed.shape[1] // rows
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


def candidate_features(image, candidates):
    """The feature matrix of ``candidates`` on ``image``, computed the old way."""
    if image.ndim == 2:
        image = cv2.cvtColor(image, cv2.COLOR_GRAY2BGR)
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
