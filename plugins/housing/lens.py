"""Re-finding the lit lens near a candidate before the housing search (issue 11, beyond the
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

Every mean is four look-ups in the frame's integral image, all candidates at once.
"""

from __future__ import annotations

import numpy as np

from tsrkit_plugins.housing.boxes import box_means

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


def measure_lenses(
    table: np.ndarray, x: np.ndarray, y: np.ndarray, r: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """The lit lens around each candidate lens ``(x, y, r)`` (arrays of N) in the grey frame
    whose integral image is ``table``: centres, radii and whether a lit lens was found (N,);
    where none was, the candidate's own lens is returned."""
    half = SCALES[None, :, None]  # (1, S, 1)
    cx = x[:, None, None] + OFFSETS[None, None, :, 0] * half  # (N, S, O)
    cy = y[:, None, None] + OFFSETS[None, None, :, 1] * half
    inner, inner_n = box_means(table, np.stack([cx - half, cy - half, cx + half, cy + half], -1))
    outer, outer_n = box_means(
        table, np.stack([cx - 2 * half, cy - 2 * half, cx + 2 * half, cy + 2 * half], -1)
    )
    ring = (outer * outer_n - inner * inner_n) / np.maximum(outer_n - inner_n, 1)
    contrast = ((inner - ring) / np.maximum(ring, FLOOR)).reshape(len(x), -1)
    best = np.argmax(contrast, axis=1)
    rows = np.arange(len(x))
    found = contrast[rows, best] >= MIN_CONTRAST
    scale, offset = np.unravel_index(best, cx.shape[1:])
    return (
        np.where(found, cx[rows, scale, offset], x),
        np.where(found, cy[rows, scale, offset], y),
        np.where(found, RADIUS_PER_HALF_SIDE * SCALES[scale], r),
        found,
    )
