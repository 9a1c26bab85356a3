"""Re-finding the lit lens near a candidate before the housing search (beyond the
documents).

A candidate's centre and radius are the detector's: ``union`` keeps the largest radius any
member found (blobs of 40-70 px at 1280x720), FRST-like detectors give almost none, and the
centre may sit on the lens's rim. The housing layouts are drawn in units of the lens radius,
so the fit starts from a measured lens: around each candidate, squares of half-size ``s``
(:data:`SCALES`) at the centre and at offsets of ``s / 2`` (:data:`OFFSETS`) are compared with
the square ring between ``s`` and ``2 s`` around them, by the centre-surround contrast
``(inner - ring) / max(ring, FLOOR)`` of their mean grey levels (a box approximation of a
difference of Gaussians, as in SURF's box filters). The best square is the lit lens: its
centre, and ``RADIUS_PER_HALF_SIDE x s`` as the radius (a lit disc's contrast peaks at
``s`` about 0.8 of its radius, calibrated on rendered heads). A candidate with no square above
:data:`MIN_CONTRAST` keeps its own lens.

Every mean is four look-ups in the frame's integral image, all candidates in one compiled pass
(:func:`best_squares`: the float64 operations of the NumPy form before it, in its order).
"""

from __future__ import annotations

import numpy as np
from numba import njit

from tsrkit_plugins.verifiers.housing.boxes import box_sum

#: Half-sides (px) of the squares tried.
SCALES = np.array([1.0, 1.4, 2.0, 2.8, 4.0, 5.6, 8.0, 11.0, 16.0, 22.0, 32.0])
#: Offsets of the square's centre from the candidate's, in half-sides.
OFFSETS = np.array([(dx, dy) for dx in (-0.5, 0.0, 0.5) for dy in (-0.5, 0.0, 0.5)])
#: Lens radius per half-side of the best square.
RADIUS_PER_HALF_SIDE = 1.25
#: Lowest centre-surround contrast read as a lit lens.
MIN_CONTRAST = 0.5
#: Grey level below which the ring's mean no longer divides the contrast (dark surrounds).
FLOOR = 8.0


@njit(cache=True, nogil=True, inline="always")
def square_mean(table: np.ndarray, x: float, y: float, half: float) -> tuple[float, float]:
    """Mean grey level (0 when empty) and pixel count of the square of half-side ``half``
    around ``(x, y)``."""
    total, count = box_sum(table, x - half, y - half, x + half, y + half)
    return total / max(count, 1.0), count


@njit(cache=True, nogil=True)
def best_squares(
    table: np.ndarray, x: np.ndarray, y: np.ndarray, best: np.ndarray, contrast: np.ndarray
) -> None:
    """For each candidate centre ``(x[i], y[i])``, the square (index ``scale * len(OFFSETS) +
    offset`` into ``best[i]``) of the highest centre-surround contrast (into ``contrast[i]``;
    the first of equals)."""
    for i in range(len(x)):
        for s in range(len(SCALES)):
            half = SCALES[s]
            for o in range(len(OFFSETS)):
                cx = x[i] + OFFSETS[o, 0] * half
                cy = y[i] + OFFSETS[o, 1] * half
                inner, inner_n = square_mean(table, cx, cy, half)
                outer, outer_n = square_mean(table, cx, cy, 2 * half)
                ring = (outer * outer_n - inner * inner_n) / max(outer_n - inner_n, 1.0)
                value = (inner - ring) / max(ring, FLOOR)
                k = s * len(OFFSETS) + o
                if k == 0 or value > contrast[i]:
                    best[i], contrast[i] = k, value


def measure_lenses(
    table: np.ndarray, x: np.ndarray, y: np.ndarray, r: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """The lit lens around each candidate lens ``(x, y, r)`` (arrays of N) in the grey frame
    whose integral image is ``table``: centres, radii and whether a lit lens was found (N,);
    where none was, the candidate's own lens is returned."""
    best = np.empty(len(x), np.int64)
    contrast = np.empty(len(x))
    best_squares(table, x, y, best, contrast)
    found = contrast >= MIN_CONTRAST
    scale, offset = np.divmod(best, len(OFFSETS))
    half = SCALES[scale]
    return (
        np.where(found, x + OFFSETS[offset, 0] * half, x),
        np.where(found, y + OFFSETS[offset, 1] * half, y),
        np.where(found, RADIUS_PER_HALF_SIDE * half, r),
        found,
    )
