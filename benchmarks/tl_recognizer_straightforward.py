"""The straightforward version of TL-recognizer's pruning and validation (Mascetti 2016, 3.3-3.5,
4.1), the speed reference of ``bench_tl_recognizer.py --reference`` for ``tl-recognizer``.

Written the plain way: the whole frame is rotated once so that the horizon is level, every
contour is levelled on its own, and each surviving contour's patch is cropped from the levelled
frame (whole pixels), resized to the template and compared by the textbook NCC formula in
NumPy. Range filtering, contour extraction, the pruning rule, the red/yellow split and the
templates are the detector's own. The shipped detector instead samples each patch straight
from the frame at template size with one small warp and uses OpenCV's NCC; the two agree up to
the crop's rounding to whole pixels.
"""

from __future__ import annotations

import math

import cv2
import numpy as np

from tsrkit import Candidate, Frame
from tsrkit_plugins.detectors.tl_recognizer import tl_geometry as geo
from tsrkit_plugins.detectors.tl_recognizer.tl_recognizer import (
    PASSES,
    TlRecognizer,
    extract_contours,
    range_mask,
    red_or_yellow,
    reduced_hsv,
)
from tsrkit_plugins.detectors.tl_recognizer.tl_templates import patch_box, patch_size


def textbook_ncc(patch: np.ndarray, template: np.ndarray) -> float:
    """Sum over pixels and channels of the products of mean-free values (per-channel means),
    over the root of the product of their sums of squares; 0 for a flat patch."""
    p = patch.astype(np.float64) - patch.mean(axis=(0, 1))
    t = template.astype(np.float64) - template.mean(axis=(0, 1))
    denominator = math.sqrt(float((p * p).sum()) * float((t * t).sum()))
    return float((p * t).sum()) / denominator if denominator > 0 else 0.0


def levelled_frame(image: np.ndarray, roll: float, centre: tuple[float, float]) -> np.ndarray:
    """The frame rotated about ``centre`` so that the horizon is horizontal (bilinear)."""
    c, s = math.cos(roll), math.sin(roll)
    cx, cy = centre
    to_image = np.array([[c, s, cx - c * cx - s * cy], [-s, c, cy + s * cx - c * cy]])
    return cv2.warpAffine(
        image,
        to_image,
        (image.shape[1], image.shape[0]),
        flags=cv2.INTER_LINEAR | cv2.WARP_INVERSE_MAP,
        borderMode=cv2.BORDER_REPLICATE,
    )


def crop(level: np.ndarray, box_uv, centre, size: tuple[int, int]) -> np.ndarray:
    """The whole pixels of the levelled frame inside ``box_uv`` (edges relative to the centre),
    resized to ``size`` (width, height)."""
    u0, v0, u1, v1 = box_uv
    height, width = level.shape[:2]
    x0 = min(max(int(round(u0 + centre[0] + 0.5)), 0), width - 1)
    y0 = min(max(int(round(v0 + centre[1] + 0.5)), 0), height - 1)
    x1 = min(max(int(round(u1 + centre[0] + 0.5)), x0 + 1), width)
    y1 = min(max(int(round(v1 + centre[1] + 0.5)), y0 + 1), height)
    return cv2.resize(level[y0:y1, x0:x1], size, interpolation=cv2.INTER_LINEAR)


def tl_recognizer_straightforward(detector: TlRecognizer, frame: Frame) -> list[Candidate]:
    """The candidates ``detector.detect`` gives, computed the straightforward way."""
    p = detector.params
    image = frame.image
    camera = detector.camera(frame)
    hsv = reduced_hsv(image, p["resize_factor"])
    scale = (image.shape[1] / hsv.shape[1], image.shape[0] / hsv.shape[0])
    centre = ((image.shape[1] - 1) / 2, (image.shape[0] - 1) / 2)
    level = levelled_frame(image, camera.roll, centre)
    found = []
    for colour, rows in PASSES.items():
        for contour in extract_contours(range_mask(hsv, detector.ranges, rows)):
            pts = (contour.reshape(-1, 2).astype(np.float64) + 0.5) * scale - 0.5
            uv = geo.level_coordinates(pts, camera.roll, centre)
            (u0, v0), (u1, v1) = uv.min(axis=0), uv.max(axis=0)
            box = (u0 - scale[0] / 2, v0 - scale[1] / 2, u1 + scale[0] / 2, v1 + scale[1] / 2)
            if not detector._passes_pruning(box, camera):
                continue
            state = colour
            if colour == "yellowred":
                lens = crop(level, box, centre, (p["template_size"],) * 2)
                ranges = detector.ranges
                state = red_or_yellow(
                    lens, ranges[1, 0, 1], ranges[1, 0, 2], p["red_h"], p["yellow_h"]
                )
            score = max(
                textbook_ncc(
                    crop(
                        level,
                        patch_box(box, state, orientation, detector.layout),
                        centre,
                        patch_size(orientation, detector.layout),
                    ),
                    detector.templates[state, orientation],
                )
                for orientation in detector.orientations
            )
            if score > detector.threshold:
                corners = geo.image_coordinates(
                    np.array(
                        [[box[0], box[1]], [box[2], box[1]], [box[2], box[3]], [box[0], box[3]]]
                    ),
                    camera.roll,
                    centre,
                )
                (x0, y0), (x1, y1) = corners.min(axis=0), corners.max(axis=0)
                found.append(Candidate.from_box((x0, y0, x1, y1), score, state))
    return sorted(found, key=lambda c: -c.score)
