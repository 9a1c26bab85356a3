"""The fast radial symmetry transform of Loy & Zelinsky (2003), vectorised with NumPy and OpenCV.

Every pixel with a strong enough gradient votes for the pixels ``n`` steps along (and against)
its gradient direction; the votes, clipped and sharpened, are smoothed and summed over radii.
Reusable: any detector may call :func:`frst` on a 2-D float map. The votes are cast by a
compiled loop (:func:`cast_votes`) that finds each affected pixel and adds to it in one pass, with
no per-radius index arrays; it sums in the order ``np.bincount`` does, so the transform is the
same to the last bit.

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
from functools import reduce

import cv2
import numpy as np
from numba import njit

#: Which affected pixels receive votes: both, positively-affected only, negatively-affected only.
MODES = ("both", "bright", "dark")


@dataclass(frozen=True)
class Voters:
    """The pixels whose gradient takes part in the vote (``||g|| > beta * max ||g||``).

    Votes are cast on a working grid that pads the image by ``pad`` pixels on every side, so
    that a vote leaving the image needs no bounds check: it lands in the margin, which is cut
    away afterwards. ``index`` is each voter's flat index on that grid, ``ux``/``uy`` its unit
    gradient, ``magnitude`` the norm ``||g(p)||``; ``shape`` is the image shape.
    """

    index: np.ndarray
    ux: np.ndarray
    uy: np.ndarray
    magnitude: np.ndarray
    shape: tuple[int, int]
    pad: int

    @property
    def grid(self) -> tuple[int, int]:
        """Shape of the padded working grid."""
        return self.shape[0] + 2 * self.pad, self.shape[1] + 2 * self.pad

    def crop(self, flat: np.ndarray) -> np.ndarray:
        """The image part of a flat array over the working grid, as a 2-D view."""
        height, width = self.shape
        return flat.reshape(self.grid)[self.pad : self.pad + height, self.pad : self.pad + width]


def sobel_gradient(image: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Gradient ``g(p) = (gx, gy)`` by the 3x3 Sobel filter (Loy & Zelinsky 2003).

    Computed in float64; borders are reflected without repeating the edge pixel (OpenCV's
    BORDER_REFLECT_101).
    """
    gx = cv2.Sobel(image, cv2.CV_64F, 1, 0, ksize=3, borderType=cv2.BORDER_REFLECT_101)
    gy = cv2.Sobel(image, cv2.CV_64F, 0, 1, ksize=3, borderType=cv2.BORDER_REFLECT_101)
    return gx, gy


def select_voters(gx: np.ndarray, gy: np.ndarray, beta: float, pad: int) -> Voters:
    """Keep the pixels whose gradient norm exceeds ``beta`` times the largest one.

    This is Loy & Zelinsky's gradient threshold beta for ignoring small gradients, read as a
    fraction of the image's largest gradient norm; zero gradients never vote, whatever beta.
    ``pad`` must be at least the largest radius. The gradients are zero-padded to the working
    grid first, so the selected flat indices are already grid indices.
    """
    shape = gx.shape
    gx = cv2.copyMakeBorder(gx, pad, pad, pad, pad, cv2.BORDER_CONSTANT).ravel()
    gy = cv2.copyMakeBorder(gy, pad, pad, pad, pad, cv2.BORDER_CONSTANT).ravel()
    magnitude = cv2.magnitude(gx, gy).ravel()
    index = np.flatnonzero(magnitude > beta * float(magnitude.max()))
    mag = magnitude[index]
    return Voters(index, gx[index] / mag, gy[index] / mag, mag, shape, pad)


@njit(cache=True, nogil=True)
def cast_votes(index, ux, uy, magnitude, n, width, sign, counts, sums):
    """Add one vote per voter at its affected pixel ``p +- round(g(p)/||g(p)|| * n)``.

    ``sign=+1`` votes at the positively-affected pixels p+ve, ``-1`` at the negatively-affected
    p-ve; ``round`` is to the nearest integer with ties to even (``np.rint``). ``counts[q]``
    gains 1 and ``sums[q]`` gains ``||g(p)||`` for every voter whose affected pixel is the flat
    grid index ``q`` (several voters hitting one pixel all count), in voter order, so the sums
    are those ``np.bincount`` would give. O_n and M_n are ``sign`` times these.
    """
    for i in range(index.shape[0]):
        step = np.rint(uy[i] * n) * width + np.rint(ux[i] * n)
        target = index[i] + sign * np.intp(step)
        counts[target] += 1
        sums[target] += magnitude[i]


def kappa(n: int) -> float:
    """The normalising factor k_n: 8 for n = 1, 9.9 otherwise (Loy & Zelinsky 2003)."""
    return 8.0 if n == 1 else 9.9


def clipped_orientation(orientation: np.ndarray, k: float) -> np.ndarray:
    """O~_n: O_n where ``|O_n| < k_n``, else ``k_n * sign(O_n)``."""
    return np.sign(orientation) * np.minimum(np.abs(orientation), k)


def radial_strength(
    magnitude: np.ndarray, orientation: np.ndarray, k: float, alpha: float
) -> np.ndarray:
    """F_n = (M_n / k_n) * (|O~_n| / k_n) ** alpha.

    O_n holds integer vote counts, so ``(|O~_n| / k_n) ** alpha / k_n`` takes at most
    ``ceil(k_n) + 1`` values: they are computed once and looked up, which gives the same numbers
    as the power.
    """
    levels = np.arange(math.ceil(k) + 1)
    table = (np.minimum(levels, k) / k) ** alpha / k
    counts = np.abs(orientation)
    np.minimum(counts, levels[-1], out=counts)
    strength = np.take(table, counts)
    strength *= magnitude
    return strength


def orientation_strength(orientation: np.ndarray, k: float, alpha: float) -> np.ndarray:
    """Orientation-based F_n = sign(O~_n) (|O~_n| / k_n) ** alpha (no magnitude projection).

    The orientation-based variant Loy & Zelinsky describe: gradient magnitude is ignored, so the
    result does not change when the image contrast is scaled.
    """
    clipped = clipped_orientation(orientation, k)
    return np.sign(clipped) * (np.abs(clipped) / k) ** alpha


def gaussian_kernel(n: int) -> np.ndarray:
    """The 1-D factor of A_n: normalised Gaussian, sigma = 0.25 n, half-width ceil(3 sigma)."""
    sigma = 0.25 * n
    return cv2.getGaussianKernel(2 * math.ceil(3 * sigma) + 1, sigma, cv2.CV_64F)


def spread(strength: np.ndarray, n: int) -> np.ndarray:
    """S_n = F_n * A_n: separable Gaussian smoothing, zero outside the image."""
    kernel = gaussian_kernel(n).astype(np.float32)
    return cv2.sepFilter2D(
        strength.astype(np.float32), cv2.CV_32F, kernel, kernel, borderType=cv2.BORDER_CONSTANT
    )


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
    voters = select_voters(*sobel_gradient(image), beta, max(radii))
    signs = {"both": (1, -1), "bright": (1,), "dark": (-1,)}[mode]
    total = np.zeros(image.shape, np.float32)
    for n in radii:
        orientation, magnitude = projections(voters, int(n), signs)
        k = kappa(int(n))
        strength = (
            orientation_strength(orientation, k, alpha)
            if orientation_only
            else radial_strength(magnitude, orientation, k, alpha)
        )
        total += spread(voters.crop(strength), int(n))
    return total


def projections(voters: Voters, n: int, signs: Sequence[int]) -> tuple[np.ndarray, np.ndarray]:
    """O_n and M_n (flat, working grid) for radius ``n``, voting at the pixels of ``signs``."""
    size = voters.grid[0] * voters.grid[1]
    parts = []
    for sign in signs:
        counts, sums = np.zeros(size, np.int64), np.zeros(size)
        cast_votes(
            voters.index,
            voters.ux,
            voters.uy,
            voters.magnitude,
            n,
            voters.grid[1],
            sign,
            counts,
            sums,
        )
        parts.append((counts, sums) if sign > 0 else (np.negative(counts), np.negative(sums)))
    return reduce(np.add, (o for o, _ in parts)), reduce(np.add, (m for _, m in parts))
