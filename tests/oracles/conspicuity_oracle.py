"""Straightforward reference for Zheng's conspicuity map and DRMShift (2016, 3.2.1-3.2.2).

Each window average is a direct correlation of the feature with its mask (disk A1, quadrant
parts of A1 and A2, annulus A3), borders mirrored like the fast code; Eq. 3.1 is evaluated as
written, root included, for every radius. Written for clarity, not speed.
"""

from __future__ import annotations

import numpy as np
from scipy import ndimage

from tsrkit_plugins.detectors.conspicuity import lightness, saturation


def distance_grid(half_side: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Offsets ``dy, dx`` of a square window and their Euclidean distance from its centre."""
    dy, dx = np.mgrid[-half_side : half_side + 1, -half_side : half_side + 1]
    return dy, dx, np.hypot(dy, dx)


def window_mean(feature: np.ndarray, mask: np.ndarray) -> np.ndarray:
    """Mean of ``feature`` over the pixels flagged by ``mask`` around every pixel."""
    total = ndimage.correlate(feature, mask.astype(np.float64), mode="mirror")
    return total / mask.sum()


def disk_mask(radius: int, half_side: int) -> np.ndarray:
    """Eq. 3.4: pixels within ``radius`` of the centre."""
    return distance_grid(half_side)[2] <= radius


def quadrant_masks(radius: int, margin: int, vertical: int, horizontal: int):
    """Eq. 3.9: the A1 part (+1) and A2 part (-1) of one quadrant of the bounding box."""
    dy, dx, dist = distance_grid(radius + margin)
    quadrant = (dy * vertical >= 0) & (dx * horizontal >= 0)
    return quadrant & (dist <= radius), quadrant & (dist > radius)


def conspicuity_at_radius(
    light: np.ndarray,
    sat: np.ndarray,
    radius: int,
    weights,
    margin: int = 0,
    quadrant_rule: str = "max",
) -> np.ndarray:
    """Eq. 3.1 for one radius, each feature by direct correlation with its mask."""
    ld = window_mean(light, disk_mask(radius, radius))
    contrasts = []
    for vertical in (-1, 1):
        for horizontal in (-1, 1):
            inner, border = quadrant_masks(radius, margin, vertical, horizontal)
            difference = window_mean(light, inner) - window_mean(light, border)
            # Both means are multiples of 1/(255 n); anything this small is rounding noise,
            # which the root of Eq. 3.1 would magnify.
            difference[np.abs(difference) < 1e-9] = 0.0
            contrasts.append(np.maximum(0.0, difference))
    lc = np.max(contrasts, axis=0) if quadrant_rule == "max" else np.min(contrasts, axis=0)
    sd = window_mean(sat, disk_mask(radius, 2 * radius))
    annulus = ~disk_mask(radius, 2 * radius) & disk_mask(2 * radius, 2 * radius)
    sa = window_mean(sat, annulus)
    w_l, w_lc, w_s = weights
    product = ld**w_l * lc**w_lc * np.maximum(sd, sa) ** w_s
    return product ** (1.0 / (w_l + w_lc + w_s))


def conspicuity_reference(
    image: np.ndarray,
    radii=tuple(range(1, 11)),
    weights=(1, 1, 1),
    margin: int = 0,
    quadrant_rule: str = "max",
):
    """Eq. 3.2: maximum over the radius set; returns (values, arg-max radius, per-radius stack)."""
    light = lightness(image).astype(np.float64) / 255.0
    sat = saturation(image).astype(np.float64) / 255.0
    stack = np.stack(
        [conspicuity_at_radius(light, sat, r, weights, margin, quadrant_rule) for r in radii]
    )
    return stack.max(axis=0), np.asarray(radii)[np.argmax(stack, axis=0)], stack


def drmshift_reference(cm: np.ndarray, rm: np.ndarray, start, h_c: float = 0.5, n_max: int = 10):
    """Algorithm 3-1 line by line for one start point, with the fast code's reading: the window
    is centred on the rounded centre, pixels outside the image are skipped."""
    height, width = cm.shape
    i, j = float(start[0]), float(start[1])
    d = h_c
    r = 0
    while n_max > 0 and d >= h_c:
        n_max -= 1
        ci = min(max(int(np.rint(i)), 0), height - 1)
        cj = min(max(int(np.rint(j)), 0), width - 1)
        r = int(rm[ci, cj])
        m00 = m01 = m10 = 0.0
        for ii in range(ci - r, ci + r + 1):
            for jj in range(cj - r, cj + r + 1):
                inside = 0 <= ii < height and 0 <= jj < width
                if inside and (ii - ci) ** 2 + (jj - cj) ** 2 <= r * r:
                    weight = float(cm[ii, jj])
                    m00 += weight
                    m01 += ii * weight
                    m10 += jj * weight
        if m00 > 0:
            i_tmp, j_tmp = i, j
            i, j = m01 / m00, m10 / m00
            d = float(np.hypot(i - i_tmp, j - j_tmp))
        else:
            break
    ci = min(max(int(np.rint(i)), 0), height - 1)
    cj = min(max(int(np.rint(j)), 0), width - 1)
    return (i, j), int(rm[ci, cj])
