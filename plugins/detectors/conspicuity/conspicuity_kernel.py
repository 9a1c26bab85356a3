"""Compiled kernel of Zheng's conspicuity map (2016, 3.2.1, Eq. 3.1-3.12 under the root of
Eq. 3.1, and the running maximum of Eq. 3.2).

The window sums are the same signed sums of shifted prefix-table entries that
``conspicuity.py`` plans (:func:`compile_terms` and the ``*_plan`` functions there); this module
only executes them. One call walks a list of row runs (row, first column, end column): for each
run it sums every window into short integer row buffers and combines them into the product of
Eq. 3.1 per radius, keeping the maximum and its radius. The float32 operations of the earlier
NumPy/OpenCV execution (commit e57479b) are applied in the same order, so with unit weights
the values are bit for bit the same (other weights use ``powf`` instead of ``cv2.pow``: within
6e-8). A full frame is one run per row; a caller may pass any subset of pixels as runs.

Integer sums wrap in the buffers like the tables do (modulo 2**32 in int32, 2**16 in int16), so
the true sums (which are small) come out exact even when the column integrals overflow.

Speed (issue 16): the tables are built in one compiled pass per channel; every term is a flat
offset into the flattened tables, so each read is a contiguous run the compiler vectorises; and
a window adds its terms in groups of four, reading and writing its buffer once per group. When
every lightness window holds at most :data:`NARROW_PIXELS` pixels (radius + margin <= 10, the
paper's defaults), the lightness tables and buffers are int16: the tables wrap modulo 2**16,
each window sum is computed modulo 2**16, and since its true value lies in [-32768, 32767] it
comes out exact, with twice the lanes per vector operation (the lightness windows take about
half the time they took in int32). The saturation disks (up to 1257 pixels) are then summed
the same way in uint16, in bands of rows of at most :data:`BAND_PIXELS` pixels whose sums
(in [0, 65535]) are added in int32. Being exact integer sums, none of this changes a value
(``bench_conspicuity.py --baseline`` checks the maps and the candidates against an earlier
commit's).
"""

from __future__ import annotations

from itertools import pairwise

import numpy as np
from numba import njit

#: Plane of a channel's table stack: the row prefix sums, and their column integrals.
PREFIX, INTEGRAL = range(2)

#: The most pixels a window of a uint8 channel may hold for its sum (at most
#: ``255 * NARROW_PIXELS`` in magnitude) to be exact in int16 arithmetic.
NARROW_PIXELS = np.iinfo(np.int16).max // 255

#: The most pixels a band of a saturation disk may hold for its (non-negative) sum to be exact
#: in uint16 arithmetic.
BAND_PIXELS = np.iinfo(np.uint16).max // 255

#: Lightness windows per radius, in this order: the four quarters of A1, the four quadrant
#: boxes of A1 + A2, and the shared axes that rebuild the full disk from its quarters.
LIGHT_WINDOWS = 9


def prefix_tables(channel: np.ndarray, dtype: type = np.int32) -> np.ndarray:
    """Row prefix sums of a mirrored uint8 channel and their column integrals, stacked.

    ``table[PREFIX, y, c]`` is the sum of padded row ``y - 1`` left of column ``c`` (row 0 and
    column 0 are zero); ``table[INTEGRAL]`` sums the prefix rows ``0..y``. Entries are stored
    in ``dtype`` (int32, or int16 for :data:`NARROW_PIXELS` windows) and wrap modulo its
    range; differences of entries stay exact modulo it.
    """
    height, width = channel.shape
    stack = np.zeros((2, height + 1, width + 1), dtype)
    fill_tables(channel, stack[PREFIX], stack[INTEGRAL])
    return stack


@njit(cache=True, nogil=True)
def fill_tables(channel, prefix, integral):
    """Row prefix sums of ``channel`` into ``prefix`` and their running column sums into
    ``integral`` (both zero on entry), in one pass over the rows; integer stores wrap."""
    height, width = channel.shape
    for y in range(height):
        total = 0
        row = prefix[y + 1]
        for x in range(width):
            total += channel[y, x]
            row[x + 1] = total
        above, below = integral[y], integral[y + 1]
        for x in range(width + 1):
            below[x] = above[x] + row[x]


def flat_offsets(terms: np.ndarray, shape: tuple[int, ...]) -> np.ndarray:
    """Offsets of terms (plane, dy, dc, sign) in the flattened table stack of ``shape``,
    relative to a pixel's flat index in the prefix plane."""
    terms = terms.astype(np.int64)
    return (terms[:, 0] * shape[1] + terms[:, 1]) * shape[2] + terms[:, 2]


def positive_ends(terms: np.ndarray, starts: np.ndarray) -> np.ndarray:
    """Per window, the index after its positive terms (a plan lists them first)."""
    return np.array(
        [a + int(np.count_nonzero(terms[a:b, 3] > 0)) for a, b in pairwise(starts)],
        np.int64,
    )


@njit(cache=True, nogil=True, inline="always")
def _source(flat, offsets, t, base, count):
    """The ``count`` contiguous table entries term ``t`` reads for the pixels from ``base``."""
    start = base + offsets[t]
    return flat[start : start + count]


@njit(cache=True, nogil=True)
def window_sum(flat, offsets, first, mid, last, base, count, out):
    """``out[:count]`` = the sum of the table entries of terms ``first:mid`` minus those of
    terms ``mid:last``, each read at flat ``offsets[t]`` from ``base`` (a pixel's flat index)
    in the flattened ``flat`` tables.

    Terms are added four at a time, or two positive and two negative ones, so that ``out`` is
    read and written once per group rather than once per term; stores into ``out`` (of the
    tables' integer type) wrap, so the grouping does not change the result.
    """
    target = out[:count]
    target[:] = 0
    p, q = first, mid
    while mid - p >= 4:
        a, b = _source(flat, offsets, p, base, count), _source(flat, offsets, p + 1, base, count)
        c, d = (
            _source(flat, offsets, p + 2, base, count),
            _source(flat, offsets, p + 3, base, count),
        )
        for x in range(count):
            target[x] += (a[x] + b[x]) + (c[x] + d[x])
        p += 4
    while last - q >= 4:
        a, b = _source(flat, offsets, q, base, count), _source(flat, offsets, q + 1, base, count)
        c, d = (
            _source(flat, offsets, q + 2, base, count),
            _source(flat, offsets, q + 3, base, count),
        )
        for x in range(count):
            target[x] -= (a[x] + b[x]) + (c[x] + d[x])
        q += 4
    while mid - p >= 2 and last - q >= 2:
        a, b = _source(flat, offsets, p, base, count), _source(flat, offsets, p + 1, base, count)
        c, d = _source(flat, offsets, q, base, count), _source(flat, offsets, q + 1, base, count)
        for x in range(count):
            target[x] += (a[x] + b[x]) - (c[x] + d[x])
        p += 2
        q += 2
    while p < mid and q < last:
        a, c = _source(flat, offsets, p, base, count), _source(flat, offsets, q, base, count)
        for x in range(count):
            target[x] += a[x] - c[x]
        p += 1
        q += 1
    while p < mid:
        a = _source(flat, offsets, p, base, count)
        for x in range(count):
            target[x] += a[x]
        p += 1
    while q < last:
        a = _source(flat, offsets, q, base, count)
        for x in range(count):
            target[x] -= a[x]
        q += 1


@njit(cache=True, nogil=True)
def lightness_contrast(light, n_quarter, n_box, use_min, count, out):
    """Eq. 3.5-3.8 as exact integers: ``out[x] = max(0, comb_k(n_box * D_k - n_quarter * B_k))``
    with ``D_k`` the sum of quarter ``k`` of A1 (rows 0-3 of ``light``) and ``B_k`` that of its
    quadrant box A1 + A2 (rows 4-7); this is ``n_quarter * n_border * 255 * (LD_k - LB_k)``
    with ``n_border = n_box - n_quarter``. ``comb`` is the printed maximum, or the minimum.
    Clipping once after combining equals clipping each quadrant (max/min commute with
    ``max(0, .)``); integers keep a zero contrast exactly zero."""
    for x in range(count):
        out[x] = n_box * np.int64(light[0, x]) - n_quarter * np.int64(light[4, x])
    for q in range(1, 4):
        for x in range(count):
            part = n_box * np.int64(light[q, x]) - n_quarter * np.int64(light[4 + q, x])
            out[x] = min(out[x], part) if use_min else max(out[x], part)
    for x in range(count):
        out[x] = max(out[x], 0)


@njit(cache=True, nogil=True)
def disk_from_quarters(light, count, out):
    """The A1 sum (numerator of Eq. 3.3) from its four overlapping quarters plus the axes term
    (row 8 of ``light``: minus the centre column and the two centre-row runs they share)."""
    for x in range(count):
        out[x] = light[0, x] + light[1, x] + light[2, x] + light[3, x] + light[8, x]


@njit(cache=True, nogil=True)
def saturation_feature(inner, outer, disk_scale, annulus_scale, count, out):
    """Eq. 3.10-3.12: the larger of the disk mean of saturation and the mean over the annulus
    A3 (``outer`` disk of radius ``2 r`` minus the ``inner`` disk of radius ``r``)."""
    for x in range(count):
        out[x] = max(
            np.float32(inner[x]) * disk_scale, np.float32(outer[x] - inner[x]) * annulus_scale
        )


@njit(cache=True, nogil=True)
def weighted_product(lightness, contrast, saturation, weights, count, out):
    """The product under the root of Eq. 3.1, ``LD^w_L * LC^w_LC * S^w_S``, in float32 (a
    unit weight multiplies the feature itself)."""
    if weights[0] == 1 and weights[1] == 1 and weights[2] == 1:
        for x in range(count):
            out[x] = lightness[x] * contrast[x] * saturation[x]
        return
    for x in range(count):
        out[x] = (
            _powered(lightness[x], weights[0])
            * _powered(contrast[x], weights[1])
            * _powered(saturation[x], weights[2])
        )


@njit(cache=True, nogil=True)
def _powered(feature, weight):
    """``feature ** weight`` in float32, the feature itself for a unit weight."""
    return feature if weight == 1 else np.float32(feature**weight)


@njit(cache=True, nogil=True)
def keep_best(product, radius, count, best, best_radius):
    """Eq. 3.2's running maximum over radii; the earlier (smaller) radius wins ties."""
    for x in range(count):
        if product[x] > best[x]:
            best[x] = product[x]
            best_radius[x] = radius


@njit(cache=True, nogil=True)
def unit_max_product(
    light, inner, outer, n_quarter, n_box, scales, radius, count, best, best_radius, exact
):
    """:func:`lightness_contrast` (printed maximum), :func:`disk_from_quarters`,
    :func:`saturation_feature`, :func:`weighted_product` (unit weights) and :func:`keep_best`
    fused into one pass per pixel (the paper's defaults, Table 5-1): the same values, one loop
    instead of nine.

    The integer steps run in the number type ``exact``: int64 always holds them; float32 holds
    every integer below 2**24 exactly, and with 16-bit sums (lightness windows of at most
    ``NARROW_PIXELS`` = 128 pixels) ``n_box * D_k`` and ``n_quarter * B_k`` stay below
    ``128 * 128 * 255``, the disk below ``4 * 128 * 255`` and the saturation disks (radius up to
    2 * 10) below ``1257 * 255``, so every sum, product and difference is the same integer, in
    twice the lanes. The float32 steps after them are the same operations in the same order."""
    l0, l1, l2, l3, l4, l5, l6, l7, l8 = (
        light[0],
        light[1],
        light[2],
        light[3],
        light[4],
        light[5],
        light[6],
        light[7],
        light[8],
    )
    nq, nb = exact(n_quarter), exact(n_box)
    for x in range(count):
        q0, q1, q2, q3 = exact(l0[x]), exact(l1[x]), exact(l2[x]), exact(l3[x])
        contrast = max(
            max(nb * q0 - nq * exact(l4[x]), nb * q1 - nq * exact(l5[x])),
            max(nb * q2 - nq * exact(l6[x]), nb * q3 - nq * exact(l7[x])),
        )
        contrast = max(contrast, exact(0))
        disk = q0 + q1 + q2 + q3 + exact(l8[x])
        product = (np.float32(disk) * scales[0]) * (np.float32(contrast) * scales[1])
        ring = np.float32(exact(outer[x]) - exact(inner[x]))
        product *= max(np.float32(inner[x]) * scales[2], ring * scales[3])
        if product > best[x]:
            best[x] = product
            best_radius[x] = radius


@njit(cache=True, nogil=True)
def best_products(
    light_tables,
    sat_tables,
    pad,
    runs,
    light_offsets,
    light_starts,
    light_mids,
    sat_offsets,
    sat_starts,
    sat_mids,
    sat_bands,
    sat_inner,
    sat_outer,
    radii,
    n_quarter,
    n_box,
    scales,
    weights,
    use_min,
    exact,
    best,
    best_radius,
):
    """Eq. 3.1 (under its root) for every radius and the maximum of Eq. 3.2 over the pixels
    of ``runs``; ``best`` (zeros on entry) and ``best_radius`` are written in place.

    Parameters
    ----------
    light_tables, sat_tables : ndarray
        (2, H + 2 pad + 1, W + 2 pad + 1) from :func:`prefix_tables`: lightness (int16 or
        int32; the window buffers take its type) and saturation (int32).
    pad : int
        Mirror padding of the tables.
    runs : ndarray
        int64 (N, 3): row, first column, end column (exclusive) of the pixels to compute.
    light_offsets, light_starts, light_mids : ndarray
        Flat offsets (:func:`flat_offsets`) of the terms of the ``LIGHT_WINDOWS`` windows of
        each radius, window ``w`` of radius index ``k`` spanning
        ``light_starts[k * LIGHT_WINDOWS + w]`` to the next start, its positive terms ending at
        ``light_mids[k * LIGHT_WINDOWS + w]``.
    sat_offsets, sat_starts, sat_mids : ndarray
        The same for the bands of the saturation disks, band ``b`` spanning
        ``sat_starts[b:b + 2]``.
    sat_bands : ndarray
        Disk ``d`` is the sum of bands ``sat_bands[d]`` to ``sat_bands[d + 1]`` (exclusive).
    sat_inner, sat_outer : ndarray
        Per radius index, the saturation disk of radius ``r`` and of ``2 r``.
    radii, n_quarter, n_box : ndarray
        Per radius index: the radius, the pixels of a quarter of A1, of a quadrant box.
    scales : ndarray
        float32 (R, 4): the factors turning the lightness disk, contrast, saturation disk and
        annulus sums into means (Eq. 3.3, 3.6-3.8, 3.10, 3.11).
    weights : ndarray
        float32 (w_L, w_LC, w_S).
    use_min : bool
        Combine the quadrants by minimum instead of the printed maximum (Eq. 3.5).
    exact : type
        ``np.float32`` for 16-bit sums, ``np.int64`` otherwise: the number type of the integer
        steps of :func:`unit_max_product`, which combines when the weights are 1 and the rule is
        the printed maximum.
    """
    longest = max(1, np.max(runs[:, 2] - runs[:, 1])) if runs.shape[0] else 1
    light = np.zeros((LIGHT_WINDOWS, longest), light_tables.dtype)
    sat = np.zeros((sat_bands.shape[0] - 1, longest), np.int32)
    band = np.zeros(longest, sat_tables.dtype)
    contrast = np.zeros(longest, np.int64)
    disk = np.zeros(longest, np.int32)
    features = np.zeros((3, longest), np.float32)
    product = np.zeros(longest, np.float32)
    fused = not use_min and weights[0] == 1 and weights[1] == 1 and weights[2] == 1
    light_flat = light_tables.reshape(light_tables.size)
    sat_flat = sat_tables.reshape(sat_tables.size)
    for run in range(runs.shape[0]):
        i, x0, count = runs[run, 0], runs[run, 1], runs[run, 2] - runs[run, 1]
        base = (pad + 1 + i) * sat_tables.shape[2] + pad + x0
        for d in range(sat.shape[0]):
            total = sat[d]
            total[:count] = 0
            for b in range(sat_bands[d], sat_bands[d + 1]):
                window_sum(
                    sat_flat,
                    sat_offsets,
                    sat_starts[b],
                    sat_mids[b],
                    sat_starts[b + 1],
                    base,
                    count,
                    band,
                )
                for x in range(count):
                    total[x] += band[x]
        for k in range(radii.shape[0]):
            for w in range(LIGHT_WINDOWS):
                start = k * LIGHT_WINDOWS + w
                window_sum(
                    light_flat,
                    light_offsets,
                    light_starts[start],
                    light_mids[start],
                    light_starts[start + 1],
                    base,
                    count,
                    light[w],
                )
            inner, outer = sat[sat_inner[k]], sat[sat_outer[k]]
            if fused:
                unit_max_product(
                    light,
                    inner,
                    outer,
                    n_quarter[k],
                    n_box[k],
                    scales[k],
                    radii[k],
                    count,
                    best[i, x0 : x0 + count],
                    best_radius[i, x0 : x0 + count],
                    exact,
                )
                continue
            lightness_contrast(light, n_quarter[k], n_box[k], use_min, count, contrast)
            disk_from_quarters(light, count, disk)
            for x in range(count):
                features[0, x] = np.float32(disk[x]) * scales[k, 0]
                features[1, x] = np.float32(contrast[x]) * scales[k, 1]
            saturation_feature(inner, outer, scales[k, 2], scales[k, 3], count, features[2])
            weighted_product(features[0], features[1], features[2], weights, count, product)
            keep_best(
                product, radii[k], count, best[i, x0 : x0 + count], best_radius[i, x0 : x0 + count]
            )
