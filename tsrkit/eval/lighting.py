"""The light condition of a frame from its mean HSV value (Mascetti et al. 2016, 3.2, Table 4).

``mean_v`` is the value M of the paper (the mean of the V channel over every pixel);
``light_condition`` maps M onto the four classes of Table 4. The evaluation's lighting
categories and the TL-recognizer detector both use it.
"""

from __future__ import annotations

import numpy as np

__all__ = ["LIGHT_CONDITIONS", "condition_of_m", "light_condition", "mean_v"]

#: The four light conditions of Table 4, brightest first.
LIGHT_CONDITIONS = ("very_high", "high", "mid", "low")

#: Upper bounds of M (inclusive) for "low", "mid" and "high"; above the last is "very_high".
_LOW_MAX, _MID_MAX, _HIGH_MAX = 5.0, 60.0, 120.0


def _check_bgr(image_bgr: np.ndarray) -> np.ndarray:
    image = np.asarray(image_bgr)
    if image.ndim != 3 or image.shape[2] != 3:
        raise ValueError(f"expected a BGR image of shape (H, W, 3); got shape {image.shape}")
    if image.dtype != np.uint8:
        raise ValueError(f"expected a uint8 image; got dtype {image.dtype}")
    if image.size == 0:
        raise ValueError("expected a non-empty image")
    return image


def mean_v(image_bgr: np.ndarray) -> float:
    """The mean V (HSV value) of an image, M in Mascetti 3.2.

    V is the per-pixel maximum of B, G and R, as in OpenCV's ``COLOR_BGR2HSV``.

    Parameters
    ----------
    image_bgr : ndarray of shape (H, W, 3), uint8

    Returns
    -------
    float
        In [0, 255].

    Examples
    --------
    >>> import numpy as np
    >>> mean_v(np.full((2, 2, 3), (10, 200, 30), np.uint8))
    200.0
    """
    image = _check_bgr(image_bgr)
    return float(image.max(axis=2).mean())


def condition_of_m(m: float) -> str:
    """Map a mean V value M to its Table 4 class.

    Table 4: very high ``120 < M``; high ``60 < M <= 120``; mid ``5 < M <= 60``; low ``M <= 5``.

    Examples
    --------
    >>> condition_of_m(120.0), condition_of_m(120.5), condition_of_m(5.0)
    ('high', 'very_high', 'low')
    """
    if not np.isfinite(m):
        raise ValueError(f"mean V must be a finite number; got {m!r}")
    if m <= _LOW_MAX:
        return "low"
    if m <= _MID_MAX:
        return "mid"
    if m <= _HIGH_MAX:
        return "high"
    return "very_high"


def light_condition(image_bgr: np.ndarray) -> str:
    """The light condition of a frame: one of :data:`LIGHT_CONDITIONS` (Mascetti 3.2, Table 4).

    Parameters
    ----------
    image_bgr : ndarray of shape (H, W, 3), uint8

    Returns
    -------
    str
        ``"very_high"`` (M > 120), ``"high"`` (60 < M <= 120), ``"mid"`` (5 < M <= 60) or
        ``"low"`` (M <= 5).

    Examples
    --------
    >>> import numpy as np
    >>> light_condition(np.zeros((4, 4, 3), np.uint8))
    'low'
    """
    return condition_of_m(mean_v(image_bgr))
