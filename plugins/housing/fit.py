"""Fitting a signal housing around a lit lens: the dark rectangle the lamp sits in.

Beyond the documents (issue 11): the field's datasets box whole housings while every method of
the three documents outputs a lens. For each lens ``(x, y, r)`` the fit

1. **searches** layouts: vertical and horizontal heads of :data:`LENS_COUNTS` lenses, the lit
   lens at every position, housing widths of :data:`WIDTHS` x ``r`` and lens pitches of
   :data:`PITCHES` x width; each hypothesis is scored by its darkness contrast, the mean grey
   level of a band just outside the box against the mean inside it (the lit lens left out),
   ``(outside - inside) / outside``;
2. **refines** each edge of the best box within ``+-REFINE x r`` to the offset where a strip
   just outside is brightest against a strip just inside (a gradient projection across the edge);
3. **scores** the refined box by its contrast, clipped to [0, 1].

Every box sum is four look-ups in one integral image of the frame, and all hypotheses of all
candidates are scored in one vectorised pass.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import cv2
import numpy as np

#: Lens counts of the heads searched.
LENS_COUNTS = (3, 4)
#: Housing width, in lens radii.
WIDTHS = (2.4, 2.8, 3.2)
#: Lens pitch along the axis, as a share of the housing width (square cells, or lenses packed
#: closer, as on many European heads).
PITCHES = (0.65, 0.8, 1.0)
#: Lens radii (px) tried besides the detector's own: many detectors (FRST, top-hat) give a centre
#: but no reliable radius, and one lens radius is the unit of every layout.
RADIUS_LADDER = (2.0, 3.0, 4.0, 6.0, 8.0, 11.0, 16.0, 23.0, 32.0, 45.0, 64.0)
#: Second-pass radius factors around the first pass's choice.
FINE = np.array([0.85, 0.92, 1.0, 1.08, 1.17])
#: Edge refinement range, in lens radii: across the head, and along it (the two ends move by
#: up to about one lens cell, so a head with one lens more or less than its layout still fits).
REFINE = 0.5
REFINE_ALONG = 3.2
#: Width of the band outside the box and of the edge strips, in lens radii (at least 1 px).
BAND = 0.6


@dataclass(frozen=True)
class Layout:
    """One head layout searched: orientation, lens count, lit position, width, pitch."""

    vertical: bool
    lenses: int
    lit: int
    width: float
    pitch: float


LAYOUTS = tuple(
    Layout(vertical, n, lit, w, p)
    for vertical in (True, False)
    for n in LENS_COUNTS
    for lit in range(n)
    for w in WIDTHS
    for p in PITCHES
)


def integral(gray: np.ndarray) -> np.ndarray:
    """int32 (H + 1, W + 1) integral image of a grey uint8 image (exact up to 8 MP)."""
    return cv2.integral(gray, sdepth=cv2.CV_32S)


def box_sums(table: np.ndarray, boxes: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Sums and pixel counts of ``boxes`` (..., 4) as (x0, y0, x1, y1), rounded to pixels and
    clipped to the image."""
    height, width = table.shape[0] - 1, table.shape[1] - 1
    x0 = np.clip(np.rint(boxes[..., 0]), 0, width).astype(np.int64)
    y0 = np.clip(np.rint(boxes[..., 1]), 0, height).astype(np.int64)
    x1 = np.clip(np.rint(boxes[..., 2]), 0, width).astype(np.int64)
    y1 = np.clip(np.rint(boxes[..., 3]), 0, height).astype(np.int64)
    x1, y1 = np.maximum(x1, x0), np.maximum(y1, y0)
    total = table[y1, x1] - table[y0, x1] - table[y1, x0] + table[y0, x0]
    return total.astype(np.float64), ((x1 - x0) * (y1 - y0)).astype(np.float64)


def grow(boxes: np.ndarray, margin: np.ndarray) -> np.ndarray:
    """``boxes`` widened by ``margin`` on every side."""
    m = np.asarray(margin)[..., None]
    return boxes + np.concatenate([-m, -m, m, m], axis=-1)


def contrast(table: np.ndarray, boxes: np.ndarray, lens: np.ndarray, band: np.ndarray):
    """``(outside - inside) / outside`` of each box: inside without the lens square, outside a
    ``band`` wide frame around the box."""
    inner, inner_n = box_sums(table, boxes)
    lens_sum, lens_n = box_sums(table, lens)
    outer, outer_n = box_sums(table, grow(boxes, band))
    inside = (inner - lens_sum) / np.maximum(inner_n - lens_n, 1)
    outside = (outer - inner) / np.maximum(outer_n - inner_n, 1)
    return (outside - inside) / np.maximum(outside, 1.0)


#: The layouts of the first, coarse pass (one width, the extreme pitches).
COARSE = tuple(lay for lay in LAYOUTS if lay.width == 2.8 and lay.pitch in (0.65, 1.0))


def layout_boxes(x, y, r, layouts: Sequence[Layout] = LAYOUTS) -> np.ndarray:
    """(N, len(layouts), 4) housing boxes of each layout around lenses ``(x, y, r)``."""
    out = np.zeros((len(x), len(layouts), 4))
    for k, layout in enumerate(layouts):
        half = layout.width * r / 2
        pitch = layout.pitch * layout.width * r
        start = -(layout.lit + 0.5) * pitch
        end = start + layout.lenses * pitch
        if layout.vertical:
            out[:, k] = np.stack([x - half, y + start, x + half, y + end], axis=1)
        else:
            out[:, k] = np.stack([x + start, y - half, x + end, y + half], axis=1)
    return out


def refine(table: np.ndarray, boxes: np.ndarray, r: np.ndarray) -> np.ndarray:
    """Move each edge of ``boxes`` (N, 4) within ``+-REFINE r`` (the ends: ``+-REFINE_ALONG r``)
    to where the strip outside it is brightest against the strip inside it (sides: 0 left,
    1 top, 2 right, 3 bottom)."""
    steps = np.linspace(-1.0, 1.0, 25)
    width = np.maximum(BAND * r, 1.0)[:, None]
    rows = np.arange(len(boxes))
    vertical = (boxes[:, 3] - boxes[:, 1]) >= (boxes[:, 2] - boxes[:, 0])
    out = boxes.copy()
    for side in range(4):
        along = vertical if side % 2 == 1 else ~vertical
        reach = np.where(along, REFINE_ALONG, REFINE) * r
        edge = boxes[:, side][:, None] + steps[None, :] * reach[:, None]  # (N, S)
        outward = -1.0 if side < 2 else 1.0
        axis = side % 2  # 0: the edge is an x coordinate, 1: a y coordinate
        span = boxes[:, [1 - axis, 3 - axis]]  # the box's extent along the edge
        strips = []
        for direction in (outward, -outward):  # the strip outside, then the one inside
            a, b = edge, edge + direction * width
            strip = np.empty(edge.shape + (4,))
            strip[..., axis], strip[..., axis + 2] = np.minimum(a, b), np.maximum(a, b)
            strip[..., 1 - axis] = span[:, None, 0]
            strip[..., 3 - axis] = span[:, None, 1]
            total, count = box_sums(table, strip)
            strips.append(total / np.maximum(count, 1))
        out[:, side] = edge[rows, np.argmax(strips[0] - strips[1], axis=1)]
    for low in (0, 1):  # opposite ends that crossed: keep the box at least one radius long
        middle = (out[:, low] + out[:, low + 2]) / 2
        crossed = out[:, low + 2] - out[:, low] < r
        out[crossed, low] = middle[crossed] - r[crossed] / 2
        out[crossed, low + 2] = middle[crossed] + r[crossed] / 2
    return out


def radius_options(r: np.ndarray) -> np.ndarray:
    """(N, K) lens radii to try per candidate: the detector's radius and 0.8 / 1.25 of it, and
    the :data:`RADIUS_LADDER` steps within 0.5-3x of it (all steps when it is below 2 px, a
    detector without a radius estimate); unused slots are NaN."""
    ladder = np.array(RADIUS_LADDER)
    own = r[:, None] * np.array([0.8, 1.0, 1.25])
    steps = np.where(
        (r[:, None] < 2) | ((ladder >= 0.5 * r[:, None]) & (ladder <= 3 * r[:, None])),
        ladder,
        np.nan,
    )
    own = np.where(r[:, None] >= 2, own, np.nan)
    return np.concatenate([own, steps], axis=1)


def best_layouts(
    table: np.ndarray,
    x: np.ndarray,
    y: np.ndarray,
    options: np.ndarray,
    layouts: Sequence[Layout] = LAYOUTS,
) -> tuple[np.ndarray, np.ndarray]:
    """The best-scoring box (N, 4) over ``layouts`` and every radius of ``options`` (N, K;
    NaN: unused, not computed), and the radius it used."""
    owner, option = np.nonzero(~np.isnan(options))
    radii = options[owner, option]
    xs, ys = x[owner], y[owner]
    boxes = layout_boxes(xs, ys, radii, layouts)  # (M, L, 4)
    lens = np.stack([xs - radii, ys - radii, xs + radii, ys + radii], axis=1)[:, None, :]
    band = np.maximum(BAND * radii, 1.0)[:, None]
    scores = contrast(table, boxes, np.broadcast_to(lens, boxes.shape), band)
    best_layout = np.argmax(scores, axis=1)
    best_score = scores[np.arange(len(owner)), best_layout]
    order = np.lexsort((-best_score, owner))  # per owner, its best hypothesis first
    first = order[np.r_[True, owner[order][1:] != owner[order][:-1]]]
    return boxes[first, best_layout[first]], radii[first]


def fit_housings(
    gray: np.ndarray, lenses: Sequence[tuple[float, float, float]]
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Housing boxes (N, 4), fit scores (N,) in [0, 1] and the lens radius each fit chose, around
    ``lenses`` (x, y, radius) of a grey uint8 frame.

    Two passes: the radii of :func:`radius_options` over the :data:`COARSE` layouts, then
    0.85-1.17x the radius the first pass chose over every layout; the best box's edges are
    then refined.
    """
    if not len(lenses):
        return np.zeros((0, 4)), np.zeros(0), np.zeros(0)
    table = integral(gray)
    x, y, r = (np.asarray(v, np.float64) for v in zip(*lenses))
    _, coarse = best_layouts(table, x, y, radius_options(r), COARSE)
    best, chosen = best_layouts(table, x, y, coarse[:, None] * FINE)
    lens = np.stack([x - chosen, y - chosen, x + chosen, y + chosen], axis=1)
    # A housing holds its lens: refinement may not move an edge past the lens disc.
    refined = refine(table, best, chosen)
    refined[:, :2] = np.minimum(refined[:, :2], lens[:, :2])
    refined[:, 2:] = np.maximum(refined[:, 2:], lens[:, 2:])
    final = contrast(table, refined, lens, np.maximum(BAND * chosen, 1.0))
    return refined, np.clip(final, 0.0, 1.0), chosen
