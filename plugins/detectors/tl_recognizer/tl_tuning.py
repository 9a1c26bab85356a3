"""Training TL-recognizer on annotated frames: range bounds (Figure 16) and threshold T (5.2).

``derive_ranges`` runs the extraction with broad ranges, keeps the contours whose centre falls
in an annotated box of the same colour, gathers their pixels (without white V = 255 ones) and
takes the smallest ranges that hold them. ``tune_threshold`` sets T to the highest NCC of a
pruned patch that is not a light, so the tuning set is recognised with precision 1.
"""

from __future__ import annotations

import cv2
import numpy as np

from tsrkit.api import Model, TsrkitError, centre_hits
from tsrkit_plugins.detectors.tl_recognizer.tl_recognizer import (
    PASSES,
    extract_contours,
    range_mask,
    reduced_hsv,
)

#: The broad first ranges standing in for the paper's "few manually sampled pixels" (5.2):
#: Table 6 widened by 20 hue steps and with S, V from 40.
BROAD_RANGES = np.array(
    [
        [[50, 40, 40], [115, 255, 255]],
        [[0, 40, 40], [45, 255, 255]],
        [[146, 40, 40], [180, 255, 255]],
    ],
    dtype=np.float64,
)
#: Which annotated states each colour pass collects pixels for.
PASS_STATES = {"green": ("green",), "yellowred": ("red", "yellow")}


def contour_pixels(hsv: np.ndarray, mask: np.ndarray, contour: np.ndarray) -> np.ndarray:
    """HSV values (N, 3) of the pixels inside a contour that passed the range filter ``mask``."""
    x, y, w, h = cv2.boundingRect(contour)
    inside = np.zeros((h, w), np.uint8)
    cv2.drawContours(inside, [contour - (x, y)], -1, 255, thickness=cv2.FILLED)
    return hsv[y : y + h, x : x + w][(inside > 0) & (mask[y : y + h, x : x + w] > 0)]


def lens_contour(contour: np.ndarray, scale: np.ndarray, boxes) -> bool:
    """A contour centred in an annotated box and not larger than the box (full-res pixels)."""
    x, y, w, h = cv2.boundingRect(contour)
    centre = (np.array([x + w / 2, y + h / 2]) * scale)[None, :]
    hits = centre_hits(centre, boxes)[0]
    areas = np.array([(b[2] - b[0]) * (b[3] - b[1]) for b in boxes])
    return bool(np.any(hits & (w * h * scale[0] * scale[1] <= areas)))


def annotated_lens_pixels(samples, factor: int) -> dict[str, np.ndarray]:
    """Pixels of broad-range contours that fit a box of their colour, per pass (Figure 16)."""
    found: dict[str, list[np.ndarray]] = {colour: [] for colour in PASSES}
    for sample in samples:
        frame = sample.load()
        hsv = reduced_hsv(frame.image, factor)
        scale = np.array([frame.width / hsv.shape[1], frame.height / hsv.shape[0]])
        for colour, rows in PASSES.items():
            boxes = [a.bbox for a in sample.annotations if a.state in PASS_STATES[colour]]
            if not boxes:
                continue
            mask = range_mask(hsv, BROAD_RANGES, rows)
            for contour in extract_contours(mask):
                if lens_contour(contour, scale, boxes):
                    found[colour].append(contour_pixels(hsv, mask, contour))
    return {
        colour: np.concatenate(parts) if parts else np.zeros((0, 3), np.uint8)
        for colour, parts in found.items()
    }


def smallest_ranges(
    pixels: dict[str, np.ndarray], fallback: np.ndarray, coverage: float
) -> np.ndarray:
    """Ranges holding a ``coverage`` share of the lens pixels; ``fallback`` rows where none.

    White pixels (V = 255) are left out as in 5.2; dark ones never pass the broad filter. Hue
    splits at 90 into the two yellowRed filters, whose outer ends stay at 0 and 180. S and V
    share one lower bound over every colour (Table 6) and keep 255 as upper bound.
    """
    lo_q, hi_q = 1 - coverage, coverage
    ranges = fallback.copy()
    green = pixels["green"][pixels["green"][:, 2] < 255]
    yellowred = pixels["yellowred"][pixels["yellowred"][:, 2] < 255]
    hue = yellowred[:, 0].astype(np.float64)
    if len(green):
        ranges[0, :, 0] = np.quantile(green[:, 0], [lo_q, hi_q])
    if np.any(hue < 90):
        ranges[1, :, 0] = 0, np.quantile(hue[hue < 90], hi_q)
    if np.any(hue >= 90):
        ranges[2, :, 0] = np.quantile(hue[hue >= 90], lo_q), 180
    every = np.concatenate([green, yellowred])
    if len(every):
        ranges[:, 0, 1:] = np.quantile(every[:, 1:], lo_q, axis=0)
        ranges[:, 1, 1:] = 255
    return _rounded(ranges)


def _rounded(ranges: np.ndarray) -> np.ndarray:
    """Integer bounds that still include every pixel: minima down, maxima up."""
    out = ranges.copy()
    out[:, 0] = np.floor(out[:, 0])
    out[:, 1] = np.ceil(out[:, 1])
    return out


def patch_scores(detector, samples) -> tuple[np.ndarray, np.ndarray]:
    """NCC of every pruned patch, split into lights and others by the annotations (5.2).

    A patch is a light when its centre lies in the minimum enclosing circle of an annotated box
    (Zheng 5.2.1). Returns ``(lights, others)``, two float arrays.
    """
    lights: list[float] = []
    others: list[float] = []
    for sample in samples:
        candidates = detector.scored(sample.load())
        if not candidates:
            continue
        boxes = [a.bbox for a in sample.annotations]
        centres = [(c.x, c.y) for c in candidates]
        inside = np.asarray(
            centre_hits(centres, boxes).any(axis=1) if boxes else np.zeros(len(candidates), bool)
        )
        for candidate, hit in zip(candidates, inside):
            (lights if hit else others).append(candidate.score)
    return np.array(lights, dtype=np.float64), np.array(others, dtype=np.float64)


def tune_threshold(detector, samples) -> tuple[float | None, int, int]:
    """Highest NCC of a pruned patch centred in no annotated box (5.2), and the patch counts.

    Returns ``(T, lights, others)``; T is None when no patch outside the boxes survived pruning.
    """
    lights, others = patch_scores(detector, samples)
    return (float(others.max()) if len(others) else None), len(lights), len(others)


def fit_model(detector, samples) -> Model:
    """Fit ``detector`` (a TlRecognizer) on annotated ``samples``: ranges, then T (5.2).

    The ranges stay as they are when the detector's ``fit_ranges`` is false.
    """
    samples = list(samples)
    if not samples:
        raise TsrkitError("tl-recognizer: cannot train on an empty dataset")
    pixels = {colour: np.zeros((0, 3), np.uint8) for colour in PASSES}
    if detector.params["fit_ranges"]:
        pixels = annotated_lens_pixels(samples, detector.params["resize_factor"])
        detector.ranges = smallest_ranges(pixels, detector.ranges, detector.params["fit_coverage"])
    threshold, lights, others = tune_threshold(detector, samples)
    if threshold is not None:
        detector.threshold = threshold
    return Model(
        arrays={"ranges": detector.ranges, "threshold": np.array(detector.threshold)},
        info={
            "lens_pixels": {k: int(len(v)) for k, v in pixels.items()},
            "patches_in_boxes": lights,
            "patches_outside_boxes": others,
            "threshold_from_data": threshold is not None,
        },
    )
