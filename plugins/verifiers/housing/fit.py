"""Fitting a signal housing around a lit lens: the dark rectangle the lamp sits in.

Beyond the documents: the field's datasets box whole housings while every method of
the three documents outputs a lens. For each candidate lens ``(x, y, r)`` the fit

1. **measures** the lit lens near the candidate (:mod:`.lens`): its centre and radius, the unit
   of every layout;
2. **searches** layouts: vertical and horizontal heads of :data:`LENS_COUNTS` lenses, the lit
   lens at every position, housing widths of :data:`WIDTHS` x ``r`` and lens pitches of
   :data:`PITCHES` x width; each hypothesis is scored by its darkness contrast, the mean grey
   level of a band just outside the box against the mean inside it (the lit lens left out),
   ``(outside - inside) / outside``. A coarse pass tries every orientation, lens count and lit
   position at the middle width and pitch over the radii of :func:`radius_options`; a fine pass
   tries every width and pitch of the coarse winner's head at 0.85-1.17x its radius;
3. **refines** each edge of the best box within ``+-REFINE x r`` to the offset where a strip
   just outside is brightest against a strip just inside (a gradient projection across the
   edge), keeps the box at least :data:`MIN_ASPECT` widths long (a head of three lenses) and
   around its lens;
4. **scores** the refined box by its contrast, clipped to [0, 1].

Every box sum is four look-ups in one integral image of the frame (:mod:`.boxes`), and all
hypotheses of all candidates are scored in one compiled pass (:func:`score_layouts`; each
value computed by the same float64 operations, in the same order, as the NumPy form before it:
``tests/verifiers/test_housing_oracle.py`` compares them).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from numba import njit

from tsrkit_plugins.verifiers.housing.boxes import box_mean, box_sum, integral
from tsrkit_plugins.verifiers.housing.lens import measure_lenses

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
#: Largest ladder step tried around a detector's point (a candidate without a radius estimate
#: whose lit lens was not measured either): a 16-px lens is a near head, which every detector
#: gives a radius.
POINT_REACH = 16.0
#: Span of the ladder around the lens radius: a detector's radius (0.5-3x), or a measured lit
#: lens's (0.6-1.8x: a large dark region several lens sizes away no longer wins).
SPAN_GIVEN = (0.5, 3.0)
SPAN_MEASURED = (0.6, 1.8)
#: Second-pass radius factors around the first pass's choice.
FINE = np.array([0.85, 0.92, 1.0, 1.08, 1.17])
#: Edge refinement range, in lens radii: across the head, and along it (the two ends move by
#: up to about one lens cell, so a head with one lens more or less than its layout still fits).
REFINE = 0.5
REFINE_ALONG = 3.2
#: Offsets tried per edge, evenly over its range.
REFINE_STEPS = 13
#: Those offsets, in units of the range.
STEPS = np.linspace(-1.0, 1.0, REFINE_STEPS)
#: Width of the band outside the box and of the edge strips, in lens radii (at least 1 px).
BAND = 0.6
#: Shortest head after refinement, in housing widths: the shortest layout searched (three lenses
#: at pitch 0.65) is 1.95 widths long.
MIN_ASPECT = 1.8

#: Every layout searched, one row each: vertical (1/0), lens count, lit position (0: top or
#: left), width (lens radii), pitch (share of the width).
LAYOUTS = np.array(
    [
        (vertical, n, lit, w, p)
        for vertical in (1, 0)
        for n in LENS_COUNTS
        for lit in range(n)
        for w in WIDTHS
        for p in PITCHES
    ],
    dtype=np.float64,
)
#: The layouts of the coarse pass: the middle width and pitch (the extreme pitches as well fitted
#: no better on the development splits, at twice the cost).
COARSE = LAYOUTS[(LAYOUTS[:, 3] == 2.8) & (LAYOUTS[:, 4] == 0.8)]


@njit(cache=True, nogil=True, inline="always")
def box_contrast(
    table: np.ndarray,
    box: tuple[float, float, float, float],
    lens: tuple[np.int32, float],
    band: float,
) -> float:
    """``(outside - inside) / outside`` of ``box``: inside without the lens (its sum and pixel
    count, ``lens``), outside a ``band`` wide frame around the box."""
    x0, y0, x1, y1 = box
    inner, inner_n = box_sum(table, x0, y0, x1, y1)
    outer, outer_n = box_sum(table, x0 - band, y0 - band, x1 + band, y1 + band)
    inside = (inner - lens[0]) / max(inner_n - lens[1], 1.0)
    outside = (outer - inner) / max(outer_n - inner_n, 1.0)
    return (outside - inside) / max(outside, 1.0)


@njit(cache=True, nogil=True)
def contrasts(table: np.ndarray, boxes: np.ndarray, lens: np.ndarray, band: np.ndarray):
    """:func:`box_contrast` of each box of ``boxes`` (N, 4) with its ``lens`` box (N, 4) and
    ``band`` (N,)."""
    out = np.empty(len(boxes))
    for i in range(len(boxes)):
        box = (boxes[i, 0], boxes[i, 1], boxes[i, 2], boxes[i, 3])
        around = box_sum(table, lens[i, 0], lens[i, 1], lens[i, 2], lens[i, 3])
        out[i] = box_contrast(table, box, around, band[i])
    return out


@njit(cache=True, nogil=True, inline="always")
def layout_box(
    x: float, y: float, r: float, layout: np.ndarray
) -> tuple[float, float, float, float]:
    """The housing box of one ``layout`` (a row of :data:`LAYOUTS`) around the lens
    ``(x, y, r)``, as :func:`layout_boxes` computes it."""
    vertical, lenses, lit, width, pitch = layout[0], layout[1], layout[2], layout[3], layout[4]
    half = width * r / 2
    step = pitch * width * r
    start = -(lit + 0.5) * step
    end = start + lenses * step
    if vertical != 0:
        return x - half, y + start, x + half, y + end
    return x + start, y - half, x + end, y + half


@njit(cache=True, nogil=True)
def score_layouts(
    table: np.ndarray,
    lenses: np.ndarray,
    layouts: np.ndarray,
    group: np.ndarray,
    best: np.ndarray,
    score: np.ndarray,
) -> None:
    """For each hypothesis ``i``, a lens ``lenses[i]`` (x, y, radius), the layout of
    ``layouts[group[i]]`` (G, L, 5) whose box scores the best contrast (the first of equals):
    its index into ``best[i]``, its contrast into ``score[i]``."""
    for i in range(len(lenses)):
        x, y, r = lenses[i, 0], lenses[i, 1], lenses[i, 2]
        lens = box_sum(table, x - r, y - r, x + r, y + r)  # the same for every layout
        band = max(BAND * r, 1.0)
        rows = layouts[group[i]]
        for k in range(rows.shape[0]):
            value = box_contrast(table, layout_box(x, y, r, rows[k]), lens, band)
            if k == 0 or value > score[i]:
                best[i], score[i] = k, value


def layout_boxes(x, y, r, layouts: np.ndarray) -> np.ndarray:
    """Housing boxes (..., 4) of ``layouts`` (rows of :data:`LAYOUTS`, (..., 5)) around lenses
    ``(x, y, r)``; all broadcast together."""
    vertical, lenses, lit, width, pitch = np.moveaxis(layouts, -1, 0)
    half = width * r / 2
    step = pitch * width * r
    start = -(lit + 0.5) * step
    end = start + lenses * step
    vertical = vertical.astype(bool)
    along, across = np.where(vertical, y, x), np.where(vertical, x, y)
    a0, a1, c0, c1 = along + start, along + end, across - half, across + half
    return np.stack(
        [
            np.where(vertical, c0, a0),
            np.where(vertical, a0, c0),
            np.where(vertical, c1, a1),
            np.where(vertical, a1, c1),
        ],
        axis=-1,
    )


@njit(cache=True, nogil=True, inline="always")
def strip_mean(
    table: np.ndarray, axis: int, edge: float, shift: float, low: float, high: float
) -> float:
    """The mean of the strip between ``edge`` and ``edge + shift`` across ``axis`` (0: x) and
    from ``low`` to ``high`` along it."""
    a, b = min(edge, edge + shift), max(edge, edge + shift)
    if axis == 0:
        return box_mean(table, a, low, b, high)
    return box_mean(table, low, a, high, b)


@njit(cache=True, nogil=True)
def refine_edges(table: np.ndarray, boxes: np.ndarray, r: np.ndarray, out: np.ndarray) -> None:
    """:func:`refine` into ``out`` (N, 4): for each side of each box the first of the
    :data:`REFINE_STEPS` offsets where the outer strip's mean is most above the inner one's."""
    for i in range(len(boxes)):
        width = max(BAND * r[i], 1.0)
        vertical = (boxes[i, 3] - boxes[i, 1]) >= (boxes[i, 2] - boxes[i, 0])
        for side in range(4):
            axis = side % 2  # 0: the edge is an x coordinate, 1: a y coordinate
            along = vertical if axis == 1 else not vertical
            reach = (REFINE_ALONG if along else REFINE) * r[i]
            outward = -width if side < 2 else width
            low, high = boxes[i, 1 - axis], boxes[i, 3 - axis]
            best = 0.0
            for k in range(REFINE_STEPS):
                edge = boxes[i, side] + STEPS[k] * reach
                outside = strip_mean(table, axis, edge, outward, low, high)
                gain = outside - strip_mean(table, axis, edge, -outward, low, high)
                if k == 0 or gain > best:
                    best, out[i, side] = gain, edge


def refine(table: np.ndarray, boxes: np.ndarray, r: np.ndarray) -> np.ndarray:
    """Move each edge of ``boxes`` (N, 4) within ``+-REFINE r`` (the ends: ``+-REFINE_ALONG r``)
    to where the strip outside it is brightest against the strip inside it (sides: 0 left,
    1 top, 2 right, 3 bottom; compiled: :func:`refine_edges`)."""
    out = np.empty_like(boxes)
    refine_edges(table, np.ascontiguousarray(boxes, np.float64), r.astype(np.float64), out)
    return out


def keep_long(refined: np.ndarray, searched: np.ndarray) -> np.ndarray:
    """``refined`` boxes (N, 4) lengthened along their head's axis to :data:`MIN_ASPECT` x
    their width where refinement shortened them below it, each end moving back towards the
    ``searched`` box's (equally when neither end moved in)."""
    out = refined.copy()
    vertical = (searched[:, 3] - searched[:, 1]) >= (searched[:, 2] - searched[:, 0])
    for low, rows in ((1, vertical), (0, ~vertical)):
        across = out[:, 3 - low] - out[:, 1 - low]
        missing = np.maximum(MIN_ASPECT * across - (out[:, low + 2] - out[:, low]), 0.0)
        head = np.maximum(out[:, low] - searched[:, low], 0.0)
        tail = np.maximum(searched[:, low + 2] - out[:, low + 2], 0.0)
        share = np.where(head + tail > 0, head / np.maximum(head + tail, 1e-9), 0.5)
        out[rows, low] -= (missing * share)[rows]
        out[rows, low + 2] += (missing * (1.0 - share))[rows]
    return out


def radius_options(r: np.ndarray, measured: np.ndarray) -> np.ndarray:
    """(N, K) lens radii to try per candidate: its radius (and 0.8 / 1.25 of it when it was not
    measured), and the :data:`RADIUS_LADDER` steps within :data:`SPAN_MEASURED` of a measured
    lens's radius or :data:`SPAN_GIVEN` of a detector's; a detector's radius below 2 px (a
    detector without a radius estimate) tries every step up to :data:`POINT_REACH` instead.
    A measured lens below 2 px is a small lens, not a missing estimate: it keeps its span (a
    1-px lamp of a distant head once reached the 64-px step, and a housing 20x its size).
    Unused slots are NaN."""
    ladder = np.array(RADIUS_LADDER)[None, :]
    low = np.where(measured, SPAN_MEASURED[0], SPAN_GIVEN[0])[:, None] * r[:, None]
    high = np.where(measured, SPAN_MEASURED[1], SPAN_GIVEN[1])[:, None] * r[:, None]
    point = (r[:, None] < 2) & ~measured[:, None] & (ladder <= POINT_REACH)
    steps = np.where(point | ((ladder >= low) & (ladder <= high)), ladder, np.nan)
    factors = np.where(measured[:, None], [np.nan, 1.0, np.nan], [0.8, 1.0, 1.25])
    own = np.where((r[:, None] >= 2) | measured[:, None], r[:, None] * factors, np.nan)
    return np.concatenate([own, steps], axis=1)


def best_layouts(
    table: np.ndarray, x: np.ndarray, y: np.ndarray, options: np.ndarray, layouts: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The best-scoring box (N, 4) over every radius of ``options`` (N, K; NaN: unused, not
    computed) and ``layouts`` ((L, 5) for all candidates, or (N, L, 5) each its own), with the
    radius and the layout row it used (scored by :func:`score_layouts`)."""
    owner, option = np.nonzero(~np.isnan(options))
    radii = options[owner, option]
    shared = layouts.ndim == 2
    grouped = np.ascontiguousarray(layouts[None] if shared else layouts, np.float64)
    group = np.zeros_like(owner) if shared else owner
    best_layout = np.empty(len(owner), np.int64)
    best_score = np.empty(len(owner))
    lenses = np.column_stack([x[owner], y[owner], radii])
    score_layouts(table, lenses, grouped, group, best_layout, best_score)
    order = np.lexsort((-best_score, owner))  # per owner, its best hypothesis first
    first = order[np.r_[True, owner[order][1:] != owner[order][:-1]]]
    chosen = grouped[group[first], best_layout[first]]
    boxes = layout_boxes(x[owner[first]], y[owner[first]], radii[first], chosen)
    return boxes, radii[first], chosen


def head_variants(heads: np.ndarray) -> np.ndarray:
    """(N, W x P, 5): every width and pitch of each head (orientation, lens count, lit
    position) of ``heads`` (N, 5)."""
    grid = np.array([(w, p) for w in WIDTHS for p in PITCHES])
    out = np.repeat(heads[:, None, :], len(grid), axis=1)
    out[..., 3:] = grid
    return out


def fit_housings(
    gray: np.ndarray, lenses: Sequence[tuple[float, float, float]]
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Housing boxes (N, 4), fit scores (N,) in [0, 1] and the lenses (N, 3: x, y, radius) the
    fits used, around candidate ``lenses`` (x, y, radius) of a grey uint8 frame (steps in the
    module docstring). Every box holds its lens's disc."""
    if not len(lenses):
        return np.zeros((0, 4)), np.zeros(0), np.zeros((0, 3))
    table = integral(gray)
    x, y, r, measured = measure_lenses(table, *(np.asarray(v, np.float64) for v in zip(*lenses)))
    _, coarse, heads = best_layouts(table, x, y, radius_options(r, measured), COARSE)
    searched, chosen, _ = best_layouts(table, x, y, coarse[:, None] * FINE, head_variants(heads))
    lens = np.stack([x - chosen, y - chosen, x + chosen, y + chosen], axis=1)
    refined = keep_long(refine(table, searched, chosen), searched)
    refined[:, :2] = np.minimum(refined[:, :2], lens[:, :2])
    refined[:, 2:] = np.maximum(refined[:, 2:], lens[:, 2:])
    final = contrasts(table, refined, lens, np.maximum(BAND * chosen, 1.0))
    return refined, np.clip(final, 0.0, 1.0), np.stack([x, y, chosen], axis=1)
