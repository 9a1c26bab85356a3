"""The housing fit as NumPy computed it before it was compiled: every box sum
of a search step gathered over one array of boxes (``box_sums``), the contrasts, the arg-max
over layouts and the edge refinement as array operations. The oracle the compiled searches of
``plugins/verifiers/housing/fit.py`` and ``lens.py`` must match exactly; the steps the speed-up left
alone (the radius options, head variants, layout boxes, ``keep_long``) are imported."""

from __future__ import annotations

import numpy as np

from tsrkit_plugins.verifiers.housing.boxes import box_sums, integral
from tsrkit_plugins.verifiers.housing.fit import (
    BAND,
    COARSE,
    FINE,
    REFINE,
    REFINE_ALONG,
    REFINE_STEPS,
    head_variants,
    keep_long,
    layout_boxes,
    radius_options,
)
from tsrkit_plugins.verifiers.housing.lens import (
    FLOOR,
    MIN_CONTRAST,
    OFFSETS,
    RADIUS_PER_HALF_SIDE,
    SCALES,
)


def box_means(table, boxes):
    total, count = box_sums(table, boxes)
    return total / np.maximum(count, 1), count


def measure_lenses(table, x, y, r):
    half = SCALES[None, :, None]
    cx = x[:, None, None] + OFFSETS[None, None, :, 0] * half
    cy = y[:, None, None] + OFFSETS[None, None, :, 1] * half
    inner, inner_n = box_means(table, np.stack([cx - half, cy - half, cx + half, cy + half], -1))
    outer, outer_n = box_means(
        table, np.stack([cx - 2 * half, cy - 2 * half, cx + 2 * half, cy + 2 * half], -1)
    )
    ring = (outer * outer_n - inner * inner_n) / np.maximum(outer_n - inner_n, 1)
    contrast = ((inner - ring) / np.maximum(ring, FLOOR)).reshape(len(x), -1)
    best = np.argmax(contrast, axis=1)
    rows = np.arange(len(x))
    found = contrast[rows, best] >= MIN_CONTRAST
    scale, offset = np.unravel_index(best, cx.shape[1:])
    return (
        np.where(found, cx[rows, scale, offset], x),
        np.where(found, cy[rows, scale, offset], y),
        np.where(found, RADIUS_PER_HALF_SIDE * SCALES[scale], r),
        found,
    )


def grow(boxes, margin):
    m = np.asarray(margin)[..., None]
    return boxes + np.concatenate([-m, -m, m, m], axis=-1)


def contrast(table, boxes, lens, band):
    inner, inner_n = box_sums(table, boxes)
    lens_sum, lens_n = box_sums(table, lens)
    outer, outer_n = box_sums(table, grow(boxes, band))
    inside = (inner - lens_sum) / np.maximum(inner_n - lens_n, 1)
    outside = (outer - inner) / np.maximum(outer_n - inner_n, 1)
    return (outside - inside) / np.maximum(outside, 1.0)


def refine(table, boxes, r):
    steps = np.linspace(-1.0, 1.0, REFINE_STEPS)
    width = np.maximum(BAND * r, 1.0)[:, None]
    rows = np.arange(len(boxes))
    vertical = (boxes[:, 3] - boxes[:, 1]) >= (boxes[:, 2] - boxes[:, 0])
    out = boxes.copy()
    for side in range(4):
        along = vertical if side % 2 == 1 else ~vertical
        reach = np.where(along, REFINE_ALONG, REFINE) * r
        edge = boxes[:, side][:, None] + steps[None, :] * reach[:, None]
        outward = -1.0 if side < 2 else 1.0
        axis = side % 2
        span = boxes[:, [1 - axis, 3 - axis]]
        strips = []
        for direction in (outward, -outward):
            a, b = edge, edge + direction * width
            strip = np.empty(edge.shape + (4,))
            strip[..., axis], strip[..., axis + 2] = np.minimum(a, b), np.maximum(a, b)
            strip[..., 1 - axis] = span[:, None, 0]
            strip[..., 3 - axis] = span[:, None, 1]
            strips.append(box_means(table, strip)[0])
        out[:, side] = edge[rows, np.argmax(strips[0] - strips[1], axis=1)]
    return out


def best_layouts(table, x, y, options, layouts):
    owner, option = np.nonzero(~np.isnan(options))
    radii = options[owner, option]
    xs, ys = x[owner], y[owner]
    rows = layouts if layouts.ndim == 2 else layouts[owner]
    boxes = layout_boxes(xs[:, None], ys[:, None], radii[:, None], rows)
    lens = np.stack([xs - radii, ys - radii, xs + radii, ys + radii], axis=1)[:, None, :]
    band = np.maximum(BAND * radii, 1.0)[:, None]
    scores = contrast(table, boxes, lens, band)
    best_layout = np.argmax(scores, axis=1)
    best_score = scores[np.arange(len(owner)), best_layout]
    order = np.lexsort((-best_score, owner))
    first = order[np.r_[True, owner[order][1:] != owner[order][:-1]]]
    chosen = rows[best_layout[first]] if rows.ndim == 2 else rows[first, best_layout[first]]
    return boxes[first, best_layout[first]], radii[first], chosen


def fit_housings(gray, lenses):
    table = integral(gray)
    x, y, r, measured = measure_lenses(table, *(np.asarray(v, np.float64) for v in zip(*lenses)))
    _, coarse, heads = best_layouts(table, x, y, radius_options(r, measured), COARSE)
    searched, chosen, _ = best_layouts(table, x, y, coarse[:, None] * FINE, head_variants(heads))
    lens = np.stack([x - chosen, y - chosen, x + chosen, y + chosen], axis=1)
    refined = keep_long(refine(table, searched, chosen), searched)
    refined[:, :2] = np.minimum(refined[:, :2], lens[:, :2])
    refined[:, 2:] = np.maximum(refined[:, 2:], lens[:, 2:])
    final = contrast(table, refined, lens, np.maximum(BAND * chosen, 1.0))
    return refined, np.clip(final, 0.0, 1.0), np.stack([x, y, chosen], axis=1)
