"""The fast radial symmetry transform in whole-image array operations, as a bit-level oracle.

Loy & Zelinsky (2003) step by step over the whole frame, in the arithmetic the compiled
transform must reproduce exactly: OpenCV's Sobel and ``magnitude`` in float64, the votes of a
radius counted and summed per affected pixel by ``np.bincount`` on a zero-padded grid (which
adds in voter order), O_n and M_n as the sum of the signed parts, F_n by the power per
clipped count, the float32 F_n smoothed by OpenCV's separable Gaussian and added up radius by
radius in float32. It is the transform as tsrkit computed it before voting became a compiled
ring-buffer pass; ``frst_oracle.py`` checks meaning, this checks bits.
"""

from __future__ import annotations

import math

import cv2
import numpy as np

SIGNS = {"both": (1, -1), "bright": (1,), "dark": (-1,)}


def frst_arrays(
    image, radii=tuple(range(1, 11)), alpha=2.0, beta=0.0, mode="both", orientation_only=False
) -> np.ndarray:
    """S = sum over n of S_n, float32, computed with whole-image arrays."""
    image = np.asarray(image, dtype=np.float32)
    height, width = image.shape
    pad = max(radii)
    gx = cv2.Sobel(image, cv2.CV_64F, 1, 0, ksize=3, borderType=cv2.BORDER_REFLECT_101)
    gy = cv2.Sobel(image, cv2.CV_64F, 0, 1, ksize=3, borderType=cv2.BORDER_REFLECT_101)
    gx = cv2.copyMakeBorder(gx, pad, pad, pad, pad, cv2.BORDER_CONSTANT)
    gy = cv2.copyMakeBorder(gy, pad, pad, pad, pad, cv2.BORDER_CONSTANT)
    norm = cv2.magnitude(gx, gy)
    rows, cols = np.nonzero(norm > beta * float(norm.max()))
    magnitude = norm[rows, cols]
    ux, uy = gx[rows, cols] / magnitude, gy[rows, cols] / magnitude
    grid = (height + 2 * pad, width + 2 * pad)
    total = np.zeros((height, width), np.float32)
    for n in radii:
        k = 8.0 if n == 1 else 9.9
        orientation = np.zeros(grid[0] * grid[1], np.int64)
        projection = np.zeros(grid[0] * grid[1])
        for sign in SIGNS[mode]:
            r = rows + sign * np.rint(uy * n).astype(np.intp)
            c = cols + sign * np.rint(ux * n).astype(np.intp)
            target = r * grid[1] + c
            counts = np.bincount(target, minlength=orientation.size)
            sums = np.bincount(target, weights=magnitude, minlength=projection.size)
            orientation = orientation + sign * counts
            projection = projection + (sums if sign > 0 else -sums)
        clipped = np.minimum(np.abs(orientation), k)
        if orientation_only:
            strength = np.sign(orientation) * (clipped / k) ** alpha
        else:
            strength = (clipped / k) ** alpha / k * projection
        strength = strength.reshape(grid)[pad : pad + height, pad : pad + width]
        kernel = cv2.getGaussianKernel(2 * math.ceil(0.75 * n) + 1, 0.25 * n, cv2.CV_64F)
        kernel = kernel.astype(np.float32)
        total += cv2.sepFilter2D(
            strength.astype(np.float32), cv2.CV_32F, kernel, kernel, borderType=cv2.BORDER_CONSTANT
        )
    return total
