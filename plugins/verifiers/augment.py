"""Training-time augmentation of the learned verifier: each real frame at other scales and as
other cameras would render it.

Why (benchmarks/RESULTS.verifier.md): the verifier is judged on cameras it never
saw, but learns the scale and colour rendering of its few training cameras. Trained without
cinTA, it gives cinTA's near, large, blurred LED heads a median probability of 0.03-0.42,
while KR and DTLD hold small distant lights. Two kinds of extra views of every real training
frame widen what it sees:

1. **Scale** (:func:`resized`): the frame resized by a factor (``cv2.INTER_AREA`` when
   shrinking, ``cv2.INTER_LINEAR`` when enlarging), its boxes following with the pixel-centre
   convention of the ``union`` detector's upscaled members, ``x' = (x + 0.5) s - 0.5`` with
   ``s`` the exact per-axis factor of the rounded size. The verifier's trainer re-runs the
   detector and the housing stage on the resized frame and labels its candidates by Zheng's
   rule (5.2.1), so a near head is also seen far, and a far one near.
2. **Camera look** (:func:`camera_look`): per view, an exposure gain and a gamma (response
   curve), white-balance gains per channel, a saturation factor, and with even odds each a mild
   Gaussian blur and a JPEG re-encoding (``cv2.imencode``): the colour, sharpness and
   compression of another camera.

The synthetic no-light training scenes get the camera looks too (not the scales): with looks
on the real frames alone, the extra positives raised leave-one-dataset-out false positives on
no-light scenes on every fold; with the looks on both, they fell (benchmarks/RESULTS.verifier.md).

Every draw comes from a generator seeded by ``(seed, CRC-32 of the frame's source, view)``: the
views, and the model trained on them, are a deterministic function of the training frames and
the seed, and a frame's views do not depend on the other frames it is trained with.
"""

from __future__ import annotations

import zlib
from collections.abc import Iterator, Sequence
from dataclasses import dataclass, replace

import cv2
import numpy as np

from tsrkit.api import Box, Frame, ParamError

#: Exposure gain range of a camera look (drawn log-uniform): darker to brighter than the frame.
EXPOSURE = (0.6, 1.7)
#: Gamma range (the camera's response curve applied to the [0, 1] intensities).
GAMMA = (0.75, 1.35)
#: Per-channel white-balance gain range.
WHITE_BALANCE = (0.85, 1.15)
#: Saturation factor range (scales each pixel's distance from its grey).
SATURATION = (0.6, 1.4)
#: Gaussian blur sigma range, px (applied to half the views).
BLUR_SIGMA = (0.4, 1.2)
#: JPEG quality range (applied to half the views).
JPEG_QUALITY = (35, 90)


def scale_box(box: Sequence[float], sx: float, sy: float) -> Box:
    """``box`` on a frame resized by ``(sx, sy)``: each edge mapped as ``(v + 0.5) s - 0.5``.

    Examples
    --------
    >>> scale_box((9.5, 19.5, 29.5, 39.5), 0.5, 0.5)
    (4.5, 9.5, 14.5, 19.5)
    >>> scale_box((0, 0, 10, 4), 1.5, 2.0)
    (0.25, 0.5, 15.25, 8.5)
    """
    x0, y0, x1, y1 = (float(v) for v in box)
    return (
        (x0 + 0.5) * sx - 0.5,
        (y0 + 0.5) * sy - 0.5,
        (x1 + 0.5) * sx - 0.5,
        (y1 + 0.5) * sy - 0.5,
    )


def resized(
    frame: Frame, boxes: Sequence[Sequence[float]], factor: float
) -> tuple[Frame, list[Box]]:
    """``frame`` resized by ``factor`` (size rounded, at least 1 px), with its ``boxes``.

    The frame's ``source`` gains ``@x<factor>`` so caches keyed by it keep the views apart.
    """
    h, w = frame.height, frame.width
    size = (max(1, int(round(w * factor))), max(1, int(round(h * factor))))
    method = cv2.INTER_AREA if factor < 1 else cv2.INTER_LINEAR
    image = cv2.resize(frame.image, size, interpolation=method)
    sx, sy = size[0] / w, size[1] / h
    view = replace(frame, image=image, source=f"{frame.source}@x{factor:g}")
    return view, [scale_box(b, sx, sy) for b in boxes]


def camera_look(image: np.ndarray, rng: np.random.Generator) -> np.ndarray:
    """``image`` (BGR uint8) as another camera might render it, every choice drawn from ``rng``:
    exposure gain (:data:`EXPOSURE`, log-uniform) and white-balance gains
    (:data:`WHITE_BALANCE`), gamma (:data:`GAMMA`), saturation (:data:`SATURATION`), then with
    probability 1/2 each a Gaussian blur (:data:`BLUR_SIGMA`) and a JPEG re-encoding
    (:data:`JPEG_QUALITY`)."""
    gains = rng.uniform(*WHITE_BALANCE, 3) * np.exp(rng.uniform(*np.log(EXPOSURE)))
    gamma = rng.uniform(*GAMMA)
    saturation = rng.uniform(*SATURATION)
    blur = rng.uniform(*BLUR_SIGMA) if rng.random() < 0.5 else 0.0
    quality = int(rng.integers(*JPEG_QUALITY, endpoint=True)) if rng.random() < 0.5 else 0
    out = np.clip(image.astype(np.float32) * (gains / 255.0), 0.0, 1.0) ** gamma
    grey = out.mean(axis=2, keepdims=True)
    out = np.clip(grey + saturation * (out - grey), 0.0, 1.0)
    look = (255.0 * out + 0.5).astype(np.uint8)
    if blur:
        look = cv2.GaussianBlur(look, (0, 0), blur)
    if quality:
        ok, data = cv2.imencode(".jpg", look, [cv2.IMWRITE_JPEG_QUALITY, quality])
        look = cv2.imdecode(data, cv2.IMREAD_COLOR) if ok else look
    return look


@dataclass(frozen=True)
class Augmentation:
    """The views of each real training frame: at every factor of ``scales`` (1: as it is) and
    ``looks`` extra copies at full size under a random :func:`camera_look`, seeded by ``seed``.

    Raises
    ------
    tsrkit.plugin.params.ParamError
        A factor given twice.
    """

    scales: tuple[float, ...] = (1.0,)
    looks: int = 0
    seed: int = 0

    def __post_init__(self):
        twice = sorted({s for s in self.scales if self.scales.count(s) > 1})
        if twice:
            raise ParamError(
                f"verifier: augment_scales gives {', '.join(f'{s:g}' for s in twice)} twice"
            )

    def views(
        self, frame: Frame, boxes: Sequence[Sequence[float]]
    ) -> Iterator[tuple[Frame, Sequence[Sequence[float]]]]:
        """The views of the real ``frame`` with its ``boxes``: every scale, then every look."""
        for factor in self.scales:
            yield (frame, boxes) if factor == 1 else resized(frame, boxes, factor)
        yield from self.looked(frame, boxes)

    def looked(
        self, frame: Frame, boxes: Sequence[Sequence[float]]
    ) -> Iterator[tuple[Frame, Sequence[Sequence[float]]]]:
        """The ``looks`` camera looks of ``frame`` (full size) with its ``boxes``."""
        for look in range(self.looks):
            rng = np.random.default_rng([self.seed, zlib.crc32(frame.source.encode()), look])
            source = f"{frame.source}@look{self.seed}.{look}"
            yield replace(frame, image=camera_look(frame.image, rng), source=source), boxes
