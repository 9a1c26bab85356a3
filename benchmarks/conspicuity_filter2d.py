"""The straightforward OpenCV version of Zheng's conspicuity map (2016, 3.2.1, Eq. 3.1-3.12), the
speed reference of ``bench_conspicuity.py``: every window average is one ``cv2.filter2D`` with
its mask as a normalised kernel (disk A1, the four quadrant parts of A1 and A2, the saturation
disk and the annulus A3), per radius, borders mirrored (reflect-101); Eq. 3.1 with its root per
radius and the maximum of Eq. 3.2. The paper's defaults (Table 5-1): radii 1..10, unit weights,
margin 0.
"""

from __future__ import annotations

import cv2
import numpy as np

from tsrkit_plugins.detectors.conspicuity import lightness, saturation


def _grid(half: int):
    dy, dx = np.mgrid[-half : half + 1, -half : half + 1]
    return dy, dx, np.hypot(dy, dx)


def _mean(feature: np.ndarray, mask: np.ndarray) -> np.ndarray:
    kernel = (mask / mask.sum()).astype(np.float32)
    return cv2.filter2D(feature, cv2.CV_32F, kernel, borderType=cv2.BORDER_REFLECT_101)


def conspicuity_filter2d(image: np.ndarray, radii=range(1, 11), margin: int = 0) -> np.ndarray:
    """Conspicuity (Eq. 3.2) of a BGR uint8 image, float32, by one ``filter2D`` per mask."""
    light = lightness(image).astype(np.float32) / 255
    sat = saturation(image).astype(np.float32) / 255
    best = np.zeros(light.shape, np.float32)
    for r in radii:
        disk = _grid(r)[2] <= r
        ld = _mean(light, disk)
        dy, dx, dist = _grid(r + margin)
        contrast = np.zeros_like(best)
        for vertical in (-1, 1):
            for horizontal in (-1, 1):
                quadrant = (dy * vertical >= 0) & (dx * horizontal >= 0)
                inner = _mean(light, quadrant & (dist <= r))
                border = _mean(light, quadrant & (dist > r))
                difference = inner - border
                difference[np.abs(difference) < 1e-6] = 0  # float32 noise the root magnifies
                contrast = np.maximum(contrast, difference)
        _, _, dist2 = _grid(2 * r)
        sd = _mean(sat, dist2 <= r)
        sa = _mean(sat, (dist2 > r) & (dist2 <= 2 * r))
        product = ld * np.maximum(contrast, 0) * np.maximum(sd, sa)
        np.maximum(best, np.cbrt(product), out=best)
    return best
