"""The straightforward NumPy/OpenCV version of LAB-FRST (Zheng 2016, 5.2.2; Loy & Zelinsky 2003),
the speed reference of ``bench_lab_frst.py`` for ``lab-frst``.

Each step is written the plain way: votes added with ``np.add.at`` on the image grid after a
bounds check, F_n with the power computed per pixel, and the smoothing A_n as one non-separable
2-D Gaussian ``cv2.filter2D`` per radius; the feature map and the spot extraction are the
detector's own (they are not what the transform's speed is about). Same defaults as the
detector: radii 1..10, alpha 3, beta 0, half-maximum spots, five per polarity.
"""

from __future__ import annotations

import cv2
import numpy as np

from tsrkit import Candidate
from tsrkit_plugins.detectors.frst.frst import gaussian_kernel, kappa
from tsrkit_plugins.detectors.frst.lab_frst import lab_feature_map, spot_candidates


def frst_straightforward(
    image: np.ndarray, radii=range(1, 11), alpha: float = 3.0, beta: float = 0.0, sign: int = 1
) -> np.ndarray:
    """FRST of a 2-D map voting only at the positively (``sign=1``, bright) or negatively
    (``sign=-1``, dark) affected pixels, summed over the radii; float64."""
    image = np.asarray(image, np.float32)
    gx = cv2.Sobel(image, cv2.CV_64F, 1, 0, ksize=3, borderType=cv2.BORDER_REFLECT_101)
    gy = cv2.Sobel(image, cv2.CV_64F, 0, 1, ksize=3, borderType=cv2.BORDER_REFLECT_101)
    magnitude = np.hypot(gx, gy)
    rows, cols = np.nonzero((magnitude > beta * magnitude.max()) & (magnitude > 0))
    norm = magnitude[rows, cols]
    ux, uy = gx[rows, cols] / norm, gy[rows, cols] / norm
    height, width = image.shape
    total = np.zeros(image.shape)
    for n in radii:
        orientation = np.zeros(image.shape)
        projection = np.zeros(image.shape)
        r = rows + sign * np.rint(uy * n).astype(int)
        c = cols + sign * np.rint(ux * n).astype(int)
        inside = (r >= 0) & (r < height) & (c >= 0) & (c < width)
        np.add.at(orientation, (r[inside], c[inside]), sign)
        np.add.at(projection, (r[inside], c[inside]), sign * norm[inside])
        k = kappa(n)
        clipped = np.clip(orientation, -k, k)
        strength = projection / k * np.power(np.abs(clipped) / k, alpha)
        g = gaussian_kernel(n)
        total += cv2.filter2D(strength, cv2.CV_64F, g @ g.T, borderType=cv2.BORDER_CONSTANT)
    return total


def lab_frst_straightforward(
    image: np.ndarray, fraction: float = 0.5, top: int = 5, alpha: float = 3.0
) -> list[Candidate]:
    """LAB-FRST candidates of a BGR uint8 frame with :func:`frst_straightforward`."""
    feature = lab_feature_map(image)
    bright = frst_straightforward(np.maximum(feature, 0), alpha=alpha, sign=1)
    dark = -frst_straightforward(np.minimum(feature, 0), alpha=alpha, sign=-1)
    found = spot_candidates(bright.astype(np.float32), fraction, top, "red")
    found += spot_candidates(dark.astype(np.float32), fraction, top, "green")
    return sorted(found, key=lambda c: -c.score)
