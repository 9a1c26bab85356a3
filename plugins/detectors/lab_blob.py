"""LAB-BLOB: LAB-FRST's colour map with scale-space blob detection in place of radial symmetry.

Beyond the documents. LAB-FRST (Zheng 2016, 5.2.2, after Siogkas et al.) makes red lenses
bright and green lenses dark in the CIELab map ``L * (a + b)`` and finds round spots in each
part with the fast radial symmetry transform, which votes at ten radii and smooths each radius
over the whole frame. A lens of radius 1-5 px is, at that size, a blob: here each part is
searched with the difference of Gaussians (DoG), the scale-normalised Laplacian's usual
approximation (Lindeberg 1998, "Feature detection with automatic scale selection", IJCV 30(2);
Lowe 2004, "Distinctive image features from scale-invariant keypoints", IJCV 60(2), 3):

1. ``P = max(F, 0)`` (red, bright) and ``P = max(-F, 0)`` (green, dark) of the map ``F``.
2. Gaussian blurs ``G_i`` of ``P`` at ``sigma_i = sigma * step ** i``, ``i = 0 .. levels``
   (each from the one before: :func:`gaussian_stack`);
   ``D_i = G_i - G_(i+1)``, which approximates ``(step - 1) sigma_i**2`` times the negated
   Laplacian of Gaussian: positive at the centre of a bright blob of radius about
   ``sqrt(2) sigma_i`` and comparable across scales.
3. Per pixel the strongest level ``R = max_i D_i``; the candidates are ``R``'s 3x3 local maxima
   of at least ``fraction`` times the part's largest ``R``, the ``top`` strongest per part,
   with radius ``sqrt(2) sigma_i`` of their level and score ``R``.

Larger lenses are the union's to find at a reduced ``scale`` (its multi-resolution keys): at
half size the same three levels cover radii of about 3-7 px of the full frame.
"""

from __future__ import annotations

import math

import cv2
import numpy as np
from numba import njit

from tsrkit.api import Candidate, Detector, Frame, Param, hookimpl
from tsrkit_plugins.detectors.frst.lab_frst import frame_feature_map


def gaussian_stack(part: np.ndarray, sigmas: list[float]) -> np.ndarray:
    """Gaussian blurs of ``part`` at each of the increasing ``sigmas``, stacked (float32).

    Each blur after the first is taken of the one before with ``sqrt(s_i**2 - s_(i-1)**2)``
    (Gaussians compose so, up to the truncation of the kernels), so that the wider scales cost
    narrower kernels; borders are reflected.
    """
    out = np.empty((len(sigmas), *part.shape), np.float32)
    source, done = part, 0.0
    for i, sigma in enumerate(sigmas):
        extra = math.sqrt(sigma * sigma - done * done)
        cv2.GaussianBlur(source, (0, 0), extra, dst=out[i], borderType=cv2.BORDER_REFLECT_101)
        source, done = out[i], sigma
    return out


@njit(cache=True, nogil=True)
def blob_peaks(blurs, fraction):
    """Rows, columns, levels and responses of the 3x3 local maxima of ``R = max_i D_i``,
    ``D_i = blurs[i] - blurs[i + 1]``, that reach ``fraction`` of its largest value (ties: the
    first level; a pixel equal to a neighbour counts as a maximum, as with a 3x3 dilation)."""
    count, height, width = blurs.shape
    best = np.empty((height, width), np.float32)
    which = np.empty((height, width), np.int8)
    peak = np.float32(0.0)
    for r in range(height):
        for c in range(width):
            value, level = blurs[0, r, c] - blurs[1, r, c], 0
            for i in range(1, count - 1):
                d = blurs[i, r, c] - blurs[i + 1, r, c]
                if d > value:
                    value, level = d, i
            best[r, c], which[r, c] = value, level
            peak = max(peak, value)
    rows = np.empty(height * width, np.int32)
    cols = np.empty(height * width, np.int32)
    levels = np.empty(height * width, np.int8)
    values = np.empty(height * width, np.float32)
    found = 0
    if peak <= 0:
        return rows[:0], cols[:0], levels[:0], values[:0]
    floor = max(np.float32(fraction) * peak, np.float32(np.finfo(np.float32).tiny))
    for r in range(height):
        for c in range(width):
            value = best[r, c]
            if value < floor:
                continue
            local = True
            for dr in range(max(r - 1, 0), min(r + 2, height)):
                for dc in range(max(c - 1, 0), min(c + 2, width)):
                    if best[dr, dc] > value:
                        local = False
                        break
                if not local:
                    break
            if local:
                rows[found], cols[found], levels[found], values[found] = r, c, which[r, c], value
                found += 1
    return rows[:found], cols[:found], levels[:found], values[:found]


def part_blobs(
    part: np.ndarray, sigmas: list[float], fraction: float, top: int, state: str
) -> list[Candidate]:
    """The ``top`` strongest DoG blobs of one part of the map (steps 2-3 above), in the
    continuous pixel convention (pixel ``(i, j)`` has centre ``(j + 0.5, i + 0.5)``)."""
    rows, cols, levels, values = blob_peaks(gaussian_stack(part, sigmas), fraction)
    order = np.argsort(-values, kind="stable")[:top]
    return [
        Candidate.from_circle(
            cols[i] + 0.5, rows[i] + 0.5, math.sqrt(2) * sigmas[levels[i]], values[i], state
        )
        for i in order
    ]


class LabBlob(Detector):
    """LAB-FRST's L*(a+b) map searched for blobs by the difference of Gaussians."""

    name = "lab-blob"
    summary = (
        "CIELab L*(a+b) map, difference-of-Gaussians blobs at a few small scales, top bright "
        "(red) and dark (green) spots"
    )
    section = "Zheng 2016, 5.2.2 (the map); beyond the documents (DoG: Lindeberg 1998, Lowe 2004)"
    PARAMS = (
        Param(
            "sigma",
            "float",
            1.0,
            min=0.5,
            max=16,
            help="smallest Gaussian scale in pixels (blob radius about 1.4 sigma)",
        ),
        Param("step", "float", 1.6, min=1.1, max=4, help="ratio of neighbouring scales"),
        Param("levels", "int", 3, min=1, max=8, help="difference-of-Gaussian levels"),
        Param(
            "fraction",
            "float",
            0.05,
            min=0.0,
            max=1,
            help="keep local maxima of at least this fraction of the part's largest response",
        ),
        Param("top", "int", 15, min=1, max=200, help="blobs kept per part (red, green)"),
    )

    def detect(self, frame: Frame) -> list[Candidate]:
        """Up to ``top`` red-hinted and ``top`` green-hinted blobs, strongest first."""
        p = self.params
        sigmas = [p["sigma"] * p["step"] ** i for i in range(p["levels"] + 1)]
        feature = frame_feature_map(frame)
        found = part_blobs(np.maximum(feature, 0), sigmas, p["fraction"], p["top"], "red")
        found += part_blobs(np.maximum(-feature, 0), sigmas, p["fraction"], p["top"], "green")
        return sorted(found, key=lambda c: -c.score)


@hookimpl
def register_detectors(register):
    """Register the LAB-BLOB detector."""
    register(LabBlob)
