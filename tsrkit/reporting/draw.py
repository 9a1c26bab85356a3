"""Overlays: detections drawn on the frame, coloured by state."""

from __future__ import annotations

from collections.abc import Iterable

import cv2
import numpy as np

from tsrkit.core.types import Detection

__all__ = ["STATE_COLOURS", "draw_detections"]

#: BGR colour of each state on overlays.
STATE_COLOURS = {
    "red": (0, 0, 255),
    "yellow": (0, 215, 255),
    "green": (0, 200, 0),
    "off": (128, 128, 128),
    "unknown": (255, 255, 255),
}


def draw_detections(image: np.ndarray, detections: Iterable[Detection]) -> np.ndarray:
    """Return a copy of ``image`` with a circle and a box per detection, coloured by state."""
    out = image.copy()
    for det in detections:
        c = det.candidate
        colour = STATE_COLOURS.get(det.state, STATE_COLOURS["unknown"])
        x0, y0, x1, y1 = (int(round(v)) for v in c.bbox)
        cv2.rectangle(out, (x0, y0), (x1, y1), colour, 1)
        cv2.circle(
            out,
            (int(round(c.x)), int(round(c.y))),
            max(1, int(round(c.radius))),
            colour,
            1,
            cv2.LINE_AA,
        )
        cv2.putText(
            out,
            det.state,
            (x0, max(10, y0 - 3)),
            cv2.FONT_HERSHEY_SIMPLEX,
            0.35,
            colour,
            1,
            cv2.LINE_AA,
        )
    return out
