"""A dataset's box margin: how far its annotated boxes reach beyond the housing itself.

Datasets draw housing boxes by different conventions: cinTA's hug the head, DTLD's carry a
band of background of about a quarter of the head's width on every side. A fit that finds the
right head then still scores IoU < 0.5 against a loose box. Two tools keep "wrong housing"
apart from "annotation margin":

- :func:`margin_free_iou`, a measure blind to the convention (the best IoU over boxes grown or
  shrunk by up to :data:`MAX_MARGIN` of their short side);
- :func:`learn_margin`, the convention of a set learned from its **training** annotations (the
  housing stage's ``margin`` applies it; learning it from a test split would grade the fit on
  the answers).
"""

from __future__ import annotations

from collections.abc import Iterable

import cv2
import numpy as np

from tsrkit.api import Sample, iou_matrix
from tsrkit_plugins.shared.regions import find_lens
from tsrkit_plugins.verifiers.housing.fit import fit_housings

#: Largest margin :func:`margin_free_iou` allows for, as a share of the box's short side.
MAX_MARGIN = 0.25
#: Margins tried by :func:`margin_free_iou`.
MARGINS = np.linspace(-MAX_MARGIN, MAX_MARGIN, 11)


def widen(boxes: np.ndarray, margin: float, pad: float = 0.0) -> np.ndarray:
    """``boxes`` (N, 4) grown on every side by ``margin`` x their short side plus ``pad``
    pixels.

    Examples
    --------
    >>> widen(np.array([[0.0, 0.0, 10.0, 20.0]]), 0.1, pad=1.0).tolist()
    [[-2.0, -2.0, 12.0, 22.0]]
    """
    short = np.minimum(boxes[:, 2] - boxes[:, 0], boxes[:, 3] - boxes[:, 1])
    return boxes + np.outer(margin * short + pad, [-1.0, -1.0, 1.0, 1.0])


def margin_free_iou(truth, fit) -> float:
    """The best IoU of the box ``fit`` with the annotated box ``truth`` grown or shrunk on every
    side by up to :data:`MAX_MARGIN` of its short side."""
    box = np.asarray(truth, np.float64)
    short = min(box[2] - box[0], box[3] - box[1])
    grown = box + np.outer(MARGINS * short, [-1.0, -1.0, 1.0, 1.0])
    return float(iou_matrix(list(grown), [fit]).max())


def learn_margin(samples: Iterable[Sample]) -> float:
    """The median margin, per side, between the annotated housings of ``samples`` and the fits
    from their lit lens (:func:`~tsrkit_plugins.shared.regions.find_lens`), as a share of
    the fit's short side; fits of another housing (margin-free IoU < 0.5) are left out, and
    a set whose boxes are tighter than the fits gets 0."""
    margins = []
    for sample in samples:
        boxes = [a.bbox for a in sample.annotations]
        if not boxes:
            continue
        frame = sample.load()
        gray = cv2.cvtColor(frame.image, cv2.COLOR_BGR2GRAY)
        lenses = [find_lens(frame.image, b) for b in boxes]
        fits, _, _ = fit_housings(gray, [(c.x, c.y, c.radius) for c in lenses])
        for box, fit in zip(boxes, fits):
            if margin_free_iou(box, fit) < 0.5:
                continue
            short = min(fit[2] - fit[0], fit[3] - fit[1])
            margins += [(fit[k] - box[k]) * (1 if k < 2 else -1) / short for k in range(4)]
    return max(float(np.median(margins)), 0.0) if margins else 0.0
