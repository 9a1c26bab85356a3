"""Loy & Zelinsky's fast radial symmetry transform written as plain loops, as a test oracle.

Pixel by pixel: Sobel gradient from the 3x3 neighbourhood, one vote per affected pixel, the
clipped orientation and F_n per pixel, then a direct (non-separable) 2-D Gaussian convolution.
It mirrors ``tsrkit_plugins.detectors.frst.frst`` in meaning, not in code.
"""

from __future__ import annotations

import math

import numpy as np
from scipy import ndimage

SOBEL_X = ((-1, 0, 1), (-2, 0, 2), (-1, 0, 1))


def sobel_at(padded: np.ndarray, r: int, c: int) -> tuple[float, float]:
    """Sobel (gx, gy) at image pixel (r, c) of an image padded by one pixel."""
    gx = gy = 0.0
    for i in range(3):
        for j in range(3):
            value = float(padded[r + i, c + j])
            gx += SOBEL_X[i][j] * value
            gy += SOBEL_X[j][i] * value
    return gx, gy


def gaussian_2d(n: int) -> np.ndarray:
    """A_n: 2-D Gaussian, sigma 0.25 n, half-width ceil(3 sigma), summing to one."""
    sigma = 0.25 * n
    half = math.ceil(3 * sigma)
    kernel = np.zeros((2 * half + 1, 2 * half + 1))
    for i in range(-half, half + 1):
        for j in range(-half, half + 1):
            kernel[i + half, j + half] = math.exp(-(i * i + j * j) / (2 * sigma * sigma))
    return kernel / kernel.sum()


def frst_oracle(
    image, radii=tuple(range(1, 11)), alpha=2.0, beta=0.0, mode="both", orientation_only=False
) -> np.ndarray:
    """The transform S = sum over n of F_n * A_n, computed the long way."""
    image = np.asarray(image, dtype=np.float32)
    height, width = image.shape
    padded = np.pad(image, 1, mode="reflect")
    grads = {}
    for r in range(height):
        for c in range(width):
            grads[r, c] = sobel_at(padded, r, c)
    norms = {p: math.hypot(*g) for p, g in grads.items()}
    limit = beta * max(norms.values())
    signs = {"both": (1, -1), "bright": (1,), "dark": (-1,)}[mode]
    total = np.zeros((height, width))
    for n in radii:
        k = 8.0 if n == 1 else 9.9
        orient = np.zeros((height, width))
        magn = np.zeros((height, width))
        for (r, c), (gx, gy) in grads.items():
            norm = norms[r, c]
            if norm <= limit or norm == 0:
                continue
            dr, dc = round(gy / norm * n), round(gx / norm * n)
            for sign in signs:
                rr, cc = r + sign * dr, c + sign * dc
                if 0 <= rr < height and 0 <= cc < width:
                    orient[rr, cc] += sign
                    magn[rr, cc] += sign * norm
        strength = np.zeros((height, width))
        for r in range(height):
            for c in range(width):
                o = orient[r, c]
                clipped = math.copysign(min(abs(o), k), o)
                if orientation_only:
                    strength[r, c] = math.copysign((abs(clipped) / k) ** alpha, clipped)
                else:
                    strength[r, c] = magn[r, c] / k * (abs(clipped) / k) ** alpha
        total += ndimage.convolve(strength, gaussian_2d(n), mode="constant", cval=0.0)
    return total
