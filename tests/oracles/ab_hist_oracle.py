"""ab-hist scores lens by lens, as the plugin computed them before it was batched (one
``cv2.calcHist`` and ``cv2.GaussianBlur`` per area, Eq. 3.20 per state): the oracle the batched
classifier must match exactly."""

from __future__ import annotations

import cv2
import numpy as np

from tsrkit_plugins.classifiers.ab_hist import chroma
from tsrkit_plugins.shared.regions import rings


def _histogram(lab, mask, bins, sigma):
    count = int(np.count_nonzero(mask))
    hist = cv2.calcHist([lab], [1, 2], mask.astype(np.uint8), [bins, bins], [0, 256, 0, 256])
    hist = hist / count if count else hist
    return cv2.GaussianBlur(hist, (0, 0), sigma, borderType=cv2.BORDER_CONSTANT) if sigma else hist


def _similarity(h, h_ref):
    norm = float(np.linalg.norm(h) * np.linalg.norm(h_ref))
    if norm == 0:
        return 0.0
    cosine = float(np.clip(np.sum(h * h_ref) / norm, -1.0, 1.0))
    return float(1.0 - 2.0 * np.arccos(cosine) / np.pi)


def _mean_saturation(hsv, mask):
    return float(hsv[..., 1][mask].mean()) if mask.any() else 0.0


def lens_areas(image, lens, bins, min_chroma, sigma):
    """The smoothed A1 and A3 histograms of one lens, and whether A1 is the more saturated."""
    area = rings(image, lens.x, lens.y, lens.radius)
    lab = cv2.cvtColor(area.patch, cv2.COLOR_BGR2LAB)
    hsv = cv2.cvtColor(area.patch, cv2.COLOR_BGR2HSV)
    a1_saturated = _mean_saturation(hsv, area.disk) >= _mean_saturation(hsv, area.annulus)
    coloured = chroma(lab) >= min_chroma
    a1 = _histogram(lab, area.disk & coloured, bins, sigma)
    a3 = _histogram(lab, area.annulus & coloured, bins, sigma)
    return a1, a3, a1_saturated


def lens_scores(image, lens, trained, min_chroma, sigma, mode):
    """Eq. 3.19 score of every state (rows of ``trained``) for one lens, as a list."""
    a1, a3, a1_saturated = lens_areas(image, lens, trained.shape[1], min_chroma, sigma)
    if mode == "max":
        return [max(_similarity(a1, t), _similarity(a3, t)) for t in trained]
    return [_similarity(a1 if a1_saturated else a3, t) for t in trained]
