"""The warm-red prior: hues between the trained red and yellow modes are read as red.

Hue is ordered round the circle red -> orange -> yellow -> green. Red lamps image anywhere from
pink-red to orange-red depending on the camera (white balance, and over-exposure clipping the red
channel so that green rises: the orange-red pitfall), while one camera's training set
shows only its own red. Under this prior a trained yellow histogram keeps only the hues from its
mode away from red, and the red histogram takes over the warm arc between the red mode and the
yellow mode. It has no tuned number: the boundary is the trained yellow mode. It is a deviation
from Zheng 3.3 and Lee 5.3.3, who use the learned histograms as they are.
"""

from __future__ import annotations

import numpy as np


def on_arc(angles: np.ndarray, start: float, end: float, period: float) -> np.ndarray:
    """Whether each angle lies strictly between ``start`` and ``end``, going the increasing
    way round a circle of ``period``.

    Examples
    --------
    >>> on_arc(np.array([170.0, 178.0, 5.0, 20.0, 90.0]), 175.0, 18.0, 180.0).tolist()
    [False, True, True, False, False]
    """
    offset = np.mod(angles - start, period)
    return (offset > 0) & (offset < np.mod(end - start, period))


def warm_red(
    red: np.ndarray, yellow: np.ndarray, angles: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """The red and yellow histograms under the warm-red prior.

    ``angles`` gives each bin's hue angle in degrees (same shape as the histograms); a mode is
    the angle of a histogram's highest bin. On the arc from the red mode up to the yellow mode,
    red becomes ``max(red, yellow)`` and yellow 0.

    Examples
    --------
    >>> hue = np.arange(6) * 60.0
    >>> r, y = warm_red(np.array([1., .5, 0, 0, 0, 0]), np.array([0, .3, 1., .4, 0, 0]), hue)
    >>> r.tolist(), y.tolist()
    ([1.0, 0.5, 0.0, 0.0, 0.0, 0.0], [0.0, 0.0, 1.0, 0.4, 0.0, 0.0])
    """
    warm = on_arc(angles, angles.flat[np.argmax(red)], angles.flat[np.argmax(yellow)], 360.0)
    return np.where(warm, np.maximum(red, yellow), red), np.where(warm, 0.0, yellow)
