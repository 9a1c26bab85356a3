"""Colour conversions and per-pixel maps of one frame, computed once and shared by its stages.

Every :class:`tsrkit.core.types.Frame` carries a :class:`FrameViews` (``frame.views``). Detectors
that run on the same frame, such as the members of a ``union``, ask it for the conversion or
map they need instead of computing their own: the first asker computes it, the others reuse it.
A frame's upper band (:meth:`tsrkit.core.types.Frame.band`) asks its parent first: what the whole
frame already holds is sliced, not recomputed, which is exact because every view is computed
pixel by pixel.

The arrays handed out are shared: read them, do not write into them.
"""

from __future__ import annotations

from collections.abc import Callable, Hashable

import cv2
import numpy as np

__all__ = ["FrameViews"]


class FrameViews:
    """The views of one image (BGR uint8), computed on first use.

    Parameters
    ----------
    image : ndarray
        The frame's pixels.
    parent : FrameViews, optional
        The views of a frame whose upper rows ``image`` is: its views are sliced when it
        already holds them.
    """

    def __init__(self, image: np.ndarray, parent: FrameViews | None = None):
        self._image = image
        self._parent = parent
        self._cache: dict[Hashable, np.ndarray] = {}

    def __reduce__(self):
        """Pickled (to a worker process) without the computed views or the parent."""
        return (FrameViews, (self._image,))

    def map(self, key: Hashable, compute: Callable[[np.ndarray], np.ndarray]) -> np.ndarray:
        """``compute(image)``, computed once per frame under ``key``.

        ``compute`` must work pixel by pixel (each output pixel a function of the same input
        pixel only) and return an array with the image's rows first; ``key`` must name what
        it computes (two callers with one key get one array).
        """
        if key not in self._cache:
            parent = self._parent
            if parent is not None and key in parent._cache:
                self._cache[key] = parent._cache[key][: self._image.shape[0]]
            else:
                self._cache[key] = compute(self._image)
        return self._cache[key]

    def colour(self, code: int) -> np.ndarray:
        """``cv2.cvtColor(image, code)`` for a per-pixel conversion code (``COLOR_BGR2Lab``,
        ``COLOR_BGR2HSV``, ``COLOR_BGR2HSV_FULL``, ``COLOR_BGR2GRAY``...)."""
        return self.map(("cvtColor", code), lambda image: cv2.cvtColor(image, code))
