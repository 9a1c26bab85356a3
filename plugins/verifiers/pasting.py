"""Real signal heads pasted into scenes: positives of a camera no training set shows.

The verifier's training sets show few cameras; held out, a camera whose housings look otherwise
(cinTA's veiled grey heads) gets low probabilities. The train crops of
``udacity_mit_tl_crops`` (whole heads, red / yellow / green, many veiled grey) are pasted at
dash-cam sizes into the real training frames (clear of their boxes) or into synthetic daylight
no-light road scenes, each crop's box its housing box; the candidates on them are labelled as
those of the training sets (Zheng's centre rule, :mod:`mining`). The crop's edge is feathered
so that the paste border is no cue. Measured leave-one-dataset-out in
``benchmarks/RESULTS.verifier.md``.

Two options widen what is pasted: the training sets' own housing boxes cut out as crops
(``training``: a head of one camera on the frames of another, so that neither the head nor the
scene alone names the camera), and a share of the crops turned a quarter turn (``rotate``:
vertical heads become horizontal ones, as Japan's and Korea's, and the reverse).
"""

from __future__ import annotations

import zlib
from collections.abc import Iterator, Sequence
from dataclasses import dataclass

import cv2
import numpy as np

from tsrkit.api import Frame, Sample, TsrkitError, open_datasets
from tsrkit_plugins.verifiers.unlit import SYNTH_SIZE, no_light_frames

#: The registry name of the crop set and the split pasted.
CROP_SET = "udacity_mit_tl_crops"
CROP_SPLIT = "train"
#: Seed of the scenes' backgrounds and of the pasting.
CROPS_SEED = 313
#: The range of housing heights (px, log-uniform) in a 1280x720 scene (:data:`SYNTH_SIZE`).
HEIGHTS = (10.0, 110.0)
#: Pasted heads per scene; the fraction of the frame height they stay above (their bottom).
PER_SCENE = 5
UPPER = 0.55
#: Width of the alpha ramp at the crop's edge, px.
FEATHER = 2
#: A crop is pasted at most this many times its own height (a 15 px housing is not blown up to
#: 110 px).
ENLARGE = 3.0
#: A training box is cut out as a housing crop when its long side is at least this many times
#: its short side (a lens box, as KR's, is about square) and its short side at least
#: :data:`MIN_CROP` px.
HOUSING_ASPECT = 1.5
MIN_CROP = 6

Box = tuple[float, float, float, float]


def feathered_alpha(height: int, width: int, ramp: int = FEATHER) -> np.ndarray:
    """Opacity of a ``height`` x ``width`` paste: 1 inside, rising linearly over the ``ramp``
    outermost pixels of each side (the outermost ``1 / (ramp + 1)``).

    Examples
    --------
    >>> alpha = feathered_alpha(6, 6, 2).astype(float).round(2)
    >>> alpha[2].tolist(), alpha[0].tolist()
    ([0.33, 0.67, 1.0, 1.0, 0.67, 0.33], [0.33, 0.33, 0.33, 0.33, 0.33, 0.33])
    """

    def side(n: int) -> np.ndarray:
        k = np.arange(n)
        return np.minimum(np.minimum(k + 1, n - k) / (ramp + 1), 1.0)

    return np.minimum(side(height)[:, None], side(width)[None, :]).astype(np.float32)


def paste(image: np.ndarray, crop: np.ndarray, box: tuple[int, int, int, int]) -> None:
    """Blend ``crop``, resized to the integer ``box`` (x0, y0, x1, y1), into ``image`` in place
    with a feathered edge (:func:`feathered_alpha`); area resampling when shrinking."""
    x0, y0, x1, y1 = box
    width, height = x1 - x0, y1 - y0
    shrink = width < crop.shape[1] or height < crop.shape[0]
    interpolation = cv2.INTER_AREA if shrink else cv2.INTER_LINEAR
    resized = cv2.resize(crop, (width, height), interpolation=interpolation).astype(np.float32)
    alpha = feathered_alpha(height, width)[:, :, None]
    under = image[y0:y1, x0:x1].astype(np.float32)
    blended = alpha * resized + (1.0 - alpha) * under
    image[y0:y1, x0:x1] = np.clip(np.round(blended), 0, 255).astype(np.uint8)


def place(
    rng: np.random.Generator, shape: tuple[int, int], size: tuple[int, int], taken: Sequence[Box]
) -> tuple[int, int, int, int] | None:
    """An integer box of ``size`` (width, height) in the upper part of a frame of ``shape``
    (height, width), its bottom above :data:`UPPER` x the height, clear of every ``taken`` box
    by a box's width; None after 20 tries."""
    height, width = shape
    w, h = size
    for _ in range(20):
        x0 = int(rng.integers(0, width - w + 1))
        y0 = int(rng.integers(0, max(1, int(UPPER * height) - h + 1)))
        box = (x0, y0, x0 + w, y0 + h)
        if all(
            box[2] + w <= t[0] or t[2] + w <= box[0] or box[3] + w <= t[1] or t[3] + w <= box[1]
            for t in taken
        ):
            return box
    return None


def paste_crops(
    image: np.ndarray,
    crops: Sequence[np.ndarray],
    rng: np.random.Generator,
    count: int = PER_SCENE,
    taken: Sequence[Box] = (),
    rotate: float = 0.0,
) -> list[Box]:
    """Paste ``count`` crops (BGR images) drawn from ``crops`` into ``image`` (in place), each
    turned a quarter turn either way with probability ``rotate``, with a housing height along
    the frame's rows log-uniform in :data:`HEIGHTS` (scaled to the frame's height against
    720 px, at most :data:`ENLARGE` x the crop's own) and its own aspect ratio, clear of the
    ``taken`` boxes, and return their boxes (x0, y0, x1, y1). ``rotate`` 0 draws exactly what
    it drew before the option existed."""
    scale = image.shape[0] / SYNTH_SIZE[1]
    boxes: list[Box] = list(taken)
    for _ in range(count):
        crop = crops[int(rng.integers(0, len(crops)))]
        if rotate > 0 and rng.random() < rotate:
            crop = np.rot90(crop, 1 if rng.random() < 0.5 else 3)
        drawn = scale * np.exp(rng.uniform(*np.log(HEIGHTS)))
        height = max(4, int(round(min(drawn, ENLARGE * crop.shape[0]))))
        width = max(2, int(round(height * crop.shape[1] / crop.shape[0])))
        box = place(rng, image.shape[:2], (width, height), boxes)
        if box is None:
            continue
        paste(image, np.ascontiguousarray(crop[:, :, :3]), box)
        boxes.append(tuple(float(v) for v in box))  # type: ignore[arg-type]
    return boxes[len(taken) :]


@dataclass(frozen=True)
class CropPool:
    """The crops a run pastes, the share of them turned, and a tag naming both (it enters the
    scenes' sources, so that a source names one image)."""

    images: Sequence[np.ndarray]
    rotate: float = 0.0
    tag: str = ""


def pasted_scenes(
    count: int, pool: CropPool, seed: int = CROPS_SEED
) -> Iterator[tuple[Frame, list[Box]]]:
    """``count`` synthetic 1280x720 daylight road scenes without a lit light (the crops are
    daylight photographs; the no-light generator of :mod:`mining`, drawn with ``seed``), each
    with :data:`PER_SCENE` pasted crops of ``pool`` (:func:`paste_crops`), and their housing
    boxes; a deterministic function of the arguments.
    """
    rng = np.random.default_rng(seed)
    name = f"pasted-crops{pool.tag}"
    for frame in no_light_frames(count, seed, lighting=("day",), name=name):
        boxes = paste_crops(frame.image, pool.images, rng, rotate=pool.rotate)
        yield frame, boxes


def framed_scenes(
    count: int, pool: CropPool, backgrounds: Sequence[Sample], seed: int = CROPS_SEED
) -> Iterator[tuple[Frame, list[Box]]]:
    """``count`` real training frames (``backgrounds``, spread evenly over them, each kept
    whole) with :data:`PER_SCENE` crops of ``pool`` pasted clear of their own boxes, and all
    their boxes (their own, then the pasted ones). A scene's pasting is seeded by ``seed``, its
    index and its frame's source, so that its source (with the pool's tag) names one image.
    """
    for k in range(count):
        sample = backgrounds[k * len(backgrounds) // count]
        image = sample.load().image.copy()
        own: list[Box] = [a.bbox for a in sample.annotations]
        rng = np.random.default_rng([seed, k, zlib.crc32(sample.source.encode())])
        boxes = paste_crops(image, pool.images, rng, taken=own, rotate=pool.rotate)
        source = f"pasted-crops{pool.tag}:{seed}:{k}:{sample.source}"
        yield Frame(image, source), own + boxes


def crop_samples() -> list[Sample]:
    """The train crops of :data:`CROP_SET` (through the dataset registry), in source order.

    Raises
    ------
    TsrkitError
        The set is missing (or unreadable, or has no train crop), naming what to do.
    """
    try:
        samples = open_datasets([CROP_SET], split=CROP_SPLIT).samples
    except TsrkitError as exc:
        raise TsrkitError(
            f"verifier: crop_frames > 0 pastes the {CROP_SPLIT} crops of {CROP_SET}, which "
            f"could not be read ({exc}); or set crop_frames=0"
        ) from None
    if not samples:
        raise TsrkitError(f"verifier: {CROP_SET} has no {CROP_SPLIT} crop; set crop_frames=0")
    return sorted(samples, key=lambda s: s.source)


def housing_crops(samples: Sequence[Sample]) -> list[tuple[str, np.ndarray]]:
    """Every housing box of ``samples`` (:data:`HOUSING_ASPECT`, :data:`MIN_CROP`) cut out of
    its frame, with a name (source and box) for the pool's tag."""
    out = []
    for sample in samples:
        boxes = [a.bbox for a in sample.annotations]
        long_enough = [
            b
            for b in boxes
            if max(b[2] - b[0], b[3] - b[1]) >= HOUSING_ASPECT * min(b[2] - b[0], b[3] - b[1])
            and min(b[2] - b[0], b[3] - b[1]) >= MIN_CROP
        ]
        if not long_enough:
            continue
        image = sample.load().image
        height, width = image.shape[:2]
        for b in long_enough:
            x0, y0 = max(int(round(b[0])), 0), max(int(round(b[1])), 0)
            x1, y1 = min(int(round(b[2])), width), min(int(round(b[3])), height)
            if x1 - x0 >= MIN_CROP and y1 - y0 >= MIN_CROP:
                out.append((f"{sample.source}{b}", image[y0:y1, x0:x1].copy()))
    return out


def crop_pool(training: Sequence[Sample] = (), rotate: float = 0.0) -> CropPool:
    """MIT's train crops (:func:`crop_samples`), with the housings of ``training``
    (:func:`housing_crops`), a share ``rotate`` of them turned when pasted.

    Raises
    ------
    TsrkitError
        The crop set is missing (:func:`crop_samples`).
    """
    images = [s.load().image for s in crop_samples()]
    own = housing_crops(training)
    tag = f"+up{ENLARGE:g}"
    if own:
        names = "".join(name for name, _ in own)
        tag += f"+own{len(own)}.{zlib.crc32(names.encode()):08x}"
    if rotate > 0:
        tag += f"+turn{rotate:g}"
    return CropPool(images + [image for _, image in own], rotate, tag)


def crop_frames(
    count: int,
    backgrounds: Sequence[Sample] = (),
    seed: int = CROPS_SEED,
    training: Sequence[Sample] = (),
    rotate: float = 0.0,
) -> Iterator[tuple[Frame, list[Box]]]:
    """``count`` scenes with pasted real crops (:func:`crop_pool` of ``training`` and
    ``rotate``): synthetic (:func:`pasted_scenes`), or real training frames when
    ``backgrounds`` are given (:func:`framed_scenes`). The crops are read now (not when the
    first scene is drawn), so a missing set fails before any training work.

    Raises
    ------
    TsrkitError
        ``count`` > 0 and the crop set is missing (:func:`crop_samples`).
    """
    if count <= 0:
        return iter(())
    pool = crop_pool(training, rotate)
    if backgrounds:
        return framed_scenes(count, pool, backgrounds, seed)
    return pasted_scenes(count, pool, seed)
