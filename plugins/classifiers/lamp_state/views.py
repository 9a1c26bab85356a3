"""Training views for ``lamp-state``: the part of a frame its features read, and vertical heads
turned a quarter into horizontal ones.

Beyond the documents. No openly licensed set holds horizontal heads with their housings, and
their order differs by country; turned vertical heads (a quarter either way, so red lands on
the left or on the right) teach the model the horizontal reading of
:func:`~.features.turned_by_colour`, and how far a lamp's colour places it.
"""

from __future__ import annotations

from collections.abc import Sequence

import cv2
import numpy as np

Box = tuple[float, float, float, float]


def around_lights(image: np.ndarray, boxes: Sequence[Box]) -> tuple[np.ndarray, list[Box]]:
    """The part of ``image`` that lamp-state's features of ``boxes`` read, and the boxes in it:
    their bounding box widened by each box's longer side (the lit lens patch reaches at most
    0.65 of a box's shorter side past its centre), cut at the image's border (as the features
    cut it) and at whole pixels, so every pixel the features read keeps its value and
    position relative to its box. Colour jitter and turns of training views then work on this
    part only, not on the whole frame."""
    height, width = image.shape[:2]
    sides = np.array([max(x1 - x0, y1 - y0) for x0, y0, x1, y1 in boxes])
    bounds = np.array(boxes, np.float64)
    x0 = int(max(0, np.floor((bounds[:, 0] - sides).min())))
    y0 = int(max(0, np.floor((bounds[:, 1] - sides).min())))
    x1 = int(min(width, np.ceil((bounds[:, 2] + sides).max())))
    y1 = int(min(height, np.ceil((bounds[:, 3] + sides).max())))
    if x1 <= x0 or y1 <= y0:  # every box wholly outside the image: nothing is read
        return image, list(boxes)
    moved = [(bx0 - x0, by0 - y0, bx1 - x0, by1 - y0) for bx0, by0, bx1, by1 in boxes]
    return image[y0:y1, x0:x1], moved


def quarter_turn(
    image: np.ndarray, boxes: Sequence[Box], clockwise: bool
) -> tuple[np.ndarray, list[Box]]:
    """``image`` turned a quarter (``clockwise`` or not) and ``boxes`` with it.

    Examples
    --------
    >>> image = np.zeros((4, 6, 3), np.uint8)
    >>> quarter_turn(image, [(1.0, 0.0, 2.0, 3.0)], True)[1]
    [(1.0, 1.0, 4.0, 2.0)]
    >>> quarter_turn(image, [(1.0, 0.0, 2.0, 3.0)], False)[1]
    [(0.0, 4.0, 3.0, 5.0)]
    """
    height, width = image.shape[:2]
    if clockwise:  # (x, y) -> (height - y, x)
        turned = cv2.rotate(image, cv2.ROTATE_90_CLOCKWISE)
        return turned, [(height - y1, x0, height - y0, x1) for x0, y0, x1, y1 in boxes]
    turned = cv2.rotate(image, cv2.ROTATE_90_COUNTERCLOCKWISE)  # (x, y) -> (y, width - x)
    return turned, [(y0, width - x1, y1, width - x0) for x0, y0, x1, y1 in boxes]
