"""OpenCV's 8-bit CIELab L and HSV S of a BGR image in one compiled pass (Zheng 2016, 3.2.1).

The conspicuity map needs only the lightness L of ``cv2.COLOR_BGR2LAB`` and the saturation S of
``cv2.COLOR_BGR2HSV`` (``conspicuity.lightness`` and ``conspicuity.saturation``); the two
conversions also compute a, b, H and V and took about 5.5 ms of a 1280x720 frame. This module
repeats only OpenCV's own fixed-point steps for L and S (``RGB2Lab_b`` in
``modules/imgproc/src/color_lab.cpp``, ``RGB2HSV_b`` in ``color_hsv``):

* L: each channel through the sRGB gamma table (``255 * 2**3 * gamma(i / 255)``, rounded),
  Y as ``(296 B + 2929 G + 871 R + 2**11) >> 12`` (the Y row of sRGB -> XYZ D65 times
  ``2**12``, rounded), ``f(Y)`` from the cube-root table (``2**15`` times the cube root of
  ``Y / (255 * 2**3)``, or its linear part below ``216 / 24389``, rounded), and
  ``L = (296 f + (-1336934) + 2**14) >> 15`` clipped to [0, 255].
* S: ``((max - min) * round(255 * 2**12 / max) + 2**11) >> 12`` (0 when max is 0).

Equal to ``cv2.cvtColor`` on all 2**24 colours with OpenCV 5.0.0 (checked in a scratch run,
benchmarks/RESULTS.detector_speed.md); ``tests/detectors/test_conspicuity.py`` keeps a sampled check
against the installed OpenCV.
"""

from __future__ import annotations

import numpy as np
from numba import njit


def _gamma_table() -> np.ndarray:
    """sRGB gamma of each 8-bit value, times ``255 * 2**3`` and rounded, as int32."""
    x = np.arange(256) / 255.0
    linear = np.where(x <= 0.04045, x / 12.92, ((x + 0.055) / 1.055) ** 2.4)
    return np.rint(255 * 8 * linear).astype(np.int32)


def _lightness_table() -> np.ndarray:
    """The 8-bit L of each fixed-point Y index ``0 .. 3071`` (uint8)."""
    y = np.arange(3 * 256 // 2 * 8) / (255.0 * 8)
    f = np.rint(2**15 * np.where(y < 216 / 24389, y * 841 / 108 + 16 / 116, np.cbrt(y)))
    return np.clip((296 * f.astype(np.int64) - 1336934 + 2**14) >> 15, 0, 255).astype(np.uint8)


def _saturation_table() -> np.ndarray:
    """``round(255 * 2**12 / v)`` for ``v = 0 .. 255`` (0 for v = 0), as int32."""
    table = np.zeros(256, np.int32)
    table[1:] = np.rint((255 << 12) / np.arange(1, 256))
    return table


#: Per-channel Y contributions (B, G, R order) and the L and S look-up tables.
_GAMMA = _gamma_table()
_Y_WEIGHTS = np.stack([_GAMMA * 296, _GAMMA * 2929, _GAMMA * 871]).astype(np.int32)
_LIGHTNESS = _lightness_table()
_SATURATION = _saturation_table()


def lightness_and_saturation(
    image: np.ndarray, light: np.ndarray | None = None, sat: np.ndarray | None = None
) -> tuple[np.ndarray, np.ndarray]:
    """OpenCV's 8-bit CIELab L and HSV S of a BGR uint8 image, as two uint8 (H, W) arrays
    (written into ``light`` and ``sat`` when given)."""
    light = np.empty(image.shape[:2], np.uint8) if light is None else light
    sat = np.empty(image.shape[:2], np.uint8) if sat is None else sat
    _convert(image, _Y_WEIGHTS, _LIGHTNESS, _SATURATION, light, sat)
    return light, sat


@njit(cache=True, nogil=True)
def _convert(image, y_weights, lightness, saturation, light, sat):
    """Fill ``light`` and ``sat`` from the BGR ``image`` with the module's tables."""
    height, width = light.shape
    for i in range(height):
        for j in range(width):
            b, g, r = image[i, j, 0], image[i, j, 1], image[i, j, 2]
            y = (y_weights[0, b] + y_weights[1, g] + y_weights[2, r] + 2048) >> 12
            light[i, j] = lightness[y]
            high = max(b, max(g, r))
            sat[i, j] = ((high - min(b, min(g, r))) * saturation[high] + 2048) >> 12
