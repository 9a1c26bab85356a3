"""What ``lamp-state`` reads of a candidate: the colour of its lit lamp, the colour of that lamp's
rim, and where in the housing the light is lit.

Beyond the documents. Zheng (3.3) and Lee (5.3.3) read the lens colour only; on
dash-cam frames the lit lamp is often over-exposed white with a coloured rim, and red-orange
lamps sit at the hue of other cameras' ambers. Three groups of features make the reading
robust across cameras:

* **lamp colour**: hue histograms (weighted by saturation x value) of the lens disk and of its
  rim ``0.6 r .. 1.3 r`` (a white core is read by the rim), CIELab a/b of the brightest disk
  pixels and of the most chromatic rim pixels and the over-exposed share of the disk;
* **position**: the housing resampled upright (vertical or horizontal head) to
  :data:`HOUSING_SIZE`, the brightness and colourfulness of its top, middle and bottom thirds
  and the lit centroid along its axis (red on top, amber in the middle, green at the bottom in
  most countries; red+amber lights two thirds at once). Without a housing (a lens box), and for
  a horizontal head (whose order differs by country), these are zero and ``has_housing`` is 0.

Layout 3 reads the housing in its central band (the middle half across, :func:`band`): the
corners of a housing box hold sky, visors or a backplate, bright enough to pull the lit lens and
the lit centroid off the lamp. It adds the brightness and colourfulness at the three lens slots'
centres, each scaled to the housing's own range (0 the darkest slot, 1 the brightest), and
:func:`two_lit`, how much the top and middle slots are both lit above the bottom one (red+amber).

Layout 2 left out what differs by camera rather than by state (mean value and saturation of the
disk, its red/green chromaticity, the hue histogram of the whole housing): across cameras they
cost accuracy (leave-one-dataset-out, ``benchmarks/RESULTS.state.md``).
"""

from __future__ import annotations

import functools
from collections.abc import Sequence

import cv2
import numpy as np
from numpy.lib.stride_tricks import sliding_window_view

from tsrkit.api import Candidate

#: OpenCV hue (0-180) bin edges: reds split off at both ends, orange, amber, yellow, greens, blues.
HUE_EDGES = np.array([0, 6, 12, 18, 24, 32, 45, 70, 95, 130, 165, 181])
#: Lens patch side (pixels) after resampling; the lens radius is ``LENS_PATCH / (2 * 1.3)``.
LENS_PATCH = 16
#: Upright housing patch (across, along) after resampling.
HOUSING_SIZE = (12, 36)
#: Long / short side ratio from which a box without a fitted housing is read as a housing.
ELONGATION = 1.5
#: Housings are halved before their area resampling (:func:`area_resample`'s
#: ``halve_from``): a side at least this many times its :data:`HOUSING_SIZE` length is first
#: averaged over pixel pairs.
HALVE_FROM = 2
#: Feature layout version: a model trained on another layout is refused.
VERSION = 4


def _lens_masks() -> tuple[np.ndarray, np.ndarray]:
    centre = (LENS_PATCH - 1) / 2
    yy, xx = np.mgrid[:LENS_PATCH, :LENS_PATCH]
    d = np.hypot(yy - centre, xx - centre) / (LENS_PATCH / (2 * 1.3))
    return d <= 1.0, (d > 0.6) & (d <= 1.3)


DISK, RIM = _lens_masks()
#: The pixels of :data:`DISK`, then those of :data:`RIM`, as flat indices into a lens patch
#: (row-major order), and which of the two each is (0: disk, 1: rim).
LENS_AT = np.concatenate([np.flatnonzero(DISK), np.flatnonzero(RIM)])
N_DISK = int(DISK.sum())
LENS_PART = (np.arange(len(LENS_AT)) >= N_DISK).astype(np.intp)
N_HUE = len(HUE_EDGES) - 1
#: Number of features: 2 x lens hue, 4 Lab, the over-exposed share, 16 position (the last one
#: :func:`two_lit`).
N_FEATURES = 2 * N_HUE + 4 + 1 + 16
#: Column of :func:`two_lit` (0 without a housing).
TWO_LIT = N_FEATURES - 1
#: Number of lens (colour) features, the first columns.
N_LENS = 2 * N_HUE + 5


@functools.lru_cache(maxsize=1)
def chroma_table() -> np.ndarray:
    """CIELab chroma, ``np.hypot(a, b)`` around 0 in float64, of every 8-bit OpenCV (a, b)
    pair, indexed ``256 a + b`` (looked up: the same values as computed pixel by pixel)."""
    a, b = np.divmod(np.arange(65536), 256)
    return np.hypot(a - 128.0, b - 128.0)


def housing_of(candidate: Candidate) -> tuple[float, float, float, float] | None:
    """The housing to read: the fitted one, else the candidate's box when it is elongated."""
    if candidate.housing is not None:
        return candidate.housing
    x0, y0, x1, y1 = candidate.bbox
    short, long = sorted((x1 - x0, y1 - y0))
    return candidate.bbox if short > 0 and long / short >= ELONGATION else None


def quantiles(values: np.ndarray, q: float) -> np.ndarray:
    """The lower ``q`` quantile of each row of a 2-D array (by partition, for speed)."""
    k = min(int(q * values.shape[1]), values.shape[1] - 1)
    return np.partition(values, k, axis=1)[:, k]


#: The :data:`HUE_EDGES` bin of every 8-bit OpenCV hue (``np.digitize``'s, looked up).
HUE_BIN = np.digitize(np.arange(256), HUE_EDGES) - 1


def hue_histograms(pixels: np.ndarray, part: np.ndarray, parts: int) -> np.ndarray:
    """Per patch of an (N, K, 3) stack of HSV ``pixels`` and per region (``part`` (K,) gives
    each pixel's, 0 to ``parts`` - 1), the share of saturation x value weight per
    :data:`HUE_EDGES` bin, (N, parts, :data:`N_HUE`), from one weighted ``np.bincount`` (each
    bin sums its pixels in the stack's order)."""
    n = len(pixels)
    cells = HUE_BIN.take(pixels[..., 0]) + N_HUE * (parts * np.arange(n)[:, None] + part)
    weight = pixels[..., 1].astype(np.float32) * pixels[..., 2] / 65025.0
    hist = np.bincount(cells.ravel(), weights=weight.ravel(), minlength=n * parts * N_HUE)
    hist = hist.reshape(n, parts, N_HUE)
    return hist / np.maximum(hist.sum(axis=2, keepdims=True), 1e-6)


def pixel_bounds(boxes: np.ndarray, width: int, height: int) -> np.ndarray:
    """Integer pixel bounds (N, 4) of float ``boxes`` inside a ``width`` x ``height`` image,
    end exclusive (:func:`tsrkit.core.geometry.clip_box`, for all boxes at once)."""
    low = np.maximum(np.floor(boxes[:, :2]), 0)
    high = np.minimum(np.ceil(boxes[:, 2:]), (width, height))
    return np.concatenate([low, high], axis=1).astype(np.int64)


def area_resample(
    crop: np.ndarray, size: tuple[int, int], first: int, axis: int, halve_from: int = 0
) -> np.ndarray:
    """The first ``first`` rows (``axis`` 0) or columns (``axis`` 1) of ``crop`` resampled to
    ``size`` = (width, height) by OpenCV's area rule (``cv2.INTER_AREA``): the mean colour of
    each cell of a ``size`` grid over the crop.

    When both sides shrink (OpenCV's area decimation), each output row or column is summed from
    its own source cells, with weights set by its index times the scale factor alone (clamped
    only at the far edge): the crop is cut two source pixels past the wanted ones and resampled
    with the whole crop's scale factors (``fx``, ``fy``: the quotients OpenCV takes of the
    sizes), so less source is read for the same values (``tests/classifiers/test_lamp_state.py``
    compares them with whole resamplings at every crop length up to a frame's width).

    ``halve_from`` > 1 first halves each side at least ``halve_from`` times its output length:
    the crop is trimmed to an even length there (the last pixel dropped from an odd one) and
    each 2 x 2 (or 2 x 1) block averaged, OpenCV's integer-scale area path (a box average,
    vectorised for 2 x 2; with the area rule on the halved crop after it, about half the time
    of the area rule alone on a frame's housings: ``benchmarks/RESULTS.state.md``). The cells
    keep their meaning (a cell's mean colour), with the far edge moved by at most a pixel and
    the colours rounded twice. ``halve_from`` 0: the area rule alone, on the whole crop.
    """
    height, width = crop.shape[:2]
    if width < size[0] or height < size[1]:  # enlarging: OpenCV's area rule is then linear
        whole = cv2.resize(crop, size, interpolation=cv2.INTER_AREA)
        return whole[:first] if axis == 0 else whole[:, :first]
    kx = 2 if halve_from and width >= halve_from * size[0] else 1
    ky = 2 if halve_from and height >= halve_from * size[1] else 1
    width, height = width // kx, height // ky
    fx, fy = size[0] / width, size[1] / height
    rows, cols = height, width
    if axis == 0:
        rows = min(height, first * height // size[1] + 2)
    else:
        cols = min(width, first * width // size[0] + 2)
    cut = crop[: ky * rows, : kx * cols]
    if kx > 1 or ky > 1:
        cut = cv2.resize(cut, (cols, rows), interpolation=cv2.INTER_AREA)
    out = cv2.resize(cut, None, fx=fx, fy=fy, interpolation=cv2.INTER_AREA)
    return out[:first] if axis == 0 else out[:, :first]


def patches(image: np.ndarray, boxes: np.ndarray, size: tuple[int, int]) -> np.ndarray:
    """The (N, height, width, 3) stack of ``boxes`` resampled to ``size`` = (width, height) by
    OpenCV's area rule; a box wholly outside the image gives a black patch."""
    out = np.zeros((len(boxes), size[1], size[0], 3), np.uint8)
    bounds = pixel_bounds(boxes, image.shape[1], image.shape[0]).tolist()
    for i, (x0, y0, x1, y1) in enumerate(bounds):
        if x1 > x0 and y1 > y0:
            out[i] = cv2.resize(image[y0:y1, x0:x1], size, interpolation=cv2.INTER_AREA)
    return out


def convert(stack: np.ndarray, code: int) -> np.ndarray:
    """One OpenCV colour conversion over a whole (N, H, W, 3) stack (as one row of pixels:
    OpenCV's per-row overhead dominates a tall stack of small patches)."""
    return cv2.cvtColor(stack.reshape(1, -1, 3), code).reshape(stack.shape)


def lens_features(image: np.ndarray, lenses: Sequence[Candidate]) -> np.ndarray:
    """Lens and rim colour of each lens (see the module notes), (N, :data:`N_LENS`)."""
    r = np.array([max(c.radius, 0.5) * 1.3 for c in lenses])
    x, y = np.array([c.x for c in lenses]), np.array([c.y for c in lenses])
    stack = patches(image, np.stack([x - r, y - r, x + r, y + r], axis=1), (LENS_PATCH,) * 2)
    n = len(lenses)
    hsv = convert(stack, cv2.COLOR_BGR2HSV).reshape(n, -1, 3).take(LENS_AT, axis=1)
    lab = convert(stack, cv2.COLOR_BGR2LAB).reshape(n, -1, 3).take(LENS_AT, axis=1)
    disk_hsv = hsv[:, :N_DISK]
    # CIELab a and b around 0: small integers, exact in float64
    ab = lab[..., 1:].astype(np.float64) - 128
    value = disk_hsv[..., 2].astype(np.float32)
    bright = value >= quantiles(value, 0.7)[:, None]
    rim_lab = lab[:, N_DISK:]
    chroma = chroma_table().take((rim_lab[..., 1].astype(np.intp) << 8) | rim_lab[..., 2])
    vivid = chroma >= quantiles(chroma, 0.7)[:, None]

    def masked_mean(values: np.ndarray, mask: np.ndarray) -> np.ndarray:
        # one matrix product per lens; integer sums, exact in any order
        total = np.matmul(mask[:, None, :].astype(np.float64), values)[:, 0]
        return total / np.maximum(mask.sum(axis=1), 1)[:, None]

    over = (value > 230) & (disk_hsv[..., 1] < 80)
    return np.concatenate(
        [
            hue_histograms(hsv, LENS_PART, 2).reshape(n, -1),
            masked_mean(ab[:, :N_DISK], bright) / 128,
            masked_mean(ab[:, N_DISK:], vivid) / 128,
            over.mean(axis=1, keepdims=True),
        ],
        axis=1,
    ).reshape(n, -1)


def upright_housings(image: np.ndarray, boxes: np.ndarray, vertical: np.ndarray) -> np.ndarray:
    """The housings resampled to :data:`HOUSING_SIZE` by OpenCV's area rule (halved first
    where long: :data:`HALVE_FROM`), long axis vertical (those not ``vertical``, horizontal
    heads, resampled to the transposed size and transposed); a box wholly outside the image
    gives a black patch. Only their central :func:`band` is read: the columns past it are left
    black (:func:`area_resample`, a quarter less source resampled)."""
    across, along = HOUSING_SIZE
    first = across - across // 4
    out = np.zeros((len(boxes), along, across, 3), np.uint8)
    bounds = pixel_bounds(boxes, image.shape[1], image.shape[0]).tolist()
    for i, ((x0, y0, x1, y1), upright) in enumerate(zip(bounds, vertical.tolist())):
        if x1 > x0 and y1 > y0:
            crop = image[y0:y1, x0:x1]
            if upright:
                out[i, :, :first] = area_resample(crop, HOUSING_SIZE, first, 1, HALVE_FROM)
            else:
                turned = area_resample(crop, (along, across), first, 0, HALVE_FROM)
                out[i, :, :first] = turned.transpose(1, 0, 2)
    return out


def lit_lenses(
    boxes: np.ndarray, vertical: np.ndarray, hsv: np.ndarray, lens_fraction: float = 0.4
) -> list[Candidate]:
    """The lit lens of each upright housing patch, in image coordinates: the window of
    ``2 * lens_fraction`` short sides along the axis with the highest mean saturation x
    value^2 over the central :func:`band` (the rule of
    ``tsrkit_plugins.shared.regions.find_lens``, on the patch)."""
    value = hsv[..., 2].astype(np.float32) / 255
    lit = band(hsv[..., 1].astype(np.float32) / 255 * value * value).mean(axis=2)
    across, along = HOUSING_SIZE
    window = max(1, int(round(2 * lens_fraction * across)))
    kernel = np.ones(window, np.float32)
    t = np.array([np.argmax(np.convolve(row, kernel, mode="same")) for row in lit]) + 0.5
    t = t / along
    x0, y0, x1, y1 = boxes.T
    radius = lens_fraction * np.minimum(x1 - x0, y1 - y0)
    cx = np.where(vertical, (x0 + x1) / 2, x0 + t * (x1 - x0))
    cy = np.where(vertical, y0 + t * (y1 - y0), (y0 + y1) / 2)
    return [Candidate.from_circle(*v, 1.0) for v in zip(cx, cy, radius)]


def band(upright: np.ndarray) -> np.ndarray:
    """The middle half across of an (N, along, across) stack of upright housings."""
    across = upright.shape[2]
    return upright[:, :, across // 4 : across - across // 4]


def slots(profile: np.ndarray) -> np.ndarray:
    """The (N, 3) mean of an (N, along) profile around the centres of the top, middle and bottom
    lens slots (at 1/6, 1/2 and 5/6 of the length, +-1/18 of it)."""
    along = profile.shape[1]
    half = max(1, along // 18)
    centres = (2 * np.arange(3) + 1) * along // 6
    return profile[:, centres[:, None] + np.arange(-half, half + 1)].mean(axis=2)


def scaled(values: np.ndarray) -> np.ndarray:
    """Each row of ``values`` scaled to its own range: 0 at its minimum, 1 at its maximum."""
    low = values.min(axis=1, keepdims=True)
    return (values - low) / np.maximum(values.max(axis=1, keepdims=True) - low, 1e-3)


def lamp_peaks(profile: np.ndarray, prominence: float = 0.15) -> np.ndarray:
    """Where an (N, along) brightness profile has a lamp: the (N, along) mask of its interior
    local maxima (the highest within 2 bins either side) that stand out on both sides, within a
    sixth of the length, by ``prominence`` of the profile's range; of maxima 1 or 2 bins apart
    (a flat top) only the first. A bright box end (a backplate, sky) is not a lamp: it has no
    fall on its outer side."""
    along = profile.shape[1]
    reach = along // 6
    drop = prominence * np.maximum(np.ptp(profile, axis=1, keepdims=True), 1e-3)
    edged = np.pad(profile, ((0, 0), (2, 2)), constant_values=-np.inf)
    local = profile >= sliding_window_view(edged, 5, axis=1).max(axis=2)
    windows = sliding_window_view(
        np.pad(profile, ((0, 0), (reach, reach)), constant_values=np.inf), reach, axis=1
    )
    before = windows[:, :along].min(axis=2)  # profile[i - reach : i]
    after = windows[:, reach + 1 : reach + 1 + along].min(axis=2)  # profile[i + 1 : i + 1 + reach]
    peak = local & (before <= profile - drop) & (after <= profile - drop)
    peak[:, [0, along - 1]] = False
    first = peak.copy()
    peak[:, 1:] &= ~first[:, :-1]
    peak[:, 2:] &= ~first[:, :-2]
    return peak


def two_lit(profile: np.ndarray, redness: np.ndarray, dip: float = 0.7) -> np.ndarray:
    """How far two adjacent lamps of an upright housing are both lit, red above amber
    (red+amber, DTLD's ``red_yellow``): over every pair of lamps (:func:`lamp_peaks`) of the
    (N, along) brightness ``profile`` one lamp pitch ``d`` apart (a sixth to a half of the
    length) whose next slot below (``d`` further, at most a bin past the end) is dark, the
    dimmer lamp's height above that dark slot as a share of the brighter one's: 1 when both
    are as bright, 0 when no pair qualifies. A pair qualifies when the profile between the two
    dips below ``dip`` of the way from the dark slot to the dimmer lamp (two lamps, not one
    lamp's glare) and the upper lamp is red (``redness``, red minus green, at its reddest within
    a twelfth of the length either side, the lamp's rim where its core is white, above 0: a
    grey backplate or an unlit lens above an amber lamp is not) and at least as red as the
    lower one. Read on lamps found in the profile, not at fixed slots, it holds where the box
    holds a backplate above and below the head, whose bright ends shift the lamps off the
    thirds of the box and outshine them (``benchmarks/RESULTS.state.md``)."""
    n, along = profile.shape
    peak = lamp_peaks(profile)
    around = sliding_window_view(np.pad(profile, ((0, 0), (1, 1)), mode="edge"), 3, axis=1)
    level = around.mean(axis=2)
    half = along // 12
    red = sliding_window_view(
        np.pad(redness, ((0, 0), (half, half)), mode="edge"), 2 * half + 1, axis=1
    )
    red = red.max(axis=2)
    best = np.zeros(n)
    for d in range(along // 6, along // 2 + 1):
        upper = np.arange(0, min(along - d, along + 2 - 2 * d))
        lower = upper + d
        dark = level[:, np.minimum(lower + d, along - 1)]
        dim = np.minimum(profile[:, upper], profile[:, lower])
        bright = np.maximum(profile[:, upper], profile[:, lower])
        gap = sliding_window_view(profile, d + 1, axis=1).min(axis=2)[:, upper]
        pair = (
            peak[:, upper]
            & peak[:, lower]
            & (dim > dark)
            & (gap < dark + dip * (dim - dark))
            & (red[:, upper] > 0)
            & (red[:, upper] >= red[:, lower])
        )
        share = np.where(pair, (dim - dark) / np.maximum(bright - dark, 1e-3), 0.0)
        best = np.maximum(best, share.max(axis=1, initial=0.0))
    return best


def band_profiles(
    upright: np.ndarray, hsv: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """The central :func:`band` of upright housing patches (BGR ``upright`` and its ``hsv``):
    its value and colourfulness (saturation x value), (N, along, band width), and their
    profiles along the axis, brightness and redness (red minus green), (N, along)."""
    value = band(hsv[..., 2]).astype(np.float32) / 255
    colourful = band(hsv[..., 1]).astype(np.float32) / 255 * value
    bgr = band(upright[..., 1:]).astype(np.float32) / 255
    return value, colourful, value.mean(axis=2), (bgr[..., 1] - bgr[..., 0]).mean(axis=2)


def housing_features(upright: np.ndarray, hsv: np.ndarray, vertical: np.ndarray) -> np.ndarray:
    """Lit-position features of upright housing patches (BGR ``upright`` and its ``hsv``), read
    in their central :func:`band`."""
    n = hsv.shape[0]
    value, colourful, profile, redness = band_profiles(upright, hsv)
    # the 0.9 quantile of value and colourfulness over each third of the length (HOUSING_SIZE's
    # length is a multiple of 3), one partition for all six
    thirds = quantiles(np.stack([value, colourful], axis=1).reshape(2 * n * 3, -1), 0.9)
    weight = profile**4
    position = weight @ np.linspace(0, 1, weight.shape[1]) / np.maximum(weight.sum(axis=1), 1e-6)
    return np.concatenate(
        [
            thirds.reshape(n, 6),
            position[:, None],
            vertical[:, None].astype(np.float32),
            np.ones((n, 1), np.float32),
            scaled(slots(profile)),
            scaled(slots(colourful.mean(axis=2))),
            two_lit(profile, redness)[:, None],
        ],
        axis=1,
    )


def turned_by_colour(upright: np.ndarray, hsv: np.ndarray, vertical: np.ndarray) -> None:
    """Turn the horizontal heads among upright housing patches (BGR ``upright`` and its
    ``hsv``, in place) end over end where their bottom end slot is redder (red minus green,
    :func:`band_profiles`, :func:`slots`) than their top one, so that the redder end is on top,
    where a vertical head has its red lamp.

    A horizontal head's order differs by country (red on the left in Europe and the US, on the
    right in Japan), so its position is read only as its colour places it: a lit red or orange
    lamp at either end goes on top, a lit green or blue-green lamp (redness below the unlit
    end's) at the bottom, an amber lamp stays in the middle. A head and its mirror image give
    the same patch (the rule reads both ends alike), so a mirrored head reads the same state;
    a lamp without colour (a white core on a white housing) is placed by chance, and the model,
    trained on vertical heads turned a quarter either way, learns how far that placing holds."""
    wide = np.flatnonzero(~vertical)
    if len(wide):
        ends = slots(band_profiles(upright[wide], hsv[wide])[3])
        turn = wide[ends[:, 2] > ends[:, 0]]
        upright[turn] = upright[turn, ::-1]
        hsv[turn] = hsv[turn, ::-1]


def finds_lens(candidate: Candidate) -> bool:
    """Whether lamp-state finds the lit lens in the candidate's housing (:func:`lit_lenses`):
    a box read as a housing (no fitted housing), or a candidate whose housing is its own box (an
    annotated housing box given as the housing); a fitted housing's candidate is its lens."""
    return candidate.housing is None or candidate.housing == candidate.bbox


def lamp_features(image: np.ndarray, candidates: Sequence[Candidate]) -> np.ndarray:
    """The (N, :data:`N_FEATURES`) float32 features of ``candidates`` in ``image``."""
    rows = np.zeros((len(candidates), N_FEATURES), np.float32)
    housings = [housing_of(c) for c in candidates]
    boxed = [i for i, h in enumerate(housings) if h is not None]
    lenses = list(candidates)
    if boxed:
        boxes = np.array([housings[i] for i in boxed], np.float64)
        vertical = (boxes[:, 3] - boxes[:, 1]) >= (boxes[:, 2] - boxes[:, 0])
        upright = upright_housings(image, boxes, vertical)
        hsv = convert(upright, cv2.COLOR_BGR2HSV)
        finding = np.array([finds_lens(candidates[i]) for i in boxed])
        if finding.any():  # in the patches as resampled, before any turn
            found = lit_lenses(boxes[finding], vertical[finding], hsv[finding])
            for k, lens in zip(np.flatnonzero(finding).tolist(), found):
                lenses[boxed[k]] = lens
        turned_by_colour(upright, hsv, vertical)
        rows[boxed, N_LENS:] = housing_features(upright, hsv, vertical)
    if lenses:
        rows[:, :N_LENS] = lens_features(image, lenses)
    return np.nan_to_num(rows)


def red_amber_rows(
    image: np.ndarray, candidates: Sequence[Candidate], rows: np.ndarray
) -> np.ndarray:
    """The feature ``rows`` of ``candidates`` as the red+amber rule reads them: ``rows``, or a
    copy whose :data:`TWO_LIT` column also holds :func:`two_lit` of each box taller than wide
    but too square to be read as a housing (no fitted housing, elongation below
    :data:`ELONGATION`), read upright in its central :func:`band`.

    Such a box gives the model no position (DTLD's housing boxes around a backplate are often
    1.2-1.5 times as tall as wide, as are KR's lens boxes), but two lamps lit with a dark gap
    between them and a red top one are not one lamp's lens: the rule reads them there too. A
    lens candidate's box (square) is not read.
    """
    square = []
    for i, candidate in enumerate(candidates):
        if candidate.housing is None:  # most of a pipeline's candidates have a fitted housing
            x0, y0, x1, y1 = candidate.bbox
            if y1 - y0 > x1 - x0 > 0 and housing_of(candidate) is None:
                square.append(i)
    if not square:
        return rows
    out = rows.copy()
    boxes = np.array([candidates[i].bbox for i in square], np.float64)
    upright = upright_housings(image, boxes, np.ones(len(square), bool))
    _, _, profile, redness = band_profiles(upright, convert(upright, cv2.COLOR_BGR2HSV))
    out[square, TWO_LIT] = two_lit(profile, redness)
    return out
