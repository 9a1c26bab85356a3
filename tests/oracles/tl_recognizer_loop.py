"""TL-recognizer's validation contour by contour, as an equality oracle (Mascetti 2016, 3.5, 4.1).

Every contour that survives pruning is validated on its own: its lens patch sampled at
template size, the red/yellow split on that patch alone, then OpenCV's NCC of the patch the
state implies, for each allowed orientation, the best kept. Extraction and pruning are the
detector's own steps; this is how the detector validated before it sampled, split and screened
the patches of a pass together.
"""

from __future__ import annotations

import numpy as np

from tsrkit.core.types import Candidate, Frame
from tsrkit_plugins.detectors.tl_recognizer.tl_recognizer import (
    PASSES,
    enclosed_cores,
    extract_contours,
    image_boxes,
    levelled_boxes,
    range_mask,
    red_or_yellow,
    reduced_hsv,
)
from tsrkit_plugins.detectors.tl_recognizer.tl_templates import (
    extract_patch,
    ncc,
    patch_box,
    patch_size,
)


def scored_loop(detector, frame: Frame) -> list[Candidate]:
    """Every pruned contour of ``frame``, scored by NCC one at a time, best first."""
    p = detector.params
    image = frame.image
    hsv = reduced_hsv(image, p["resize_factor"])
    camera = detector.camera(frame)
    scale = (image.shape[1] / hsv.shape[1], image.shape[0] / hsv.shape[0])
    centre = ((image.shape[1] - 1) / 2, (image.shape[0] - 1) / 2)
    found = []
    for colour, rows in PASSES.items():
        mask = range_mask(hsv, detector.ranges, rows)
        if p["fill_cores"]:
            mask = enclosed_cores(hsv, mask, p["core_v"], p["ring_share"])
        boxes = levelled_boxes(extract_contours(mask), scale, camera.roll, centre)
        kept = [box for box in map(tuple, boxes) if detector._passes_pruning(box, camera)]
        for box_uv, box in zip(
            kept, image_boxes(np.array(kept).reshape(-1, 4), camera.roll, centre)
        ):
            state, lens = colour, None
            if colour == "yellowred":
                lens = extract_patch(image, box_uv, camera.roll, centre, p["template_size"])
                ranges = detector.ranges
                state = red_or_yellow(
                    lens, ranges[1, 0, 1], ranges[1, 0, 2], p["red_h"], p["yellow_h"]
                )
            scores = []
            for orientation in detector.orientations:
                patch_uv = patch_box(box_uv, state, orientation, detector.layout)
                size = patch_size(orientation, detector.layout)
                if lens is not None and patch_uv == box_uv and size == lens.shape[1::-1]:
                    patch = lens
                else:
                    patch = extract_patch(image, patch_uv, camera.roll, centre, size)
                scores.append(ncc(patch, detector.templates[state, orientation]))
            found.append(Candidate.from_box(tuple(box), max(scores), state))
    return sorted(found, key=lambda c: -c.score)
