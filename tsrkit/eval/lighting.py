"""The light condition of a frame: Mascetti et al. 2016's four mean-V classes, or Zheng 2016's
five conditions.

``mean_v`` is the value M of Mascetti 3.2 (the mean of the V channel over every pixel);
``light_condition`` maps M onto the four classes of Table 4. The evaluation's lighting
categories (by default) and the TL-recognizer detector both use it.

``zheng_condition`` names Zheng 2016's five conditions (Figure 4-2: sunny, cloudy, dawn/dusk,
dark lit, dark unlit) from the solar elevation when the caller knows it (a sample's ``utc``,
``lat`` and ``lon``: :func:`tsrkit.sun.relative.sun_elevation`, which the benchmark applies),
else from image statistics alone; ``ZHENG_RULE``
states the thresholds. ``frame_condition`` picks the scheme (``--lighting mascetti|zheng``).
"""

from __future__ import annotations

import numpy as np

__all__ = [
    "LIGHTING_SCHEMES",
    "LIGHT_CONDITIONS",
    "ZHENG_CONDITIONS",
    "ZHENG_RULE",
    "condition_of_m",
    "frame_condition",
    "light_condition",
    "mean_v",
    "zheng_condition",
]

#: The four light conditions of Table 4, brightest first.
LIGHT_CONDITIONS = ("very_high", "high", "mid", "low")

#: Zheng 2016's five conditions (Figure 4-2), brightest first.
ZHENG_CONDITIONS = ("sunny", "cloudy", "dawn_dusk", "dark_lit", "dark_unlit")

#: The lighting schemes of the evaluation's categories (``--lighting``); the first is the default.
LIGHTING_SCHEMES = ("mascetti", "zheng")

#: Solar elevation (degrees) bounding civil twilight: above it day, below its negative dark.
_TWILIGHT_DEG = 6.0
#: Image rule: M at most this is dark (night frames; the darkest real day frame has M 36).
_DARK_M = 30.0
#: Image rule: a dark frame is lit when at least this share of pixels has V >= _LIT_V.
_LIT_SHARE, _LIT_V = 0.05, 100
#: Image rule: M at most this with mean S below _DUSK_S is dawn/dusk (dim and desaturated).
_DUSK_M, _DUSK_S = 80.0, 60.0
#: Image rule: a day frame whose top third has mean S below this has a grey sky: cloudy.
_GREY_SKY_S = 40.0

#: The Zheng rule in one sentence, for reports.
ZHENG_RULE = (
    "Zheng 2016 Figure 4-2 conditions: with a solar elevation e (time and position known), "
    f"e > {_TWILIGHT_DEG:g} deg is day, -{_TWILIGHT_DEG:g} <= e <= {_TWILIGHT_DEG:g} dawn_dusk, "
    f"e < -{_TWILIGHT_DEG:g} dark; without it, mean V M <= {_DARK_M:g} is dark, "
    f"M <= {_DUSK_M:g} with mean S < {_DUSK_S:g} dawn_dusk, else day; a dark frame is dark_lit "
    f"when >= {_LIT_SHARE:.0%} of pixels have V >= {_LIT_V}, else dark_unlit; a day frame is "
    f"cloudy when the top third of the image has mean S < {_GREY_SKY_S:g} (grey or white sky), "
    "else sunny"
)

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


def zheng_condition(image_bgr: np.ndarray, sun_elevation: float | None = None) -> str:
    """Zheng 2016's light condition of a frame: one of :data:`ZHENG_CONDITIONS` (Figure 4-2).

    Zheng names the conditions but gives no rule; this one (:data:`ZHENG_RULE`) was checked on
    the real sets (``benchmarks/PAPERS.md``). The solar elevation, when given, decides day,
    dawn/dusk (civil twilight, |e| <= 6 deg) or dark; image statistics decide the rest: lit or
    unlit for a dark frame (share of pixels with V >= 100), sunny or cloudy for a day frame
    (mean HSV saturation of the top third, where the sky is: a grey or white sky is cloudy).

    Parameters
    ----------
    image_bgr : ndarray of shape (H, W, 3), uint8
    sun_elevation : float, optional
        Solar elevation in degrees at the frame's time and position
        (:func:`tsrkit.sun.relative.sun_elevation`); None when unknown.

    Returns
    -------
    str

    Examples
    --------
    >>> import numpy as np
    >>> zheng_condition(np.zeros((4, 4, 3), np.uint8))
    'dark_unlit'
    >>> zheng_condition(np.full((6, 4, 3), 200, np.uint8), sun_elevation=-2.0)
    'dawn_dusk'
    """
    image = _check_bgr(image_bgr)
    if sun_elevation is not None and not np.isfinite(sun_elevation):
        raise ValueError(f"sun elevation must be a finite number of degrees; got {sun_elevation!r}")
    value = image.max(axis=2)
    # HSV saturation as OpenCV computes it: 255 * (max - min) / max, 0 where max is 0
    spread = (value - image.min(axis=2)).astype(np.float64)
    saturation = np.divide(255.0 * spread, value, out=np.zeros_like(spread), where=value > 0)
    m = float(value.mean())
    if sun_elevation is not None:
        period = (
            "day"
            if sun_elevation > _TWILIGHT_DEG
            else "dark"
            if sun_elevation < -_TWILIGHT_DEG
            else "dawn_dusk"
        )
    elif m <= _DARK_M:
        period = "dark"
    elif m <= _DUSK_M and float(saturation.mean()) < _DUSK_S:
        period = "dawn_dusk"
    else:
        period = "day"
    if period == "dark":
        return "dark_lit" if float((value >= _LIT_V).mean()) >= _LIT_SHARE else "dark_unlit"
    if period == "dawn_dusk":
        return period
    sky = saturation[: max(1, image.shape[0] // 3)]
    return "cloudy" if float(sky.mean()) < _GREY_SKY_S else "sunny"


def frame_condition(
    image_bgr: np.ndarray, scheme: str = "mascetti", sun_elevation: float | None = None
) -> str:
    """The light condition of a frame under ``scheme``: Mascetti's Table 4 (default) or Zheng's
    Figure 4-2 (:func:`zheng_condition`, which alone uses ``sun_elevation``).

    Examples
    --------
    >>> import numpy as np
    >>> frame_condition(np.zeros((4, 4, 3), np.uint8), "zheng")
    'dark_unlit'
    """
    if scheme == "mascetti":
        return light_condition(image_bgr)
    if scheme == "zheng":
        return zheng_condition(image_bgr, sun_elevation)
    raise ValueError(f"lighting must be one of {', '.join(LIGHTING_SCHEMES)}; got '{scheme}'")
