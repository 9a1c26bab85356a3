"""Camera augmentation of training crops: the same light as other cameras would show it.

Each training crop (a window :data:`~.windows.TRAIN_MARGIN` times wider than the network's,
:mod:`.windows`) is drawn anew every time it is seen, by :func:`augment`:

- geometry: a scale of 0.8-1.25 (the detector's lens radius is off by that much on real
  cameras), a shift of up to 8 % of the window, a rotation of up to 8 degrees, a mirror image
  with even odds, and a quarter turn with probability ``turn`` (vertical heads become
  horizontal ones, as Japan's, and the reverse); the housing box follows;
- exposure and response: a gain drawn log-uniform in 0.5-2.5 with clipping (a gain above 1
  burns a lit lamp to white and leaves a coloured rim, as over-exposed dash-cams do), a gamma of
  0.7-1.4;
- colour: white-balance gains of 0.8-1.2 per channel, a saturation factor of 0.5-1.5;
- optics and coding: a Gaussian blur (sigma up to 1.3 px at the network's resolution) or a
  defocus disc, sensor noise (sigma up to 8 grey levels), a JPEG re-encoding at quality 30-90.

Every draw comes from the generator passed in, so a training run is repeatable from its seed.
"""

from __future__ import annotations

import cv2
import numpy as np

#: Geometry ranges.
SCALE = (0.8, 1.25)
SHIFT = 0.08
ROTATE_DEG = 8.0
#: Photometric ranges.
GAIN = (0.5, 2.5)
GAMMA = (0.7, 1.4)
WHITE_BALANCE = (0.8, 1.2)
SATURATION = (0.5, 1.5)
BLUR_SIGMA = 1.3
NOISE_SIGMA = 8.0
JPEG_QUALITY = (30, 90)


def geometry(
    crop: np.ndarray, box: np.ndarray, size: int, rng: np.random.Generator, turn: float
) -> tuple[np.ndarray, np.ndarray]:
    """The centre ``size`` x ``size`` of ``crop`` under a random scale, shift, rotation,
    mirror and quarter turn, and ``box`` (window units of the centre, NaN when unknown)
    under the same map (the bounding box of its moved corners)."""
    big = crop.shape[0]
    scale = float(np.exp(rng.uniform(np.log(SCALE[0]), np.log(SCALE[1]))))
    angle = float(rng.uniform(-ROTATE_DEG, ROTATE_DEG))
    if rng.random() < turn:
        angle += 90.0 if rng.random() < 0.5 else -90.0
    centre = (big - 1) / 2.0
    matrix = cv2.getRotationMatrix2D((centre, centre), angle, scale)
    matrix[:, 2] += (size - big) / 2.0 + rng.uniform(-SHIFT, SHIFT, 2) * size
    if rng.random() < 0.5:  # mirror left-right about the output's centre
        matrix[0] = -matrix[0]
        matrix[0, 2] += size - 1
    out = cv2.warpAffine(
        crop, matrix, (size, size), flags=cv2.INTER_LINEAR, borderMode=cv2.BORDER_REFLECT
    )
    if np.isnan(box).any():
        return out, box
    # window units of the centre -> pixels of the big crop -> pixels of the output
    offset = (big - size) / 2.0
    x = np.array([box[0], box[2], box[2], box[0]]) * size + offset - 0.5
    y = np.array([box[1], box[1], box[3], box[3]]) * size + offset - 0.5
    moved = matrix @ np.stack([x, y, np.ones(4)])
    moved = (moved + 0.5) / size
    return out, np.array(
        [moved[0].min(), moved[1].min(), moved[0].max(), moved[1].max()], np.float32
    )


def photometric(batch: np.ndarray, rng: np.random.Generator) -> np.ndarray:
    """A batch of crops (``(N, S, S, 3)`` uint8 BGR), each as another camera's exposure,
    response, colour, optics and coding would render it (one draw per crop)."""
    n = len(batch)
    x = batch.astype(np.float32) * (1.0 / 255.0)
    gain = np.exp(rng.uniform(np.log(GAIN[0]), np.log(GAIN[1]), (n, 1, 1, 1)))
    x *= (gain * rng.uniform(*WHITE_BALANCE, (n, 1, 1, 3))).astype(np.float32)
    np.clip(x, 0.0, 1.0, out=x)
    x **= rng.uniform(*GAMMA, (n, 1, 1, 1)).astype(np.float32)
    grey = x.mean(axis=3, keepdims=True)
    x = grey + (x - grey) * rng.uniform(*SATURATION, (n, 1, 1, 1)).astype(np.float32)
    noisy = rng.random(n) < 0.5
    sigma = np.where(noisy, rng.uniform(0.0, NOISE_SIGMA, n), 0.0) / 255.0
    x += rng.standard_normal(x.shape, dtype=np.float32) * sigma[:, None, None, None].astype(
        np.float32
    )
    out = (np.clip(x, 0.0, 1.0) * 255.0 + 0.5).astype(np.uint8)
    optics = rng.random(n)
    jpeg = rng.random(n) < 0.3
    disc = cv2.getStructuringElement(cv2.MORPH_ELLIPSE, (3, 3)).astype(np.float32)
    for i in range(n):
        if optics[i] < 0.35:
            out[i] = cv2.GaussianBlur(out[i], (0, 0), float(rng.uniform(0.3, BLUR_SIGMA)))
        elif optics[i] < 0.45:  # defocus: a small disc
            out[i] = cv2.filter2D(out[i], -1, disc / disc.sum())
        if jpeg[i]:
            quality = int(rng.integers(*JPEG_QUALITY))
            ok, data = cv2.imencode(".jpg", out[i], [cv2.IMWRITE_JPEG_QUALITY, quality])
            if ok:
                out[i] = cv2.imdecode(data, cv2.IMREAD_COLOR)
    return out


def augment(
    crops: np.ndarray, boxes: np.ndarray, size: int, rng: np.random.Generator, turn: float = 0.2
) -> tuple[np.ndarray, np.ndarray]:
    """Augmented views of a batch of training crops and their boxes (:func:`geometry` per
    crop, then :func:`photometric` on the batch)."""
    views = np.zeros((len(crops), size, size, 3), np.uint8)
    moved = boxes.astype(np.float32, copy=True)
    for i in range(len(crops)):
        views[i], moved[i] = geometry(crops[i], boxes[i], size, rng, turn)
    return photometric(views, rng), moved


def centre(crop: np.ndarray, size: int) -> np.ndarray:
    """The centre ``size`` x ``size`` of a training crop: what the plugin reads at run time."""
    offset = (crop.shape[0] - size) // 2
    return crop[offset : offset + size, offset : offset + size]
