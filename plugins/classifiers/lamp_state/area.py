"""OpenCV's area decimation (``cv2.resize`` with ``cv2.INTER_AREA``, both sides shrinking) of
8-bit, 3-channel crops, compiled: many small crops of a frame in one call, without a call into
OpenCV per crop, to the bit.

The arithmetic is OpenCV's own (``modules/imgproc/src/resize.cpp``), step for step:

* a non-integer scale (``resizeArea_``): per output column the source columns it covers with
  their float32 weights (``computeResizeAreaTab``), each source row's products added into a
  float32 row buffer column by column in source order, the row buffers weighted and added per
  output row, the sum rounded to the nearest integer (ties to even);
* integer scales on both sides (``resizeAreaFast_``): the block's integer sum, ``(sum + 2) >> 2``
  for 2 x 2 blocks (OpenCV's vector path and its scalar tail), else ``sum * (1 / area)`` in
  float32, rounded; a block cut by the far edge (never read here) is ``sum / count``.

Enlarging crops (OpenCV's area rule is then a fixed-point linear one) are not handled here: the
callers resample them with OpenCV. ``tests/test_lamp_state.py`` compares these with OpenCV at
every crop length up to a frame's width.
"""

from __future__ import annotations

import numpy as np
from numba import njit

#: OpenCV's tolerance for an integer scale (``DBL_EPSILON``).
EPSILON = float(np.finfo(np.float64).eps)


@njit(cache=True, nogil=True)
def area_table(source: int, target: int, scale: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """OpenCV's ``computeResizeAreaTab``: for ``source`` pixels resampled to ``target`` at
    ``scale`` source pixels per output pixel, the entries (output index, source index, float32
    weight), output after output."""
    out = np.empty(2 * source + 2, np.int64)
    src = np.empty(2 * source + 2, np.int64)
    weight = np.empty(2 * source + 2, np.float32)
    k = 0
    for d in range(target):
        fs1 = d * scale
        fs2 = fs1 + scale
        cell = min(scale, source - fs1)
        s2 = min(int(np.floor(fs2)), source - 1)
        s1 = min(int(np.ceil(fs1)), s2)
        if s1 - fs1 > 1e-3:
            out[k], src[k], weight[k] = d, s1 - 1, np.float32((s1 - fs1) / cell)
            k += 1
        for s in range(s1, s2):
            out[k], src[k], weight[k] = d, s, np.float32(1.0 / cell)
            k += 1
        if fs2 - s2 > 1e-3:
            out[k], src[k] = d, s2
            weight[k] = np.float32(min(min(fs2 - s2, 1.0), cell) / cell)
            k += 1
    return out[:k], src[:k], weight[:k]


@njit(cache=True, nogil=True)
def saturate(value: np.float32) -> np.uint8:
    """OpenCV's ``saturate_cast<uchar>`` of a float: rounded, ties to even, clipped to 0-255."""
    return np.uint8(min(max(np.rint(value), 0.0), 255.0))


@njit(cache=True, nogil=True, inline="always")
def halved(src: np.ndarray, y: int, x: int, kx: int, ky: int, c: int) -> np.float32:
    """Channel ``c`` of the pixel at (``y``, ``x``) of ``src`` averaged over its ``kx`` x ``ky``
    block (1 or 2 a side) as OpenCV's ``resizeAreaFast_`` averages a whole block: ``(sum + 2)
    >> 2`` for 2 x 2 (its vector path and its scalar tail), else ``sum * (1 / area)`` rounded
    (ties to even); the pixel itself for 1 x 1."""
    if kx == 1 and ky == 1:
        return np.float32(src[y, x, c])
    total = np.int32(src[y, x, c])
    if kx == 2:
        total += np.int32(src[y, x + 1, c])
    if ky == 2:
        total += np.int32(src[y + 1, x, c])
        if kx == 2:
            return np.float32((total + np.int32(src[y + 1, x + 1, c]) + 2) >> 2)
    return np.rint(np.float32(total) * np.float32(0.5))


@njit(cache=True, nogil=True)
def decimate_general(
    src: np.ndarray,
    window: tuple[int, int, int, int],
    halve: tuple[int, int],
    size: tuple[int, int],
    scale: tuple[float, float],
    corner: tuple[int, int],
    dst: np.ndarray,
) -> None:
    """OpenCV's ``resizeArea_`` to ``size`` = (width, height) at ``scale`` = (x, y) source
    pixels per output pixel of a crop of ``src`` (H, W, 3): the crop from (top, left) of
    ``window`` = (top, left, height, width), halved by ``halve`` = (x, y) factors of 1 or 2
    (:func:`halved`: OpenCV's halving, fused here) to ``height`` x ``width``. The
    ``dst.shape[:2]`` output pixels from the row and column ``corner`` go into ``dst`` (an
    output pixel depends on its own cells alone: only theirs are read). A cell's products are
    added in a register, in OpenCV's order (the same float32 sums as its row buffer's)."""
    rows, cols = dst.shape[0], dst.shape[1]
    top, left, height, width = window
    kx, ky = halve
    x_out, x_src, x_weight = area_table(width, size[0], scale[0])
    y_out, y_src, y_weight = area_table(height, size[1], scale[1])
    first = np.searchsorted(y_out, corner[0])
    if rows == 0 or cols == 0 or first == len(y_out):
        return
    row = np.zeros((cols, 3), np.float32)
    total = np.zeros((cols, 3), np.float32)
    previous = y_out[first] - corner[0]
    start = np.searchsorted(x_out, corner[1])
    for j in range(first, len(y_out)):
        out = y_out[j] - corner[0]
        if out >= rows:
            break
        y = top + ky * y_src[j]
        k = start
        for d in range(cols):
            b, g, r = np.float32(0.0), np.float32(0.0), np.float32(0.0)
            while k < len(x_out) and x_out[k] - corner[1] == d:
                x, weight = left + kx * x_src[k], x_weight[k]
                b += halved(src, y, x, kx, ky, 0) * weight
                g += halved(src, y, x, kx, ky, 1) * weight
                r += halved(src, y, x, kx, ky, 2) * weight
                k += 1
            row[d, 0], row[d, 1], row[d, 2] = b, g, r
        if out != previous:
            for d in range(cols):
                for c in range(3):
                    dst[previous, d, c] = saturate(total[d, c])
                    total[d, c] = y_weight[j] * row[d, c]
            previous = out
        else:
            for d in range(cols):
                for c in range(3):
                    total[d, c] += y_weight[j] * row[d, c]
    for d in range(cols):
        for c in range(3):
            dst[previous, d, c] = saturate(total[d, c])


@njit(cache=True, nogil=True)
def decimate_blocks(
    src: np.ndarray,
    window: tuple[int, int, int, int],
    factors: tuple[int, int],
    corner: tuple[int, int],
    dst: np.ndarray,
) -> None:
    """OpenCV's ``resizeAreaFast_`` of the ``window`` (top, left, height, width) of ``src`` by
    the integer ``factors`` (x, y): the ``dst.shape[:2]`` output pixels from the row and
    column ``corner`` into ``dst``."""
    top, left, height, width = window
    kx, ky = factors
    inverse = np.float32(1.0) / np.float32(kx * ky)
    for dy in range(dst.shape[0]):
        y0 = (corner[0] + dy) * ky
        for dx in range(dst.shape[1]):
            x0 = (corner[1] + dx) * kx
            cut = y0 + ky > height or x0 + kx > width // kx * kx  # by the far edge
            for c in range(3):
                if not cut and kx <= 2 and ky <= 2:
                    dst[dy, dx, c] = np.uint8(halved(src, top + y0, left + x0, kx, ky, c))
                    continue
                total = 0
                count = 0
                for y in range(y0, min(y0 + ky, height)):
                    for x in range(x0, min(x0 + kx, width)):
                        total += np.int64(src[top + y, left + x, c])
                        count += 1
                if cut:
                    dst[dy, dx, c] = saturate(np.float32(total) / np.float32(count))
                else:
                    dst[dy, dx, c] = saturate(np.float32(total) * inverse)


@njit(cache=True, nogil=True)
def whole_scales(scale: tuple[float, float]) -> bool:
    """Whether OpenCV takes its integer path for ``scale`` (x, y): both whole numbers."""
    x, y = scale
    return abs(x - np.rint(x)) < EPSILON and abs(y - np.rint(y)) < EPSILON


@njit(cache=True, nogil=True)
def decimate(
    src: np.ndarray,
    window: tuple[int, int, int, int],
    size: tuple[int, int],
    scale: tuple[float, float],
    corner: tuple[int, int],
    dst: np.ndarray,
) -> None:
    """The ``dst.shape[:2]`` pixels from the row and column ``corner`` of ``cv2.resize`` of
    the ``window`` (top, left, height, width) of ``src`` (H, W, 3) to ``size`` = (width,
    height), both shrinking, at ``scale`` = (x, y) source pixels per output pixel (OpenCV's
    ``1 / inv_scale``), into ``dst``: the integer path when both scales are whole numbers,
    else the general one; an output the size of the window is the window."""
    top, left, height, width = window
    if size[0] == width and size[1] == height:
        y, x = top + corner[0], left + corner[1]
        dst[:] = src[y : y + dst.shape[0], x : x + dst.shape[1]]
    elif whole_scales(scale):
        decimate_blocks(src, window, (int(np.rint(scale[0])), int(np.rint(scale[1]))), corner, dst)
    else:
        decimate_general(src, window, (1, 1), size, scale, corner, dst)
