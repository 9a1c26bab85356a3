"""Zheng's conspicuity detector (Zheng 2016, 3.2.1, Eq. 3.1-3.12) and its plugin.

Each pixel gets the weighted geometric mean of disk lightness, four-quadrant lightness contrast
and the larger of disk and annulus saturation, maximised over a set of lens radii; the
localization of 3.2.2 (``localization.py``) then turns the map into candidates.

Reading choices (the thesis leaves them open or prints them ambiguously):

* Lightness is OpenCV's 8-bit CIELab L (``L * 255 / 100``) divided by 255, saturation the 8-bit
  HSV S divided by 255: both lie in [0, 1] on a grid of 1/255 steps, so every window sum is an
  exact integer.
* Image borders are mirrored (reflect-101, ``d c b | a b c d | c b a``), so every window holds
  its full pixel count.
* Eq. 3.5 is printed as the maximum over the four quadrants; the prose says the template is
  there "to enforce a good contrast in all four quadrants", which reads like the minimum.
  ``quadrant_rule`` offers both; the default is the printed maximum. The minimum makes each lit
  lens a one-pixel peak that the opening of Eq. 3.15 then erases, whereas the localization
  expects peak components covering "a small center portion" of the lens, which the maximum
  gives (on the first 25 frames of roboflow_traffic_light_kr: 26 of 59 lights hit with
  "max", 4 with "min").
* A2 is the bounding box of A1 widened by the margin ``m`` (half-side ``r + m``); quadrant ``k``
  is the quarter of that box on one side of the centre's row and column, both included.

Speed: every window sum is an exact integer sum of entries of one row-prefix table per
channel (rows of equal half-width merged into one look-up in its column integral; the plan of
each window is computed once per radius and executed by the numba kernel in
``conspicuity_kernel.py``, one image row at a time). Lightness entries that several windows of
a radius use (the quarters' centre column and centre row, the quadrant boxes' corners, the
axes) are read once per pixel in the pass that combines them, and only the quarters'
staircases go through row buffers; the full lightness disk is assembled from its four
quarters, saturation disks are shared between radii, the sums run in 16 bits when every
lightness window is small enough to be exact there (:func:`narrow_sums`: int16 lightness,
uint16 saturation in bands of columns, summed from each row's vertical sums of the saturation:
:func:`column_plan`), L and S come from one compiled pass (``colour.py``), and
the root of Eq. 3.1 is taken once after the maximum of Eq. 3.2 (the root is monotonic, so the
arg-max is unchanged). Intermediate arrays are per-thread buffers reused from frame to frame
(``workspace.py``).
``tests/oracles/conspicuity_oracle.py`` is the direct reference these are tested against.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from functools import cache, lru_cache

import cv2
import numpy as np

from tsrkit.api import Candidate, Detector, Frame, Param, ParamError, hookimpl
from tsrkit_plugins.detectors.conspicuity.colour import lightness_and_saturation
from tsrkit_plugins.detectors.conspicuity.conspicuity_kernel import (
    BAND_PIXELS,
    INTEGRAL,
    NARROW_PIXELS,
    PREFIX,
    best_products,
    flat_offsets,
    positive_ends,
    prefix_tables,
)
from tsrkit_plugins.detectors.conspicuity.workspace import Workspace
from tsrkit_plugins.detectors.localization import (
    LOCALIZATION_PARAMS,
    ROI_PARAM,
    localize,
    region_of_interest,
)

#: The scratch arrays of :func:`conspicuity_map`, one set per thread (``workspace.py``); the
#: arrays it returns are never among them.
WORKSPACE = Workspace()

#: Quadrant directions as (vertical sign, horizontal sign): up-right, up-left, down-left,
#: down-right (Figure 3-7).
QUADRANTS = ((-1, 1), (-1, -1), (1, -1), (1, 1))


def lightness(image: np.ndarray) -> np.ndarray:
    """CIELab L of a BGR uint8 image as uint8 (255 = L 100); divide by 255 for [0, 1] (3.2.1)."""
    return np.ascontiguousarray(cv2.cvtColor(image, cv2.COLOR_BGR2LAB)[:, :, 0])


def saturation(image: np.ndarray) -> np.ndarray:
    """HSV S of a BGR uint8 image as uint8 (255 = fully saturated) (3.2.1, Average Saturation)."""
    return np.ascontiguousarray(cv2.cvtColor(image, cv2.COLOR_BGR2HSV)[:, :, 1])


@cache
def half_widths(radius: int) -> tuple[int, ...]:
    """Half-width of the digital disk on each row ``dy = 0..radius`` (Eq. 3.4: ``|d| <= r``)."""
    return tuple(math.isqrt(radius * radius - dy * dy) for dy in range(radius + 1))


def disk_size(radius: int) -> int:
    """Number of pixels of the disk A1 (the denominator of Eq. 3.3)."""
    w = half_widths(radius)
    return 2 * w[0] + 1 + 2 * sum(2 * h + 1 for h in w[1:])


def quarter_disk_size(radius: int) -> int:
    """Number of pixels of one quadrant of A1, axes included (Eq. 3.7 denominator)."""
    return sum(h + 1 for h in half_widths(radius))


def mirror(channel: np.ndarray, pad: int, out: np.ndarray | None = None) -> np.ndarray:
    """The channel with ``pad`` mirrored pixels on every side (reflect-101), written into
    ``out`` when given."""
    return cv2.copyMakeBorder(channel, pad, pad, pad, pad, cv2.BORDER_REFLECT_101, dst=out)


def compile_terms(runs: Sequence[tuple[int, int, int]]):
    """Plan a window sum: ``sign * prefix(dy, dc)`` over ``runs`` = (dy, dc, sign).

    Runs sharing ``dc`` and ``sign`` on consecutive rows are merged into one column look-up
    (two array operations instead of one per row). Returns ``(on_integral, dy, dc, sign)``
    terms, positive ones first.
    """
    merged = []
    terms = []
    ordered = sorted(runs, key=lambda t: (t[1], t[2], t[0]))
    start = 0
    for end in range(1, len(ordered) + 1):
        if (
            end < len(ordered)
            and ordered[end][1:] == ordered[end - 1][1:]
            and ordered[end][0] == ordered[end - 1][0] + 1
        ):
            continue
        group = ordered[start:end]
        if len(group) == 1:
            terms.append((False, *group[0]))
        else:
            merged.append((group[0][0], group[-1][0], group[0][1], group[0][2]))
        start = end
    for top, bottom, dc, sign in merged:
        terms += [(True, bottom, dc, sign), (True, top - 1, dc, -sign)]
    return tuple(sorted(terms, key=lambda term: -term[3]))


@cache
def disk_plan(radius: int):
    """Plan of the disk ``|d| <= radius`` (numerator of Eq. 3.3 and Eq. 3.10)."""
    w = half_widths(radius)
    runs = []
    for dy in range(-radius, radius + 1):
        half = w[abs(dy)]
        runs += [(dy, half + 1, 1), (dy, -half, -1)]
    return compile_terms(runs)


@cache
def disk_bands(radius: int, limit: int) -> tuple[tuple[int, int], ...]:
    """The disk's rows ``(top, bottom)`` cut, from the top, into consecutive bands of at most
    ``limit`` pixels each (by symmetry, its columns too: :func:`column_plan`)."""
    w = half_widths(radius)
    bands, top, pixels = [], -radius, 0
    for dy in range(-radius, radius + 1):
        width = 2 * w[abs(dy)] + 1
        if pixels + width > limit:
            bands.append((top, dy - 1))
            top, pixels = dy, 0
        pixels += width
    return (*bands, (top, radius))


@cache
def column_plan(radius: int, left: int, right: int, zero: int) -> tuple[tuple[int, int], ...]:
    """Columns ``left..right`` of the disk ``|d| <= radius`` as terms ``(h, dx)``: the disk's
    sum over them is the sum of column ``dx``'s vertical sums of half-height ``h`` centred on
    the disk's row (``conspicuity_kernel.fill_columns``), padded to a multiple of four terms
    with ``(zero, 0)``, a row of zeros (``conspicuity_kernel.column_disks``). The disk is
    symmetric, so its columns' half-heights are its rows' half-widths, and :func:`disk_bands`
    cuts it into bands of columns as well."""
    w = half_widths(radius)
    terms = [(w[abs(dx)], dx) for dx in range(left, right + 1)]
    return tuple(terms + [(zero, 0)] * (-len(terms) % 4))


@cache
def stair_plan(radius: int, quadrant: tuple[int, int]):
    """Plan of the staircase of quadrant ``k`` of A1: the far-edge prefixes of its rows
    ``1..radius`` away from the centre row, the part of the quarter (numerator of Eq. 3.7) that
    no other window shares.

    The staircase follows the disk's edge (rows of equal half-width merged into one column
    look-up); the centre-column edge of those rows (one column look-up) and the centre row are
    single entries of :func:`corner_terms` and :data:`SHARED_TERMS`, read once per pixel for
    the quarters, boxes and axes together (``conspicuity_kernel._light_windows``).
    """
    vertical, horizontal = quadrant
    w = half_widths(radius)
    if horizontal > 0:
        return compile_terms([(vertical * dy, w[dy] + 1, 1) for dy in range(1, radius + 1)])
    return compile_terms([(vertical * dy, -w[dy], -1) for dy in range(1, radius + 1)])


#: The single lightness entries every radius shares, as kernel terms (plane, dy, dc): the row
#: prefix left of the centre and right of it, and the column integrals at the centre row and
#: the row above it, left and right of the centre column.
SHARED_TERMS = (
    (PREFIX, 0, 0),
    (PREFIX, 0, 1),
    (INTEGRAL, 0, 0),
    (INTEGRAL, 0, 1),
    (INTEGRAL, -1, 0),
    (INTEGRAL, -1, 1),
)


@cache
def corner_terms(radius: int, half_side: int) -> tuple[tuple[int, int, int], ...]:
    """The single lightness entries of radius ``radius`` (plane, dy, dc), read once per pixel
    and shared by its windows (``conspicuity_kernel._light_windows``).

    With ``r = radius`` and ``s = half_side`` (``r + m``): the centre row's prefix right and
    left of the disk; the column integrals above and below the disk's centre-column run (these
    close the four quarters with :data:`SHARED_TERMS` and :func:`stair_plan`, and with the
    centre row give the axes term, minus the centre column and the two centre-row runs the
    quarters share); then the outer corners of the quadrant boxes of A1 + A2 (Eq. 3.8): two
    each of the up-right, up-left, down-left and down-right box. With :func:`margin_terms` and
    :data:`SHARED_TERMS` these close the boxes.
    """
    r, s = radius, half_side
    return (
        (PREFIX, 0, r + 1),
        (PREFIX, 0, -r),
        (INTEGRAL, -r - 1, 0),
        (INTEGRAL, -r - 1, 1),
        (INTEGRAL, r, 0),
        (INTEGRAL, r, 1),
        (INTEGRAL, 0, s + 1),
        (INTEGRAL, -s - 1, s + 1),
        (INTEGRAL, 0, -s),
        (INTEGRAL, -s - 1, -s),
        (INTEGRAL, s, -s),
        (INTEGRAL, -1, -s),
        (INTEGRAL, s, s + 1),
        (INTEGRAL, -1, s + 1),
    )


def margin_terms(half_side: int) -> tuple[tuple[int, int, int], ...]:
    """The quadrant boxes' entries on the centre column's edges, above and below the box
    (plane, dy, dc): left and right of the centre column at the top, then at the bottom. With
    margin 0 (``half_side`` = radius) they are :func:`corner_terms`' own column entries and are
    not read again."""
    s = half_side
    return ((INTEGRAL, -s - 1, 0), (INTEGRAL, -s - 1, 1), (INTEGRAL, s, 0), (INTEGRAL, s, 1))


def kernel_terms(plan) -> list[tuple[int, int, int, int]]:
    """A plan's ``(on_integral, dy, dc, sign)`` terms as kernel rows ``(plane, dy, dc, sign)``
    of a channel's table stack (``conspicuity_kernel.PREFIX`` or ``INTEGRAL``)."""
    return [(int(on_integral), dy, dc, sign) for on_integral, dy, dc, sign in plan]


def mean_scale(count: int) -> np.float32:
    """The float32 factor turning a uint8 window sum over ``count`` pixels into the mean of the
    [0, 1] feature (Eq. 3.3, 3.7, 3.8, 3.10, 3.11)."""
    return np.float32(1.0 / (255.0 * count))


@dataclass(frozen=True)
class KernelPlan:
    """Every window of every radius as kernel terms (see ``conspicuity_kernel.best_products``)."""

    light_terms: np.ndarray
    light_starts: np.ndarray
    light_mids: np.ndarray
    corners: np.ndarray
    margins: np.ndarray | None
    sat_terms: np.ndarray
    sat_starts: np.ndarray
    sat_mids: np.ndarray
    sat_bands: np.ndarray
    column_sums: bool
    sat_inner: np.ndarray
    sat_outer: np.ndarray
    radii: np.ndarray
    n_quarter: np.ndarray
    n_box: np.ndarray
    scales: np.ndarray


def concatenated(plans: Sequence[list]) -> tuple[np.ndarray, np.ndarray]:
    """Terms of several windows in one int32 array and the start index of each window."""
    starts = np.cumsum([0] + [len(plan) for plan in plans])
    return np.array([t for plan in plans for t in plan], np.int32).reshape(-1, 4), starts.astype(
        np.int64
    )


@lru_cache(maxsize=16)
def kernel_plan(radii: tuple[int, ...], margin: int) -> KernelPlan:
    """The windows of Eq. 3.3-3.11 for the radius set RAD and margin ``m``.

    Per radius: the staircases of the four quarters of A1 and the single entries that close
    them, the quadrant boxes of A1 + A2 (half-side ``r + m``) and the axes term on lightness;
    the saturation disks of radius ``r`` and ``2 r``
    are planned once per distinct radius (the annulus A3 is their difference). With
    :func:`narrow_sums` they are bands of columns of at most
    :data:`conspicuity_kernel.BAND_PIXELS` pixels, summed from vertical sums
    (:func:`column_plan`; ``column_sums`` true, ``sat_terms`` rows ``(h, dx)``); otherwise
    table plans (:func:`disk_plan`, one band).
    """
    light = [kernel_terms(stair_plan(r, q)) for r in radii for q in QUADRANTS]
    sat_radii = sorted(set(radii) | {2 * r for r in radii})
    if narrow_sums(radii, margin):
        bands = [disk_bands(r, BAND_PIXELS) for r in sat_radii]
        zero = 2 * max(radii) + 1
        columns = [
            column_plan(r, *band, zero) for r, rows in zip(sat_radii, bands) for band in rows
        ]
        sat_terms = np.array([term for plan in columns for term in plan], np.int64)
        sat_starts = np.cumsum([0] + [len(plan) for plan in columns]).astype(np.int64)
        sat_mids = sat_starts[1:].copy()
        sat_bands = np.cumsum([0] + [len(rows) for rows in bands]).astype(np.int64)
    else:
        sat_terms, sat_starts = concatenated([kernel_terms(disk_plan(r)) for r in sat_radii])
        sat_mids = positive_ends(sat_terms, sat_starts)
        sat_bands = np.arange(len(sat_radii) + 1, dtype=np.int64)
    n_quarter = [quarter_disk_size(r) for r in radii]
    n_box = [(r + margin + 1) ** 2 for r in radii]
    scales = [
        (
            mean_scale(disk_size(r)),
            mean_scale(nq * (nb - nq)),
            mean_scale(disk_size(r)),
            mean_scale(disk_size(2 * r) - disk_size(r)),
        )
        for r, nq, nb in zip(radii, n_quarter, n_box)
    ]
    light_terms, light_starts = concatenated(light)
    return KernelPlan(
        light_terms,
        light_starts,
        positive_ends(light_terms, light_starts),
        np.array([corner_terms(r, r + margin) for r in radii], np.int32),
        np.array([margin_terms(r + margin) for r in radii], np.int32) if margin else None,
        sat_terms,
        sat_starts,
        sat_mids,
        sat_bands,
        narrow_sums(radii, margin),
        np.array([sat_radii.index(r) for r in radii], np.int64),
        np.array([sat_radii.index(2 * r) for r in radii], np.int64),
        np.array(radii, np.int32),
        np.array(n_quarter, np.int64),
        np.array(n_box, np.int64),
        np.array(scales, np.float32),
    )


def full_runs(height: int, width: int) -> np.ndarray:
    """Row runs ``(row, first column, end column)`` covering a whole ``height x width`` map."""
    runs = np.zeros((height, 3), np.int64)
    runs[:, 0] = np.arange(height)
    runs[:, 2] = width
    return runs


def weighted_root(
    product: np.ndarray, weights: Sequence[float], out: np.ndarray | None = None
) -> np.ndarray:
    """The ``(w_L + w_LC + w_S)``-th root of Eq. 3.1; with the product of the weighted features
    (``conspicuity_kernel.weighted_product``) this is the weighted geometric mean whose pixel
    ratios do not change when a feature is rescaled (Appendix A). Written into ``out`` (which
    may be ``product``) when given."""
    return np.power(product, 1.0 / float(sum(weights)), dtype=np.float32, out=out)


@dataclass(frozen=True)
class ConspicuityMap:
    """Eq. 3.2: the conspicuity ``values`` and, per pixel, the arg-max lens ``radius``."""

    values: np.ndarray
    radius: np.ndarray


def check_settings(radii: Sequence[int], weights: Sequence[float], margin: int) -> None:
    """Raise ValueError unless the radius set, weights and margin can be used."""
    if not radii or min(radii) < 1:
        raise ValueError(f"radii must be positive integers; got {tuple(radii)}")
    if len(weights) != 3 or min(weights) < 0 or sum(weights) <= 0:
        raise ValueError(f"weights must be three non-negative numbers, not all 0; got {weights}")
    if margin < 0:
        raise ValueError(f"margin m must be >= 0; got {margin}")


def conspicuity_map(
    image: np.ndarray,
    radii: Sequence[int] = tuple(range(1, 11)),
    weights: Sequence[float] = (1.0, 1.0, 1.0),
    margin: int = 0,
    quadrant_rule: str = "max",
    *,
    scratch: bool = False,
) -> ConspicuityMap:
    """Eq. 3.1-3.12 on every pixel of a BGR uint8 image.

    Parameters
    ----------
    image : ndarray
        BGR uint8, shape (H, W, 3).
    radii : sequence of int
        The radius set RAD (Table 5-1: 1..10).
    weights : sequence of float
        ``(w_L, w_LC, w_S)`` (Table 5-1: 1, 1, 1).
    margin : int
        The A2 margin ``m`` (Table 5-1: 0).
    quadrant_rule : {"max", "min"}
        How Eq. 3.5 combines the quadrants (see the module notes).
    scratch : bool
        Return the calling thread's :data:`WORKSPACE` buffers, valid only until its next
        call, instead of new arrays (the detector's own use: its map never leaves ``detect``).

    Returns
    -------
    ConspicuityMap
        float32 conspicuity in [0, 1] and the int32 radius giving it (smallest on ties).

    Examples
    --------
    >>> img = np.zeros((40, 40, 3), np.uint8)
    >>> _ = cv2.circle(img, (20, 20), 4, (0, 0, 255), -1)
    >>> cmap = conspicuity_map(img)
    >>> bool(cmap.values[20, 20] == cmap.values.max()), int(cmap.radius[20, 20])
    (True, 4)
    """
    radii = sorted({int(r) for r in radii})
    check_settings(radii, weights, margin)
    if image.ndim != 3 or image.shape[2] != 3 or image.dtype != np.uint8:
        raise ValueError(
            f"expected a BGR uint8 image of shape (H, W, 3); got {image.dtype} {image.shape}"
        )
    light_tables, sat_tables, pad = channel_tables(image, radii, margin, WORKSPACE)
    shape = image.shape[:2]
    best = WORKSPACE.array("best", shape, np.float32)
    best_radius = (
        WORKSPACE.array("radius", shape, np.int32) if scratch else np.empty(shape, np.int32)
    )
    products_on_runs(
        light_tables,
        sat_tables,
        pad,
        full_runs(*shape),
        radii,
        weights,
        margin,
        quadrant_rule,
        (best, best_radius),
    )
    return ConspicuityMap(weighted_root(best, weights, best if scratch else None), best_radius)


def narrow_sums(radii: Sequence[int], margin: int) -> bool:
    """Whether the kernel sums in 16 bits: true when no lightness window holds more than
    :data:`conspicuity_kernel.NARROW_PIXELS` pixels (int16 lightness tables); the saturation
    disks are then summed in bands of at most :data:`conspicuity_kernel.BAND_PIXELS` pixels
    (uint16 saturation tables). The lightness windows of radius ``r`` are the quadrant boxes of
    A1 + A2 (``(r + m + 1)**2`` pixels), the quarters of A1 inside them, and the shared axes
    (minus ``4 r + 3`` pixels, the centre three times): with the paper's radii 1..10 and margin
    0, at most 121 pixels, and the saturation disks (radius up to 20) take 1-6 bands."""
    return max((max(radii) + margin + 1) ** 2, 4 * max(radii) + 3) <= NARROW_PIXELS


def channel_tables(
    image: np.ndarray, radii: Sequence[int], margin: int, workspace: Workspace | None = None
) -> tuple[np.ndarray, np.ndarray, int]:
    """Prefix tables of the mirrored lightness and saturation (int16 and uint16 with
    :func:`narrow_sums`, int32 otherwise), with the padding they need. The channels are those
    of :func:`lightness` and :func:`saturation`, converted in one pass (``colour.py``). With a
    ``workspace`` every array, the tables included, is one of its buffers."""
    pad = max(2 * max(radii), max(radii) + margin)
    narrow = narrow_sums(radii, margin)
    height, width = image.shape[:2]
    padded = (height + 2 * pad, width + 2 * pad)

    def scratch(key, shape, dtype):
        return None if workspace is None else workspace.array(key, shape, dtype)

    channels = lightness_and_saturation(
        image,
        scratch("light", (height, width), np.uint8),
        scratch("sat", (height, width), np.uint8),
    )
    tables = []
    for name, channel, dtype in zip(
        ("light", "sat"), channels, (np.int16, np.uint16) if narrow else (np.int32, np.int32)
    ):
        mirrored = mirror(channel, pad, scratch(f"{name} mirrored", padded, np.uint8))
        stack = scratch(f"{name} tables", (2, padded[0] + 1, padded[1] + 1), dtype)
        tables.append(prefix_tables(mirrored, dtype, stack))
    return tables[0], tables[1], pad


def products_on_runs(
    light_tables: np.ndarray,
    sat_tables: np.ndarray,
    pad: int,
    runs: np.ndarray,
    radii: Sequence[int],
    weights: Sequence[float],
    margin: int,
    quadrant_rule: str,
    out: tuple[np.ndarray, np.ndarray] | None = None,
):
    """Eq. 3.1 under its root, maximised over the radii (Eq. 3.2), on the pixels of ``runs``;
    returns the float32 maximum (0 elsewhere) and the int32 arg-max radius (smallest radius
    elsewhere and on ties). With ``out``, the two arrays are written on the runs' pixels and
    left as they are elsewhere."""
    shape = (sat_tables.shape[1] - 1 - 2 * pad, sat_tables.shape[2] - 1 - 2 * pad)
    plan = kernel_plan(tuple(radii), margin)
    if out is None:
        out = (np.zeros(shape, np.float32), np.full(shape, min(radii), np.int32))
    best, best_radius = out
    if plan.column_sums:
        table_width = sat_tables.shape[2]
        columns = WORKSPACE.array("columns", (2 * max(radii) + 2, table_width), sat_tables.dtype)
        columns[-1] = 0
        sat_offsets = plan.sat_terms[:, 0] * table_width + plan.sat_terms[:, 1]
    else:
        columns = np.zeros((0, 0), sat_tables.dtype)
        sat_offsets = flat_offsets(plan.sat_terms, sat_tables.shape)
    best_products(
        light_tables,
        sat_tables,
        pad,
        runs,
        flat_offsets(plan.light_terms, light_tables.shape),
        plan.light_starts,
        plan.light_mids,
        flat_offsets(np.array(SHARED_TERMS), light_tables.shape),
        flat_offsets(plan.corners.reshape(-1, 3), light_tables.shape).reshape(len(radii), -1),
        None
        if plan.margins is None
        else flat_offsets(plan.margins.reshape(-1, 3), light_tables.shape).reshape(len(radii), -1),
        sat_offsets,
        plan.sat_starts,
        plan.sat_mids,
        plan.sat_bands,
        columns,
        plan.sat_inner,
        plan.sat_outer,
        plan.radii,
        plan.n_quarter,
        plan.n_box,
        plan.scales,
        np.asarray(weights, np.float32),
        quadrant_rule == "min",
        np.float32 if narrow_sums(radii, margin) else np.int64,
        best,
        best_radius,
    )
    return best, best_radius


class Conspicuity(Detector):
    """Zheng's conspicuity map (Eq. 3.1-3.12) followed by the localization of 3.2.2."""

    name = "conspicuity"
    summary = "Zheng's conspicuity map (lightness, quadrant contrast, saturation) + localization"
    section = "Zheng 2016, 3.2.1-3.2.2, Eq. 3.1-3.15, Algorithm 3-1, Table 5-1"
    PARAMS = (
        Param(
            "weights",
            "floats",
            (1.0, 1.0, 1.0),
            min=0,
            length=3,
            section="Table 5-1",
            help="(w_L, w_LC, w_S): weights of lightness, contrast, saturation (Eq. 3.1)",
        ),
        Param(
            "radii",
            "ints",
            tuple(range(1, 11)),
            min=1,
            max=64,
            section="Table 5-1",
            help="the lens radius set RAD in pixels (Eq. 3.2)",
        ),
        Param(
            "margin",
            "int",
            0,
            min=0,
            max=32,
            section="Table 5-1",
            help="A2 margin m around the lens disk A1 (Eq. 3.9)",
        ),
        Param(
            "quadrant_rule",
            "str",
            "max",
            choices=("max", "min"),
            section="Eq. 3.5, 3.2.1",
            help="combine the four quadrant contrasts by max (as printed) or min (prose)",
        ),
        ROI_PARAM,
    ) + LOCALIZATION_PARAMS

    def __init__(self, **params):
        super().__init__(**params)
        p = self.params
        try:
            check_settings(p["radii"], p["weights"], p["margin"])
        except ValueError as exc:
            raise ParamError(f"detector 'conspicuity': {exc}") from None
        # Load the compiled kernel now, so that the first frame's time is the detector's own.
        conspicuity_map(np.zeros((4, 4, 3), np.uint8), (1,), p["weights"], 0, p["quadrant_rule"])

    def detect(self, frame: Frame) -> list[Candidate]:
        """Candidates, best first, each scored by its conspicuity with its arg-max radius."""
        p = self.params
        roi = region_of_interest(frame.image, p["roi_top"])
        cmap = conspicuity_map(
            roi, p["radii"], p["weights"], p["margin"], p["quadrant_rule"], scratch=True
        )
        return localize(cmap.values, p, radius_map=cmap.radius)


@hookimpl
def register_detectors(register):
    register(Conspicuity)
