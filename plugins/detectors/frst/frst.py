"""The fast radial symmetry transform of Loy & Zelinsky (2003), with compiled voting.

Every pixel with a strong enough gradient votes for the pixels ``n`` steps along (and against)
its gradient direction; the votes, clipped and sharpened, are smoothed and summed over radii.
Reusable: any detector may call :func:`frst` on a 2-D float map.

How it is computed: the voters (:func:`select_voters`) are listed once, in raster order. For
each radius a compiled pass (:func:`radial_strength_map`) walks them row by row and adds each
vote to a ring buffer that holds only the ``2n + 1`` rows a voter row can reach; a row whose
votes are all in (``n`` voter rows later) is turned into F_n and cleared, so the accumulators
stay in the processor's cache instead of spanning the frame. Each affected pixel receives its
votes in voter order, the order ``np.bincount`` sums in, and F_n is formed from the same
float64 values as the per-pixel NumPy expressions: the transform is the same to the last bit
as the plain array version (``tests/oracles/frst_oracle.py`` checks meaning, the tests of
``tests/detectors/test_frst.py`` check the bits against the earlier vectorised code).

Source: G. Loy and A. Zelinsky, "Fast radial symmetry for detecting points of interest",
IEEE PAMI 25(8), 2003: the definition of the transform and its refinements
(gradient threshold beta, bright/dark-only symmetry, orientation-based symmetry). That paper is
not among the project's seed documents, so the functions below name each quantity by its
symbol (O_n, M_n, F_n, A_n, S_n) instead of an equation number.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import cv2
import numpy as np
from numba import njit

#: Which affected pixels receive votes: both, positively-affected only, negatively-affected only.
MODES = ("both", "bright", "dark")
#: The signs of the affected pixels each mode votes at (p+ve is +1, p-ve is -1).
SIGNS = {"both": (1, -1), "bright": (1,), "dark": (-1,)}


@dataclass(frozen=True)
class Voters:
    """The pixels whose gradient takes part in the vote (``||g|| > beta * max ||g||``).

    In raster order: ``row`` and ``col`` are each voter's pixel, ``ux``/``uy`` its unit
    gradient, ``magnitude`` the norm ``||g(p)||``; the voters of image row ``r`` are
    ``starts[r]:starts[r + 1]``. ``shape`` is the image shape.
    """

    row: np.ndarray
    col: np.ndarray
    ux: np.ndarray
    uy: np.ndarray
    magnitude: np.ndarray
    starts: np.ndarray
    shape: tuple[int, int]


def sobel_gradient(image: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Gradient ``g(p) = (gx, gy)`` by the 3x3 Sobel filter (Loy & Zelinsky 2003).

    Computed in float64; borders are reflected without repeating the edge pixel (OpenCV's
    BORDER_REFLECT_101).
    """
    gx = cv2.Sobel(image, cv2.CV_64F, 1, 0, ksize=3, borderType=cv2.BORDER_REFLECT_101)
    gy = cv2.Sobel(image, cv2.CV_64F, 0, 1, ksize=3, borderType=cv2.BORDER_REFLECT_101)
    return gx, gy


@njit(cache=True, nogil=True)
def _list_voters(gx, gy, magnitude, limit):
    """Raster-order arrays of the pixels whose ``magnitude`` exceeds ``limit`` (and row starts)."""
    height, width = gx.shape
    row = np.empty(height * width, np.int32)
    col = np.empty(height * width, np.int32)
    ux = np.empty(height * width)
    uy = np.empty(height * width)
    mag = np.empty(height * width)
    starts = np.empty(height + 1, np.intp)
    i = 0
    for r in range(height):
        starts[r] = i
        for c in range(width):
            m = magnitude[r, c]
            if m > limit:
                row[i], col[i], mag[i] = r, c, m
                ux[i] = gx[r, c] / m
                uy[i] = gy[r, c] / m
                i += 1
    starts[height] = i
    return row[:i], col[:i], ux[:i], uy[:i], mag[:i], starts


def select_voters(gx: np.ndarray, gy: np.ndarray, beta: float) -> Voters:
    """Keep the pixels whose gradient norm exceeds ``beta`` times the largest one.

    This is Loy & Zelinsky's gradient threshold beta for ignoring small gradients, read as a
    fraction of the image's largest gradient norm; zero gradients never vote, whatever beta.
    The norm is OpenCV's ``magnitude``; the unit gradient is ``g / ||g||`` in float64.
    """
    magnitude = cv2.magnitude(gx, gy)
    limit = beta * float(magnitude.max())
    row, col, ux, uy, mag, starts = _list_voters(gx, gy, magnitude, limit)
    return Voters(row, col, ux, uy, mag, starts, (gx.shape[0], gx.shape[1]))


@njit(cache=True, nogil=True)
def cast_votes(row, col, ux, uy, magnitude, lo, hi, n, sign, slot_of, span, counts, sums, index):
    """Add the votes of voters ``lo:hi`` (all in one image row) at ``p + sign * round(u n)``.

    ``round`` is to the nearest integer with ties to even (``np.rint``). ``counts`` and
    ``sums`` are flat ring buffers of rows of ``span`` pixels: image row ``row + d`` lives in
    slot ``slot_of[d + n]``, column ``x`` at ``x + n``. Each affected pixel gains 1 and
    ``||g(p)||`` per voter, in voter order (so the sums are those ``np.bincount`` gives); O_n
    and M_n are ``sign`` times these. ``index`` is scratch space for the row's targets.
    """
    for i in range(lo, hi):
        dy = sign * np.intp(np.rint(uy[i] * n))
        dx = sign * np.intp(np.rint(ux[i] * n))
        index[i - lo] = slot_of[dy + n] * span + col[i] + dx + n
    for i in range(hi - lo):
        counts[index[i]] += 1
    for i in range(hi - lo):
        sums[index[i]] += magnitude[lo + i]


@njit(cache=True, nogil=True)
def emit_row(counts, sums, signs, start, table, signed, out):
    """F_n of one image row from its ring-buffer row (flat offset ``start``), into ``out``.

    Per pixel ``O_n = counts(+) - counts(-)`` and ``M_n = sums(+) + (-sums(-))``, as NumPy adds
    the signed parts; F_n is ``table[min(|O_n|, len(table) - 1)]`` times ``M_n``
    (:func:`radial_strength`) or, when ``signed``, times ``sign(O_n)``
    (:func:`orientation_strength`), rounded to float32 once.
    """
    top = table.shape[0] - 1
    if signs.shape[0] == 1:  # the common case, one polarity: a loop without branches
        c, s, sign = counts[0], sums[0], signs[0]
        for x in range(out.shape[0]):
            level = table[min(c[start + x], top)]
            if signed:
                out[x] = np.float32(sign * np.sign(c[start + x]) * level)
            else:
                out[x] = np.float32(level * (sign * s[start + x]))
        return
    for x in range(out.shape[0]):
        orientation = counts[0, start + x] - counts[1, start + x]
        projection = sums[0, start + x] + -sums[1, start + x]
        level = table[min(abs(orientation), top)]
        out[x] = np.float32(np.sign(orientation) * level if signed else level * projection)


@njit(cache=True, nogil=True)
def radial_strength_map(row, col, ux, uy, magnitude, starts, n, signs, table, signed, out):
    """F_n of every image pixel into ``out`` (float32, the image shape), for radius ``n``.

    ``signs`` holds the affected pixels voted at (+1: p+ve, -1: p-ve; both: ``(1, -1)``).
    Voter rows are cast in order (:func:`cast_votes`) into a ring of ``2n + 1`` rows; image row
    ``y`` is complete once voter row ``y + n`` is in, and is then emitted (:func:`emit_row`)
    and cleared.
    """
    height, width = out.shape
    slots = 2 * n + 1
    span = width + 2 * n
    counts = np.zeros((signs.shape[0], slots * span), np.int32)
    sums = np.zeros((signs.shape[0], slots * span))
    longest = 1
    for r in range(height):
        longest = max(longest, starts[r + 1] - starts[r])
    index = np.empty(longest, np.intp)
    slot_of = np.empty(slots, np.intp)
    for step in range(height + 2 * n):
        if step < height:
            for d in range(-n, n + 1):
                slot_of[d + n] = (step + d) % slots
            for k in range(signs.shape[0]):
                lo, hi = starts[step], starts[step + 1]
                cast_votes(
                    row, col, ux, uy, magnitude, lo, hi, n, signs[k], slot_of, span,
                    counts[k], sums[k], index,
                )  # fmt: skip
        done = step - n  # no voter row after ``step`` reaches image row ``done``
        start = (done % slots) * span
        if 0 <= done < height:
            emit_row(counts, sums, signs, start + n, table, signed, out[done])
        counts[:, start : start + span] = 0
        sums[:, start : start + span] = 0.0


def kappa(n: int) -> float:
    """The normalising factor k_n: 8 for n = 1, 9.9 otherwise (Loy & Zelinsky 2003)."""
    return 8.0 if n == 1 else 9.9


def strength_levels(k: float, alpha: float, magnitude: bool) -> np.ndarray:
    """F_n per clipped vote count ``|O~_n|`` = 0, 1, ..., ceil(k_n).

    With ``magnitude``: ``(|O~_n| / k_n) ** alpha / k_n``, the factor of M_n in
    F_n = (M_n / k_n) (|O~_n| / k_n) ** alpha; else ``(|O~_n| / k_n) ** alpha``, the
    orientation-based F_n up to its sign. O_n holds integer counts, so these values are all
    F_n needs: computed once and looked up, they are the numbers the power gives per pixel.
    """
    levels = np.arange(math.ceil(k) + 1)
    table = (np.minimum(levels, k) / k) ** alpha
    return table / k if magnitude else table


def radial_strength(
    magnitude: np.ndarray, orientation: np.ndarray, k: float, alpha: float
) -> np.ndarray:
    """F_n = (M_n / k_n) * (|O~_n| / k_n) ** alpha, with O~_n = O_n clipped to ``[-k_n, k_n]``.

    Array version of what :func:`radial_strength_map` computes per pixel.
    """
    table = strength_levels(k, alpha, magnitude=True)
    counts = np.minimum(np.abs(orientation), len(table) - 1)
    return np.take(table, counts) * magnitude


def orientation_strength(orientation: np.ndarray, k: float, alpha: float) -> np.ndarray:
    """Orientation-based F_n = sign(O~_n) (|O~_n| / k_n) ** alpha (no magnitude projection).

    The orientation-based variant Loy & Zelinsky describe: gradient magnitude is ignored, so the
    result does not change when the image contrast is scaled.
    """
    table = strength_levels(k, alpha, magnitude=False)
    counts = np.minimum(np.abs(orientation), len(table) - 1)
    return np.sign(orientation) * np.take(table, counts)


def gaussian_kernel(n: int) -> np.ndarray:
    """The 1-D factor of A_n: normalised Gaussian, sigma = 0.25 n, half-width ceil(3 sigma)."""
    sigma = 0.25 * n
    return cv2.getGaussianKernel(2 * math.ceil(3 * sigma) + 1, sigma, cv2.CV_64F)


def spread(strength: np.ndarray, n: int) -> np.ndarray:
    """S_n = F_n * A_n: separable Gaussian smoothing of float32 F_n, zero outside the image."""
    kernel = gaussian_kernel(n).astype(np.float32)
    return cv2.sepFilter2D(strength, cv2.CV_32F, kernel, kernel, borderType=cv2.BORDER_CONSTANT)


def check_frst_args(
    image: np.ndarray, radii: Sequence[int], alpha: float, beta: float, mode: str
) -> None:
    """Raise ValueError naming the first argument :func:`frst` cannot use."""
    if image.ndim != 2 or 0 in image.shape:
        raise ValueError(f"frst needs a non-empty 2-D image; got shape {image.shape}")
    if not len(radii) or any(int(n) != n or n < 1 for n in radii):
        raise ValueError(f"frst radii must be positive integers; got {list(radii)}")
    if alpha <= 0:
        raise ValueError(f"frst alpha must be positive; got {alpha}")
    if not 0 <= beta < 1:
        raise ValueError(f"frst beta must be in [0, 1); got {beta}")
    if mode not in MODES:
        raise ValueError(f"frst mode must be one of {', '.join(MODES)}; got {mode!r}")


def frst(
    image: np.ndarray,
    radii: Sequence[int] = tuple(range(1, 11)),
    alpha: float = 2.0,
    beta: float = 0.0,
    mode: str = "both",
    orientation_only: bool = False,
) -> np.ndarray:
    """Fast radial symmetry transform S = sum over n of S_n.

    Parameters
    ----------
    image : ndarray, 2-D
        Any real-valued map (converted to float32).
    radii : sequence of int
        The radii n (pixels).
    alpha : float
        Radial strictness.
    beta : float
        Gradient threshold, as a fraction of the largest gradient norm, in [0, 1).
    mode : {"both", "bright", "dark"}
        Vote at both affected pixels, or only at p+ve (bright symmetry, positive S) or only at
        p-ve (dark symmetry, negative S).
    orientation_only : bool
        Use the orientation-based F_n instead of the magnitude-weighted one.

    Returns
    -------
    ndarray, float32, same shape
        Positive at centres of bright radial symmetry, negative at dark ones. Loy & Zelinsky
        average S_n over the radii; the sum used here (Zheng 5.2.2's reading) differs only by
        the factor 1/len(radii).

    Examples
    --------
    >>> yy, xx = np.mgrid[:31, :31]
    >>> disc = ((yy - 15) ** 2 + (xx - 15) ** 2 <= 25).astype(np.float32)
    >>> s = frst(disc, radii=[5])
    >>> tuple(int(i) for i in np.unravel_index(np.argmax(s), s.shape))
    (15, 15)
    """
    image = np.asarray(image, dtype=np.float32)
    check_frst_args(image, radii, alpha, beta, mode)
    voters = select_voters(*sobel_gradient(image), beta)
    signs = np.array(SIGNS[mode], np.intp)
    total = np.zeros(image.shape, np.float32)
    strength = np.empty(image.shape, np.float32)
    for n in (int(n) for n in radii):
        table = strength_levels(kappa(n), alpha, magnitude=not orientation_only)
        radial_strength_map(
            voters.row,
            voters.col,
            voters.ux,
            voters.uy,
            voters.magnitude,
            voters.starts,
            n,
            signs,
            table,
            orientation_only,
            strength,
        )
        total += spread(strength, n)
    return total
