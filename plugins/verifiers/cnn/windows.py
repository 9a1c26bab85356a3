"""The crop the network reads around a candidate: a square window whose side follows the lens.

A signal head is about three lenses long (vertical or horizontal), so a lit lens at one end
of it lies up to five lens radii from the housing's far edge. The window is :data:`CONTEXT`
radii wide (at least :data:`MIN_SIDE`, at most :data:`MAX_SIDE` px), centred on the
candidate, so the whole housing and some surround are in view whichever lamp is lit and
however the head hangs. Windows are cut on the integer pixel grid (parts outside the frame
repeat its edge) and resized to the network's input side (area averaging when shrinking,
bilinear when enlarging; a window over twice the input side is first thinned to every k-th
pixel, which keeps a lit lens's core and costs a tenth of averaging the whole window).
Training cuts a window :data:`TRAIN_MARGIN` times wider at the same resolution, so that scale,
shift and rotation can be drawn without reaching past it.

A housing box is carried in window units: ``(x - x0) / side``, with ``(x0, y0)`` the window's
top-left corner and ``side`` its side in frame pixels.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import cv2
import numpy as np

from tsrkit.api import Box, Candidate

#: Window side in lens radii.
CONTEXT = 12.0
#: Smallest and largest window side, px.
MIN_SIDE = 16
MAX_SIDE = 512
#: Side of the network's input, px.
INPUT = 32
#: The training cut is this many times the window (same resolution).
TRAIN_MARGIN = 1.5


@dataclass(frozen=True)
class Window:
    """A square window on the frame: integer top-left corner and side, px."""

    x0: int
    y0: int
    side: int

    @classmethod
    def around(cls, candidate: Candidate, scale: float = 1.0) -> Window:
        """The window of ``candidate`` (:data:`CONTEXT` radii), ``scale`` times as wide.

        Examples
        --------
        >>> from tsrkit.api import Candidate
        >>> Window.around(Candidate.from_circle(100, 50, 1, 1.0))
        Window(x0=92, y0=42, side=16)
        >>> Window.around(Candidate.from_circle(100, 50, 5, 1.0))
        Window(x0=70, y0=20, side=60)
        """
        side = min(max(CONTEXT * candidate.radius, MIN_SIDE), MAX_SIDE) * scale
        size = int(round(side))
        return cls(
            int(round(candidate.x + 0.5 - size / 2)), int(round(candidate.y + 0.5 - size / 2)), size
        )

    def to_unit(self, box: Sequence[float]) -> np.ndarray:
        """``box`` (frame pixels, corners) in window units.

        Examples
        --------
        >>> Window(10, 20, 40).to_unit((20, 20, 30, 60)).tolist()
        [0.25, 0.0, 0.5, 1.0]
        """
        b = np.asarray(box, np.float64)
        return ((b - [self.x0, self.y0, self.x0, self.y0]) / self.side).astype(np.float32)

    def to_frame(self, unit: Sequence[float]) -> Box:
        """A box in window units back in frame pixels (the inverse of :meth:`to_unit`)."""
        x0, y0, x1, y1 = (float(v) * self.side for v in unit)
        return (x0 + self.x0, y0 + self.y0, x1 + self.x0, y1 + self.y0)


def cut(image: np.ndarray, window: Window, size: int) -> np.ndarray:
    """The pixels of ``window`` resized to ``size`` x ``size`` (edges repeated outside).

    Examples
    --------
    >>> image = np.arange(16, dtype=np.uint8).reshape(4, 4, 1).repeat(3, axis=2)
    >>> cut(image, Window(-1, -1, 3), 3)[..., 0].tolist()
    [[0, 0, 1], [0, 0, 1], [4, 4, 5]]
    """
    height, width = image.shape[:2]
    x0, y0, x1, y1 = window.x0, window.y0, window.x0 + window.side, window.y0 + window.side
    inner = image[max(y0, 0) : min(y1, height), max(x0, 0) : min(x1, width)]
    if inner.size == 0:  # a candidate off the frame (a plugin's bug): nothing to read
        return np.zeros((size, size, 3), np.uint8)
    pads = (max(-y0, 0), max(y1 - height, 0), max(-x0, 0), max(x1 - width, 0))
    if any(pads):
        inner = cv2.copyMakeBorder(inner, *pads, cv2.BORDER_REPLICATE)
    if window.side == size:
        return np.ascontiguousarray(inner)
    step = window.side // (2 * size)
    if step > 1:  # a large window: every step-th pixel first, then area averaging (10x faster)
        inner = inner[::step, ::step]
    method = cv2.INTER_AREA if window.side > size else cv2.INTER_LINEAR
    return cv2.resize(inner, (size, size), interpolation=method)


def crops(
    image: np.ndarray, candidates: Sequence[Candidate], scale: float = 1.0
) -> tuple[np.ndarray, list[Window]]:
    """Every candidate's window (``scale`` times as wide) cut to the input resolution: a
    ``(N, S, S, 3)`` uint8 batch (``S`` = :data:`INPUT` x ``scale``, rounded) and the windows."""
    size = int(round(INPUT * scale))
    windows = [Window.around(c, scale) for c in candidates]
    batch = np.zeros((len(windows), size, size, 3), np.uint8)
    for i, window in enumerate(windows):
        batch[i] = cut(image, window, size)
    return batch, windows


def to_input(batch: np.ndarray) -> np.ndarray:
    """A uint8 ``(N, S, S, 3)`` BGR batch as the network's float32 ``(N, 3, S, S)`` input,
    ``(v / 255 - 0.5) / 0.25`` per channel (the card's ``input.normalisation``). Standardising
    each crop on its own instead was measured and lost (KR fold at threshold 0.7, prior 0.3:
    hit 0.89 -> 0.76, Taiwanese false lights 0.55 -> 0.80 per keyframe;
    ``benchmarks/RESULTS.cnn.md``)."""
    x = batch.astype(np.float32).transpose(0, 3, 1, 2)
    return (x * (1.0 / (255.0 * 0.25)) - 2.0).astype(np.float32, copy=False)
