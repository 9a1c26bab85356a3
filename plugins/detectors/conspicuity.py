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

Speed: every window sum is an exact integer sum of shifted views of one row-prefix array per
channel (rows of equal half-width merged into one look-up in its column prefix; the plan of
each window is computed once per radius), the full lightness disk is assembled from its four
quarters, saturation disks are shared between radii, the frame is processed in strips that stay
in cache, and the root of Eq. 3.1 is taken once after the maximum of Eq. 3.2 (the root is
monotonic, so the arg-max is unchanged). ``tests/oracles/conspicuity_oracle.py`` is the direct
reference these are tested against.
"""
from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from functools import lru_cache

import cv2
import numpy as np

from tsrkit.hookspecs import hookimpl
from tsrkit.params import Param
from tsrkit.plugin import Detector
from tsrkit.types import Candidate, Frame
from tsrkit_plugins.detectors.localization import (LOCALIZATION_PARAMS, ROI_PARAM, localize,
                                                     region_of_interest)

#: Quadrant directions as (vertical sign, horizontal sign): up-right, up-left, down-left,
#: down-right (Figure 3-7).
QUADRANTS = ((-1, 1), (-1, -1), (1, -1), (1, 1))


def lightness(image: np.ndarray) -> np.ndarray:
    """CIELab L of a BGR uint8 image as uint8 (255 = L 100); divide by 255 for [0, 1] (3.2.1)."""
    return np.ascontiguousarray(cv2.cvtColor(image, cv2.COLOR_BGR2LAB)[:, :, 0])


def saturation(image: np.ndarray) -> np.ndarray:
    """HSV S of a BGR uint8 image as uint8 (255 = fully saturated) (3.2.1, Average Saturation)."""
    return np.ascontiguousarray(cv2.cvtColor(image, cv2.COLOR_BGR2HSV)[:, :, 1])


@lru_cache(maxsize=None)
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


def mirror(channel: np.ndarray, pad: int) -> np.ndarray:
    """The channel with ``pad`` mirrored pixels on every side (reflect-101)."""
    return cv2.copyMakeBorder(channel, pad, pad, pad, pad, cv2.BORDER_REFLECT_101)


class PrefixSums:
    """Exact integer window sums of one uint8 channel from its row prefix sums.

    The channel comes mirrored by ``pad`` pixels (:func:`mirror`); ``prefix[y, c]`` is the sum
    of the padded row ``y`` left of padded column ``c``. A horizontal run on row ``i + dy`` from
    column ``j - a`` to ``j + b`` is ``prefix(dy, b + 1) - prefix(dy, -a)``, so any window made
    of row runs is a signed sum of shifted views of this one array, and a run of equal column
    offsets down consecutive rows is one look-up in its column prefix (``integral``).
    """

    def __init__(self, padded: np.ndarray, pad: int):
        self.pad = pad
        self.height, self.width = padded.shape[0] - 2 * pad, padded.shape[1] - 2 * pad
        self.prefix = np.zeros((padded.shape[0] + 1, padded.shape[1] + 1), np.int32)
        np.cumsum(padded, axis=1, dtype=np.int32, out=self.prefix[1:, 1:])
        self.integral = np.cumsum(self.prefix, axis=0, dtype=np.int32)

    def view(self, table: np.ndarray, dy: int, dc: int) -> np.ndarray:
        """``table`` aligned so that pixel (i, j) reads padded row ``i + dy``, column ``j + dc``."""
        y, x = self.pad + 1 + dy, self.pad + dc
        return table[y:y + self.height, x:x + self.width]

    def signed_sum(self, plan: Sequence[tuple[bool, int, int, int]]) -> np.ndarray:
        """Execute a plan from :func:`compile_terms`: the signed sum of shifted table views."""
        tables = (self.prefix, self.integral)
        on_integral, dy, dc, _ = plan[0]
        total = self.view(tables[on_integral], dy, dc).copy()
        for on_integral, dy, dc, sign in plan[1:]:
            (cv2.add if sign > 0 else cv2.subtract)(
                total, self.view(tables[on_integral], dy, dc), dst=total)
        return total


def compile_terms(runs: Sequence[tuple[int, int, int]],
                  columns: Sequence[tuple[int, int, int, int]] = ()):
    """Plan a window sum: ``sign * prefix(dy, dc)`` over ``runs`` = (dy, dc, sign) plus, over
    ``columns`` = (top, bottom, dc, sign), ``sign`` times the prefix at column offset ``dc``
    summed over rows ``top..bottom``.

    Runs sharing ``dc`` and ``sign`` on consecutive rows are merged into one column look-up
    (two array operations instead of one per row). Returns ``(on_integral, dy, dc, sign)``
    terms, positive ones first.
    """
    merged = list(columns)
    terms = []
    ordered = sorted(runs, key=lambda t: (t[1], t[2], t[0]))
    start = 0
    for end in range(1, len(ordered) + 1):
        if end < len(ordered) and ordered[end][1:] == ordered[end - 1][1:] \
                and ordered[end][0] == ordered[end - 1][0] + 1:
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


@lru_cache(maxsize=None)
def disk_plan(radius: int):
    """Plan of the disk ``|d| <= radius`` (numerator of Eq. 3.3 and Eq. 3.10)."""
    w = half_widths(radius)
    runs = []
    for dy in range(-radius, radius + 1):
        half = w[abs(dy)]
        runs += [(dy, half + 1, 1), (dy, -half, -1)]
    return compile_terms(runs)


@lru_cache(maxsize=None)
def quarter_plan(radius: int, quadrant: tuple[int, int]):
    """Plan of quadrant ``k`` of A1, axes included (numerator of Eq. 3.7).

    Every row run of the quarter starts (or ends) on the centre column, so that edge is one
    column look-up; the other edge follows the disk's staircase.
    """
    vertical, horizontal = quadrant
    w = half_widths(radius)
    rows = (-radius, 0) if vertical < 0 else (0, radius)
    if horizontal > 0:
        runs = [(vertical * dy, w[dy] + 1, 1) for dy in range(radius + 1)]
        return compile_terms(runs, [(rows[0], rows[1], 0, -1)])
    runs = [(vertical * dy, -w[dy], -1) for dy in range(radius + 1)]
    return compile_terms(runs, [(rows[0], rows[1], 1, 1)])


@lru_cache(maxsize=None)
def box_plan(half_side: int, quadrant: tuple[int, int]):
    """Plan of quadrant ``k`` of the bounding box of side ``half_side + 1`` (A1 + A2)."""
    vertical, horizontal = quadrant
    top, bottom = (-half_side, 0) if vertical < 0 else (0, half_side)
    left, right = (-half_side, 0) if horizontal < 0 else (0, half_side)
    return compile_terms((), [(top, bottom, right + 1, 1), (top, bottom, left, -1)])


@lru_cache(maxsize=None)
def axes_plan(radius: int):
    """Plan of minus the centre column ``|dy| <= radius`` and the two centre-row runs
    ``0 <= +-dx <= radius`` (the parts the four quarters share)."""
    return compile_terms([(0, radius + 1, -1), (0, 0, 1), (0, 1, -1), (0, -radius, 1)],
                         [(-radius, radius, 1, -1), (-radius, radius, 0, 1)])


def disk_sum(sums: PrefixSums, radius: int) -> np.ndarray:
    """Window sum over the disk ``|d| <= radius`` (numerator of Eq. 3.3 and Eq. 3.10)."""
    return sums.signed_sum(disk_plan(radius))


def quarter_disk_sum(sums: PrefixSums, radius: int, quadrant: tuple[int, int]) -> np.ndarray:
    """Window sum over quadrant ``k`` of A1, axes included (numerator of Eq. 3.7)."""
    return sums.signed_sum(quarter_plan(radius, quadrant))


def quarter_box_sum(sums: PrefixSums, half_side: int, quadrant: tuple[int, int]) -> np.ndarray:
    """Window sum over quadrant ``k`` of the bounding box of side ``half_side + 1`` (A1 + A2)."""
    return sums.signed_sum(box_plan(half_side, quadrant))


def disk_from_quarters(sums: PrefixSums, radius: int,
                       quarters: Sequence[np.ndarray]) -> np.ndarray:
    """The disk sum rebuilt from its four overlapping quarters (same value as :func:`disk_sum`).

    The quarters share the centre row and column: ``disk = sum(quarters) - column - row_left
    - row_right`` where the column is ``|dy| <= radius, dx = 0`` and each row run
    ``dy = 0, 0 <= +-dx <= radius`` includes the centre.
    """
    total = sums.signed_sum(axes_plan(radius))
    for quarter in quarters:
        cv2.add(total, quarter, dst=total)
    return total


def average(window_sum: np.ndarray, count: int) -> np.ndarray:
    """Mean of a [0, 1] feature over a window of ``count`` pixels from its uint8 sum (Eq. 3.3,
    3.7, 3.8, 3.10, 3.11: sum of flagged values over the number of flagged pixels)."""
    return np.multiply(window_sum, np.float32(1.0 / (255.0 * count)), dtype=np.float32)


def quadrant_contrast(disk_part: np.ndarray, box_part: np.ndarray, n_disk: int,
                      n_box: int) -> np.ndarray:
    """Eq. 3.7-3.8 as an exact integer: ``n_disk * n_border * 255 * (LD_k - LB_k)``.

    ``LD_k`` averages the ``n_disk`` pixels of A1 in the quadrant (Eq. 3.7), ``LB_k`` the
    ``n_border = n_box - n_disk`` pixels of A2 in it (Eq. 3.8); with the quadrant's A1 sum ``D``
    and whole-box sum ``B`` the difference is ``(n_box * D - n_disk * B) / (n_disk * n_border)``.
    Keeping the numerator integral keeps a zero contrast exactly zero (the root of Eq. 3.1 would
    magnify rounding noise near zero).
    """
    return cv2.addWeighted(disk_part, float(n_box), box_part, -float(n_disk), 0.0,
                           dtype=cv2.CV_32S)


def lightness_contrast(per_quadrant: Sequence[np.ndarray], n_disk: int, n_box: int,
                       rule: str = "max") -> np.ndarray:
    """Eq. 3.5-3.6: combine the four quadrant differences of :func:`quadrant_contrast`
    (``"max"`` as printed, ``"min"`` for the prose's "all four quadrants"), round negative
    differences up to zero and scale to lightness units. Clipping once after the combination
    equals clipping each quadrant first, since max and min commute with ``max(0, .)``."""
    combine = cv2.max if rule == "max" else cv2.min
    out = combine(per_quadrant[0], per_quadrant[1])
    for contrast in per_quadrant[2:]:
        combine(out, contrast, dst=out)
    return average(cv2.max(out, 0), n_disk * (n_box - n_disk))


def annulus_saturation(outer_sum: np.ndarray, inner_sum: np.ndarray, radius: int) -> np.ndarray:
    """Eq. 3.11: mean saturation in the annulus ``radius < |d| <= 2 radius`` (A3)."""
    return average(cv2.subtract(outer_sum, inner_sum), disk_size(2 * radius) - disk_size(radius))


def weighted_product(features: Sequence[np.ndarray], weights: Sequence[float]) -> np.ndarray:
    """The product under the root of Eq. 3.1: ``LD^w_L * LC^w_LC * max(SD, SA)^w_S``."""
    out = None
    for feature, weight in zip(features, weights):
        term = feature if weight == 1 else cv2.pow(feature, float(weight))
        out = term.copy() if out is None else cv2.multiply(out, term)
    return out


def weighted_root(product: np.ndarray, weights: Sequence[float]) -> np.ndarray:
    """The ``(w_L + w_LC + w_S)``-th root of Eq. 3.1; with :func:`weighted_product` this is the
    weighted geometric mean whose pixel ratios do not change when a feature is rescaled
    (Appendix A)."""
    return np.power(product, 1.0 / float(sum(weights)), dtype=np.float32)


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


def conspicuity_map(image: np.ndarray, radii: Sequence[int] = tuple(range(1, 11)),
                    weights: Sequence[float] = (1.0, 1.0, 1.0), margin: int = 0,
                    quadrant_rule: str = "max") -> ConspicuityMap:
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
    radii = sorted(set(int(r) for r in radii))
    check_settings(radii, weights, margin)
    if image.ndim != 3 or image.shape[2] != 3 or image.dtype != np.uint8:
        raise ValueError(f"expected a BGR uint8 image of shape (H, W, 3); got {image.dtype} "
                         f"{image.shape}")
    pad = max(2 * radii[-1], radii[-1] + margin)
    if (STRIP_ROWS + 2 * pad + 1) * (image.shape[1] + 2 * pad + 1) * 255 >= 2 ** 31:
        raise ValueError(f"image width {image.shape[1]} too large for 32-bit window sums")
    light, sat = mirror(lightness(image), pad), mirror(saturation(image), pad)
    best = np.zeros(image.shape[:2], np.float32)
    best_radius = np.full(image.shape[:2], radii[0], np.int32)
    for top in range(0, image.shape[0], STRIP_ROWS):
        rows = slice(top, min(top + STRIP_ROWS, image.shape[0]) + 2 * pad)
        strip = slice(top, top + STRIP_ROWS)
        best_products(PrefixSums(light[rows], pad), PrefixSums(sat[rows], pad), radii, weights,
                      margin, quadrant_rule, best[strip], best_radius[strip])
    return ConspicuityMap(weighted_root(best, weights), best_radius)


#: Rows per strip: the working arrays of a strip stay in the CPU cache, and a strip's column
#: prefix sums stay below 2**31 (int32) for frames up to about 80,000 pixels wide.
STRIP_ROWS = 64


def best_products(light: PrefixSums, sat: PrefixSums, radii: Sequence[int],
                  weights: Sequence[float], margin: int, quadrant_rule: str, best: np.ndarray,
                  best_radius: np.ndarray) -> None:
    """Eq. 3.1 (under its root) for each radius and Eq. 3.2's running maximum, written into
    ``best`` (zeros on entry) and ``best_radius``."""
    sat_disks: dict[int, np.ndarray] = {}
    for r in radii:
        quarters = [quarter_disk_sum(light, r, q) for q in QUADRANTS]
        boxes = [quarter_box_sum(light, r + margin, q) for q in QUADRANTS]
        n_quarter, n_box = quarter_disk_size(r), (r + margin + 1) ** 2
        contrast = lightness_contrast(
            [quadrant_contrast(d, b, n_quarter, n_box) for d, b in zip(quarters, boxes)],
            n_quarter, n_box, quadrant_rule)
        light_disk = average(disk_from_quarters(light, r, quarters), disk_size(r))
        for radius in (r, 2 * r):
            if radius not in sat_disks:
                sat_disks[radius] = disk_sum(sat, radius)
        inner = sat_disks.pop(r)
        sat_best = cv2.max(average(inner, disk_size(r)),
                           annulus_saturation(sat_disks[2 * r], inner, r))
        product = weighted_product((light_disk, contrast, sat_best), weights)
        better = np.greater(product, best)
        np.maximum(best, product, out=best)
        np.copyto(best_radius, np.int32(r), where=better)


class Conspicuity(Detector):
    """Zheng's conspicuity map (Eq. 3.1-3.12) followed by the localization of 3.2.2."""

    name = "conspicuity"
    summary = "Zheng's conspicuity map (lightness, quadrant contrast, saturation) + localization"
    section = "Zheng 2016, 3.2.1-3.2.2, Eq. 3.1-3.15, Algorithm 3-1, Table 5-1"
    params = (
        Param("weights", "floats", (1.0, 1.0, 1.0), min=0, length=3, section="Table 5-1",
              help="(w_L, w_LC, w_S): weights of lightness, contrast, saturation (Eq. 3.1)"),
        Param("radii", "ints", tuple(range(1, 11)), min=1, max=64, section="Table 5-1",
              help="the lens radius set RAD in pixels (Eq. 3.2)"),
        Param("margin", "int", 0, min=0, max=32, section="Table 5-1",
              help="A2 margin m around the lens disk A1 (Eq. 3.9)"),
        Param("quadrant_rule", "str", "max", choices=("max", "min"), section="Eq. 3.5, 3.2.1",
              help="combine the four quadrant contrasts by max (as printed) or min (prose)"),
        ROI_PARAM,
    ) + LOCALIZATION_PARAMS

    def detect(self, frame: Frame) -> list[Candidate]:
        """Candidates, best first, each scored by its conspicuity with its arg-max radius."""
        p = self.params
        check_settings(p["radii"], p["weights"], p["margin"])
        roi = region_of_interest(frame.image, p["roi_top"])
        cmap = conspicuity_map(roi, p["radii"], p["weights"], p["margin"], p["quadrant_rule"])
        return localize(cmap.values, p, radius_map=cmap.radius)


@hookimpl
def register_detectors(register):
    register(Conspicuity)
