"""Compiled kernel of Zheng's conspicuity map (2016, 3.2.1, Eq. 3.1-3.12 under the root of
Eq. 3.1, and the running maximum of Eq. 3.2).

The window sums are the same signed sums of shifted prefix-table entries that
``conspicuity.py`` plans (:func:`compile_terms`, the ``*_plan`` functions and the single
entries of ``SHARED_TERMS`` and ``corner_terms`` there); this module only executes them. One
call walks a list of row runs (row, first column, end column): for each run it sums the
saturation disks (from the run's column sums, :func:`fill_columns`, with 16-bit sums; from the
tables otherwise) and the lightness quarters' staircases into short integer row buffers and
combines them, with the single lightness entries read in the same pass, into the product of
Eq. 3.1 per radius, keeping the maximum and its radius. The float32 operations of the earlier
NumPy/OpenCV execution (commit e57479b) are applied in the same order, so with unit weights
the values are bit for bit the same (other weights use ``powf`` instead of ``cv2.pow``: within
6e-8). A full frame is one run per row; a caller may pass any subset of pixels as runs.

Integer sums wrap in the buffers like the tables do (modulo 2**32 in int32, 2**16 in int16), so
the true sums (which are small) come out exact even when the column integrals overflow.

Speed: the tables are built in one compiled pass per channel; every term is a flat
offset into the flattened tables, so each read is a contiguous run the compiler vectorises; and
a window adds its terms in groups of four, reading and writing its buffer once per group. When
every lightness window holds at most :data:`NARROW_PIXELS` pixels (radius + margin <= 10, the
paper's defaults), the lightness tables and buffers are int16: the tables wrap modulo 2**16,
each window sum is computed modulo 2**16, and since its true value lies in [-32768, 32767] it
comes out exact, with twice the lanes per vector operation (the lightness windows take about
half the time they took in int32). The saturation disks (up to 1257 pixels) are then summed
in uint16, in bands of at most :data:`BAND_PIXELS` pixels whose sums (in [0, 65535]) are
added in int32, and not from the tables: a disk is the sum of its columns' vertical sums, all
centred on its row, so the row's 21 vertical sums per column (:func:`fill_columns`) serve
every disk (:func:`column_disks`: 285 reads per pixel, 336 with padding, plus 84 for the
sums, against 494 table reads). The nine lightness windows of a radius (Eq. 3.3, 3.7,
3.8) are built in the pass that combines them (:func:`_light_windows`) from the four quarters'
staircases and 24 single entries each read once (548 table reads per pixel over the paper's
ten radii became 188 buffered reads plus 240 single ones, and 90 buffered windows 40). Being
exact integer sums, none of this changes a value (``bench_conspicuity.py --baseline`` checks
the maps and the candidates against an earlier commit's).
"""

from __future__ import annotations

from itertools import pairwise

import numpy as np
from numba import njit
from numba.core import types
from numba.extending import overload

#: Plane of a channel's table stack: the row prefix sums, and their column integrals.
PREFIX, INTEGRAL = range(2)

#: The most pixels a window of a uint8 channel may hold for its sum (at most
#: ``255 * NARROW_PIXELS`` in magnitude) to be exact in int16 arithmetic.
NARROW_PIXELS = np.iinfo(np.int16).max // 255

#: The most pixels a band of a saturation disk may hold for its (non-negative) sum to be exact
#: in uint16 arithmetic.
BAND_PIXELS = np.iinfo(np.uint16).max // 255

#: Lightness windows summed into row buffers per radius: the staircase rows of the four
#: quarters of A1 (``conspicuity.stair_plan``), in the order of ``conspicuity.QUADRANTS``; the
#: rest of every lightness window is single table entries read where they are combined.
LIGHT_WINDOWS = 4


def prefix_tables(
    channel: np.ndarray, dtype: type = np.int32, out: np.ndarray | None = None
) -> np.ndarray:
    """Row prefix sums of a mirrored uint8 channel and their column integrals, stacked.

    ``table[PREFIX, y, c]`` is the sum of padded row ``y - 1`` left of column ``c`` (row 0 and
    column 0 are zero); ``table[INTEGRAL]`` sums the prefix rows ``0..y``. Entries are stored
    in ``dtype`` (int32, or int16 for :data:`NARROW_PIXELS` windows) and wrap modulo its
    range; differences of entries stay exact modulo it. Written into ``out`` (of that shape
    and type) when given.
    """
    height, width = channel.shape
    stack = np.empty((2, height + 1, width + 1), dtype) if out is None else out
    stack[:, 0] = 0
    stack[:, :, 0] = 0
    fill_tables(channel, stack[PREFIX], stack[INTEGRAL])
    return stack


@njit(cache=True, nogil=True)
def fill_tables(channel, prefix, integral):
    """Row prefix sums of ``channel`` into ``prefix`` and their running column sums into
    ``integral`` (row 0 and column 0 zero on entry, the rest is written), in one pass over the
    rows; integer stores wrap. Rows go four at a time: their four running sums are independent
    chains the processor overlaps (the single-row loop was one addition per cycle)."""
    height, width = channel.shape
    y = 0
    while y + 4 <= height:
        t0 = t1 = t2 = t3 = 0
        r0, r1, r2, r3 = prefix[y + 1], prefix[y + 2], prefix[y + 3], prefix[y + 4]
        for x in range(width):
            t0 += channel[y, x]
            t1 += channel[y + 1, x]
            t2 += channel[y + 2, x]
            t3 += channel[y + 3, x]
            r0[x + 1], r1[x + 1], r2[x + 1], r3[x + 1] = t0, t1, t2, t3
        for row in range(y + 1, y + 5):
            _integrate(prefix, integral, row)
        y += 4
    for row in range(y + 1, height + 1):
        total = 0
        for x in range(width):
            total += channel[row - 1, x]
            prefix[row, x + 1] = total
        _integrate(prefix, integral, row)


@njit(cache=True, nogil=True, inline="always")
def _integrate(prefix, integral, row):
    """``integral[row] = integral[row - 1] + prefix[row]`` (wrapping)."""
    above, below, sums = integral[row - 1], integral[row], prefix[row]
    for x in range(sums.shape[0]):
        below[x] = above[x] + sums[x]


def flat_offsets(terms: np.ndarray, shape: tuple[int, ...]) -> np.ndarray:
    """Offsets of terms (plane, dy, dc[, sign]) in the flattened table stack of ``shape``,
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
    p, q = first, mid
    if mid - p >= 4:
        a, b = _source(flat, offsets, p, base, count), _source(flat, offsets, p + 1, base, count)
        c, d = (
            _source(flat, offsets, p + 2, base, count),
            _source(flat, offsets, p + 3, base, count),
        )
        for x in range(count):
            target[x] = (a[x] + b[x]) + (c[x] + d[x])
        p += 4
    elif mid - p >= 2 and last - q >= 2:
        a, b = _source(flat, offsets, p, base, count), _source(flat, offsets, p + 1, base, count)
        c, d = _source(flat, offsets, q, base, count), _source(flat, offsets, q + 1, base, count)
        for x in range(count):
            target[x] = (a[x] + b[x]) - (c[x] + d[x])
        p += 2
        q += 2
    else:
        target[:] = 0
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


@njit(cache=True, nogil=True, inline="always")
def _at(flat, start, x):
    """The table entry at flat index ``start + x`` (an unsigned index: no negative-index fix-up
    in the vectorised loops)."""
    return flat[np.uint64(start + x)]


def _box_columns(flat, margin, x, columns):
    """The entries of the quadrant boxes' centre-column edges beyond the centre row (top left,
    top right, bottom left, bottom right of the centre column): with margin 0 they are the
    quarters' own ``columns``, otherwise read at the flat starts ``margin``. (Compiled only
    through its overload, chosen by the type of ``margin``.)"""


@overload(_box_columns, inline="always")
def _box_columns_overload(flat, margin, x, columns):
    """:func:`_box_columns` without a read when ``margin`` is None (margin 0)."""
    if isinstance(margin, types.NoneType):
        return lambda flat, margin, x, columns: columns
    return lambda flat, margin, x, columns: (
        _at(flat, margin[0], x),
        _at(flat, margin[1], x),
        _at(flat, margin[2], x),
        _at(flat, margin[3], x),
    )


@njit(cache=True, nogil=True, inline="always")
def _light_windows(stairs, flat, s, c, m, x, wrap):
    """The nine lightness window sums of one radius at pixel ``x`` of a run, each wrapped to the
    tables' integer type ``wrap`` (exact, see the module notes): the quarters of A1 (Eq. 3.7
    numerators), the quadrant boxes of A1 + A2 (Eq. 3.8) and the axes term that rebuilds the
    full disk from the quarters.

    ``stairs`` holds the quarters' staircase rows (``conspicuity.stair_plan``), ``s`` the flat
    starts of the ``SHARED_TERMS`` entries, ``c`` those of the radius's ``corner_terms`` and
    ``m`` those of its ``margin_terms`` (None with margin 0, where the quarters' column entries
    serve the boxes too) (``conspicuity.py``); every entry is read once and shared by the
    windows that use it.
    """
    p0, p1 = _at(flat, s[0], x), _at(flat, s[1], x)
    e0, e1, g0, g1 = _at(flat, s[2], x), _at(flat, s[3], x), _at(flat, s[4], x), _at(flat, s[5], x)
    right, left = _at(flat, c[0], x), _at(flat, c[1], x)
    top0, top1 = _at(flat, c[2], x), _at(flat, c[3], x)
    bottom0, bottom1 = _at(flat, c[4], x), _at(flat, c[5], x)
    box_top0, box_top1, box_bottom0, box_bottom1 = _box_columns(
        flat, m, x, (top0, top1, bottom0, bottom1)
    )
    return (
        wrap(stairs[0, x] + right - e0 + top0),
        wrap(stairs[1, x] - left + e1 - top1),
        wrap(stairs[2, x] - left + bottom1 - g1),
        wrap(stairs[3, x] + right - bottom0 + g0),
        wrap(_at(flat, c[6], x) - _at(flat, c[7], x) - e0 + box_top0),
        wrap(e1 - box_top1 - _at(flat, c[8], x) + _at(flat, c[9], x)),
        wrap(box_bottom1 - g1 - _at(flat, c[10], x) + _at(flat, c[11], x)),
        wrap(_at(flat, c[12], x) - _at(flat, c[13], x) - box_bottom0 + g0),
        wrap((left - right) + (p0 - p1) + (top1 - top0) + (bottom0 - bottom1)),
    )


@njit(cache=True, nogil=True, inline="always")
def _disk_and_contrast(w, n_quarter, n_box, use_min, exact):
    """The A1 sum (numerator of Eq. 3.3: the four quarters plus the axes term) and Eq. 3.5-3.8
    as exact integers, ``max(0, comb_k(n_box * D_k - n_quarter * B_k))`` with ``D_k`` quarter
    ``k`` and ``B_k`` its quadrant box among the window sums ``w``: this is
    ``n_quarter * n_border * 255 * (LD_k - LB_k)`` with ``n_border = n_box - n_quarter``.
    ``comb`` is the printed maximum, or the minimum. Clipping once after combining equals
    clipping each quadrant (max/min commute with ``max(0, .)``); integers keep a zero contrast
    exactly zero. Computed in the number type ``exact`` (see :func:`unit_max_product`)."""
    q0, q1, q2, q3 = exact(w[0]), exact(w[1]), exact(w[2]), exact(w[3])
    nq, nb = exact(n_quarter), exact(n_box)
    a, b = nb * q0 - nq * exact(w[4]), nb * q1 - nq * exact(w[5])
    c, d = nb * q2 - nq * exact(w[6]), nb * q3 - nq * exact(w[7])
    contrast = min(min(a, b), min(c, d)) if use_min else max(max(a, b), max(c, d))
    return q0 + q1 + q2 + q3 + exact(w[8]), max(contrast, exact(0))


@njit(cache=True, nogil=True)
def light_features(stairs, flat, s, c, m, n_quarter, n_box, use_min, count, disk, contrast, wrap):
    """The A1 sums and the integer contrasts of one radius over a run (in int64), see
    :func:`_disk_and_contrast`."""
    for x in range(count):
        w = _light_windows(stairs, flat, s, c, m, x, wrap)
        disk[x], contrast[x] = _disk_and_contrast(w, n_quarter, n_box, use_min, np.int64)


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
def keep_best(product, radius, count, best, best_radius, first):
    """Eq. 3.2's running maximum over radii; the earlier (smaller) radius wins ties. At the
    ``first`` (smallest) radius every pixel is written, whatever ``best`` held: its product
    (never negative) is the maximum so far, as it would be over a ``best`` of zeros."""
    for x in range(count):
        if first or product[x] > best[x]:
            best[x] = product[x]
            best_radius[x] = radius


@njit(cache=True, nogil=True, fastmath={"contract"})
def unit_max_product(
    stairs,
    flat,
    s,
    c,
    m,
    inner,
    outer,
    n_quarter,
    n_box,
    scales,
    radius,
    count,
    best,
    best_radius,
    first,
    wrap,
    exact,
):
    """:func:`light_features` (printed maximum), :func:`saturation_feature`,
    :func:`weighted_product` (unit weights) and :func:`keep_best` fused into one pass per pixel
    (the paper's defaults, Table 5-1): the same values, one loop instead of five.

    The integer steps run in the number type ``exact``: int64 always holds them; float32 holds
    every integer below 2**24 exactly, and with 16-bit sums (lightness windows of at most
    ``NARROW_PIXELS`` = 128 pixels) ``n_box * D_k`` and ``n_quarter * B_k`` stay below
    ``128 * 128 * 255``, the disk below ``4 * 128 * 255`` and the saturation disks (radius up to
    2 * 10) below ``1257 * 255``, so every sum, product and difference is the same integer, in
    twice the lanes. The float32 steps after them are the same operations in the same order;
    ``contract`` lets the compiler fuse only the multiply-subtracts of the exact integer
    contrasts, whose float32 results are exact either way. ``first`` as in :func:`keep_best`."""
    for x in range(count):
        w = _light_windows(stairs, flat, s, c, m, x, wrap)
        disk, contrast = _disk_and_contrast(w, n_quarter, n_box, False, exact)
        product = (np.float32(disk) * scales[0]) * (np.float32(contrast) * scales[1])
        ring = np.float32(exact(outer[x]) - exact(inner[x]))
        product *= max(np.float32(inner[x]) * scales[2], ring * scales[3])
        if first or product > best[x]:
            best[x] = product
            best_radius[x] = radius


@njit(cache=True, nogil=True, inline="always")
def _shared_starts(offsets, base):
    """The flat starts of the ``SHARED_TERMS`` entries for a run starting at ``base``."""
    return (
        base + offsets[0],
        base + offsets[1],
        base + offsets[2],
        base + offsets[3],
        base + offsets[4],
        base + offsets[5],
    )


@njit(cache=True, nogil=True, inline="always")
def _corner_starts(offsets, k, base):
    """The flat starts of radius index ``k``'s ``corner_terms`` for a run starting at ``base``."""
    o = offsets[k]
    return (
        base + o[0],
        base + o[1],
        base + o[2],
        base + o[3],
        base + o[4],
        base + o[5],
        base + o[6],
        base + o[7],
        base + o[8],
        base + o[9],
        base + o[10],
        base + o[11],
        base + o[12],
        base + o[13],
    )


def _margin_starts(offsets, k, base):
    """The flat starts of radius index ``k``'s ``margin_terms`` for a run starting at ``base``,
    None when ``offsets`` is None (margin 0). (Compiled only through its overload.)"""


@overload(_margin_starts, inline="always")
def _margin_starts_overload(offsets, k, base):
    """:func:`_margin_starts`, chosen by the type of ``offsets``."""
    if isinstance(offsets, types.NoneType):
        return lambda offsets, k, base: None
    return lambda offsets, k, base: (
        base + offsets[k, 0],
        base + offsets[k, 1],
        base + offsets[k, 2],
        base + offsets[k, 3],
    )


@njit(cache=True, nogil=True)
def fill_columns(flat, plane, table_width, pad, i, x0, count, columns):
    """The vertical sums of the saturation around image row ``i``, for the disks of the run
    ``x0 .. x0 + count`` on that row: ``columns[h, c]`` = the sum of padded column ``c`` over
    the ``2 h + 1`` rows ``i - h .. i + h``, for ``h <= reach = columns.shape[0] - 2`` and the
    columns within ``reach`` of the run (the last row of ``columns`` is left as it is: the
    caller keeps it zero, see :func:`column_disks`).

    Four reads of the column integrals (plane ``plane`` of the flattened table stack ``flat``)
    per entry. Stored in the tables' integer type, wrapping or not: a sum of at most
    ``41 * 255`` is exact.
    """
    reach = columns.shape[0] - 2
    first, length = pad + x0 - reach, count + 2 * reach
    for h in range(reach + 1):
        top = plane + (pad + i - h) * table_width + first
        bottom = plane + (pad + i + h + 1) * table_width + first
        below, below_next = flat[bottom : bottom + length], flat[bottom + 1 : bottom + 1 + length]
        above, above_next = flat[top : top + length], flat[top + 1 : top + 1 + length]
        target = columns[h, first : first + length]
        for x in range(length):
            target[x] = (below_next[x] - below[x]) - (above_next[x] - above[x])


@njit(cache=True, nogil=True, inline="always")
def _four(flat, offsets, t, base, count):
    """The sum of the entries of terms ``t .. t + 3`` at pixel ``x`` is
    ``(a[x] + b[x]) + (c[x] + d[x])`` for the four sources returned."""
    return (
        _source(flat, offsets, t, base, count),
        _source(flat, offsets, t + 1, base, count),
        _source(flat, offsets, t + 2, base, count),
        _source(flat, offsets, t + 3, base, count),
    )


@njit(cache=True, nogil=True)
def column_disks(flat, offsets, starts, bands, base, count, band, sat):
    """The saturation disks of a run from its column sums (:func:`fill_columns`, flattened in
    ``flat``) into the int32 rows of ``sat``.

    Disk ``d`` is the sum of its bands ``bands[d]`` to ``bands[d + 1]``, band ``b`` the sum of
    the columns of terms ``starts[b]`` to ``starts[b + 1]`` (one read per column: a disk is
    the sum of its columns, all centred on its row; ``conspicuity.column_plan``), a multiple
    of four: a plan pads its bands with reads of the zero row. Four terms are added per pass;
    a band's sum is exact in the type of ``band`` (at most :data:`BAND_PIXELS` pixels), and
    its last pass widens it into the disk's int32 row directly.

    With the saturation's row-prefix tables a disk is two reads per row of the disk or four
    per run of rows of equal width (494 reads per pixel for the paper's 15 saturation disks,
    in 31 bands); here it is one read per column, shared by every disk of the row: 285 reads
    (336 with the padding), plus the 84 of :func:`fill_columns`, in fewer passes.
    """
    kind = band.dtype.type
    for d in range(sat.shape[0]):
        total = sat[d]
        for b in range(bands[d], bands[d + 1]):
            first, last = starts[b], starts[b + 1]
            for t in range(first, last - 4, 4):
                p, q, r, s = _four(flat, offsets, t, base, count)
                if t == first:
                    for x in range(count):
                        band[x] = (p[x] + q[x]) + (r[x] + s[x])
                else:
                    for x in range(count):
                        band[x] += (p[x] + q[x]) + (r[x] + s[x])
            p, q, r, s = _four(flat, offsets, last - 4, base, count)
            alone, assign = last - 4 == first, b == bands[d]
            if alone and assign:
                for x in range(count):
                    total[x] = kind((p[x] + q[x]) + (r[x] + s[x]))
            elif alone:
                for x in range(count):
                    total[x] += kind((p[x] + q[x]) + (r[x] + s[x]))
            elif assign:
                for x in range(count):
                    total[x] = kind(band[x] + ((p[x] + q[x]) + (r[x] + s[x])))
            else:
                for x in range(count):
                    total[x] += kind(band[x] + ((p[x] + q[x]) + (r[x] + s[x])))


@njit(cache=True, nogil=True)
def best_products(
    light_tables,
    sat_tables,
    pad,
    runs,
    light_offsets,
    light_starts,
    light_mids,
    shared_offsets,
    corner_offsets,
    margin_offsets,
    sat_offsets,
    sat_starts,
    sat_mids,
    sat_bands,
    columns,
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
    of ``runs``; ``best`` and ``best_radius`` are written in place there (every pixel of the
    runs, whatever they held: the first radius's products are the maximum so far) and left
    as they are elsewhere.

    Parameters
    ----------
    light_tables, sat_tables : ndarray
        (2, H + 2 pad + 1, W + 2 pad + 1) from :func:`prefix_tables`: lightness (int16 or
        int32; the window sums wrap to its type) and saturation (uint16 or int32).
    pad : int
        Mirror padding of the tables.
    runs : ndarray
        int64 (N, 3): row, first column, end column (exclusive) of the pixels to compute.
    light_offsets, light_starts, light_mids : ndarray
        Flat offsets (:func:`flat_offsets`) of the terms of the ``LIGHT_WINDOWS`` staircases of
        each radius, window ``w`` of radius index ``k`` spanning
        ``light_starts[k * LIGHT_WINDOWS + w]`` to the next start, its positive terms ending at
        ``light_mids[k * LIGHT_WINDOWS + w]``.
    shared_offsets, corner_offsets, margin_offsets : ndarray
        Flat offsets of the single lightness entries the windows share: (6,) for every radius,
        (R, 14) and (R, 4) per radius (``SHARED_TERMS``, ``corner_terms`` and ``margin_terms``
        in ``conspicuity.py``); ``margin_offsets`` is None with margin 0.
    sat_offsets, sat_starts, sat_mids : ndarray
        The same as ``light_*`` for the saturation disks, window ``b`` spanning
        ``sat_starts[b:b + 2]``: one window per disk on the tables, or with ``columns`` the
        bands of the disks (offsets into the flattened ``columns``, all terms positive).
    sat_bands : ndarray
        Disk ``d`` is the sum of windows ``sat_bands[d]`` to ``sat_bands[d + 1]`` (exclusive).
    columns : ndarray
        (largest saturation radius + 2, table width) of the saturation tables' type, its last
        row zero: room for the column sums of :func:`fill_columns`, from which
        :func:`column_disks` sums the disks; or of shape (0, 0) to sum them from the tables.
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
    stairs = np.zeros((LIGHT_WINDOWS, longest), light_tables.dtype)
    sat = np.zeros((sat_bands.shape[0] - 1, longest), np.int32)
    band = np.zeros(longest, sat_tables.dtype)
    column_flat = columns.reshape(columns.size)
    plane = INTEGRAL * sat_tables.shape[1] * sat_tables.shape[2]
    contrast = np.zeros(longest, np.int64)
    disk = np.zeros(longest, np.int64)
    features = np.zeros((3, longest), np.float32)
    product = np.zeros(longest, np.float32)
    fused = not use_min and weights[0] == 1 and weights[1] == 1 and weights[2] == 1
    wrap = light_tables.dtype.type
    light_flat = light_tables.reshape(light_tables.size)
    sat_flat = sat_tables.reshape(sat_tables.size)
    for run in range(runs.shape[0]):
        i, x0, count = runs[run, 0], runs[run, 1], runs[run, 2] - runs[run, 1]
        base = (pad + 1 + i) * sat_tables.shape[2] + pad + x0
        if columns.shape[0]:
            fill_columns(sat_flat, plane, sat_tables.shape[2], pad, i, x0, count, columns)
            column_disks(
                column_flat, sat_offsets, sat_starts, sat_bands, pad + x0, count, band, sat
            )
        else:
            for d in range(sat.shape[0]):
                window_sum(
                    sat_flat,
                    sat_offsets,
                    sat_starts[d],
                    sat_mids[d],
                    sat_starts[d + 1],
                    base,
                    count,
                    sat[d],
                )
        shared = _shared_starts(shared_offsets, base)
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
                    stairs[w],
                )
            corners = _corner_starts(corner_offsets, k, base)
            margins = _margin_starts(margin_offsets, k, base)
            inner, outer = sat[sat_inner[k]], sat[sat_outer[k]]
            if fused:
                unit_max_product(
                    stairs,
                    light_flat,
                    shared,
                    corners,
                    margins,
                    inner,
                    outer,
                    n_quarter[k],
                    n_box[k],
                    scales[k],
                    radii[k],
                    count,
                    best[i, x0 : x0 + count],
                    best_radius[i, x0 : x0 + count],
                    k == 0,
                    wrap,
                    exact,
                )
                continue
            light_features(
                stairs,
                light_flat,
                shared,
                corners,
                margins,
                n_quarter[k],
                n_box[k],
                use_min,
                count,
                disk,
                contrast,
                wrap,
            )
            for x in range(count):
                features[0, x] = np.float32(disk[x]) * scales[k, 0]
                features[1, x] = np.float32(contrast[x]) * scales[k, 1]
            saturation_feature(inner, outer, scales[k, 2], scales[k, 3], count, features[2])
            weighted_product(features[0], features[1], features[2], weights, count, product)
            keep_best(
                product,
                radii[k],
                count,
                best[i, x0 : x0 + count],
                best_radius[i, x0 : x0 + count],
                k == 0,
            )
