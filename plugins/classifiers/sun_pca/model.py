"""Lee's Sun-compensated colour model (2017, 4.3): per target colour, a line in RGB found by PCA
of labelled pixels, the colour along it as a function of the relative azimuth of the Sun, and the
two spreads that turn a pixel's distances into a probability.

For each target and each regime (the body reflection before the red channel saturates, and the
surface reflection after it; Figure 4.7 fits one line to each):

* ``mean`` and ``axis``: the centre and the first eigenvector of the pixels' RGB (PCA);
* ``coef``: the regression ``s(alpha) = a + b max(0, cos(alpha))`` of the position ``s`` along the
  axis on the relative azimuth ``alpha`` (Eq. 4.9: the direct light varies with the cosine of the
  angle; beyond 90 degrees only sky light is left, so the cosine is clamped at 0, where Lee
  fitted only the angles below 90 degrees);
* ``offset``, ``v_a`` and ``v_d``, per 30-degree bin of ``alpha``: beyond 90 degrees, where no
  direct light is left for the cosine law to describe, the bin's mean departure from
  ``s(alpha)`` (sky light, glare when facing the Sun; 0 below 90 degrees); the spread along the
  axis about that, and the root mean square distance to the axis (Lee's v_a and v_d).

A pixel ``c`` projects to ``c_bar`` on the axis; ``e_d = d(c, c_bar)`` and ``e_a = d(c_t, c_bar)``
with ``c_t`` the target colour at the frame's ``alpha`` (``s(alpha)`` plus its bin's offset); its
probability is
``exp(-(e_a / v_a)^2 / 2 - (e_d / v_d)^2 / 2)``. Without ``alpha`` (no Sun facts) the model falls
back to its uncompensated form: the target is the pixels' mean and the spreads are pooled over
every angle (``v_a0``, ``v_d0``).
"""

from __future__ import annotations

import numpy as np

#: Bin edges of the relative azimuth, degrees (Lee's 30-degree steps of 4.2).
BIN_EDGES = np.arange(0.0, 181.0, 30.0)
REGIMES = ("body", "surface")
#: Fewest pixels for a regime's line, and for a bin's own spreads.
MIN_PIXELS = 30
MIN_BIN_PIXELS = 20
#: Added to every spread, in grey levels: sensor noise and quantisation, so none is ever zero.
SPREAD_FLOOR = 3.0


def lit_share(alpha) -> np.ndarray:
    """``max(0, cos(alpha))``: the share of the Sun's direct light a target facing the camera
    receives at relative azimuth ``alpha`` degrees (Eq. 4.9's cosine; a face turned from the Sun
    gets none, which is why Lee fits only angles below 90 degrees, Figure 4.7)."""
    return np.maximum(np.cos(np.radians(alpha)), 0.0)


def azimuth_bin(alpha: float) -> int:
    """Index of the 30-degree bin holding ``alpha`` (180 falls in the last)."""
    index = int(np.searchsorted(BIN_EDGES, alpha, side="right")) - 1
    return min(index, len(BIN_EDGES) - 2)


def regime_of(pixels: np.ndarray, saturation: float) -> np.ndarray:
    """1 (surface) where the red channel (BGR index 2) reached ``saturation``, else 0 (body)."""
    return (pixels[..., 2] >= saturation).astype(np.int64)


def fit_line(pixels: np.ndarray, alpha: np.ndarray) -> dict[str, np.ndarray]:
    """One regime's line: PCA axis, cosine regression and spreads (see the module notes).

    ``alpha`` holds each pixel's relative azimuth in degrees, NaN where unknown; the regression
    needs known angles in at least two bins, else ``b = 0`` (the uncompensated form).
    """
    mean = pixels.mean(axis=0)
    from sklearn.decomposition import PCA

    axis = PCA(n_components=1, svd_solver="full").fit(pixels).components_[0]
    axis = axis if axis.sum() >= 0 else -axis  # positive: towards brighter
    s = (pixels - mean) @ axis
    d = np.linalg.norm(pixels - mean - s[:, None] * axis, axis=1)
    known = np.isfinite(alpha)
    bins = np.array([azimuth_bin(a) for a in alpha[known]], np.int64)
    coef = np.zeros(2)
    if len(np.unique(bins)) >= 2:
        design = np.column_stack([np.ones(known.sum()), lit_share(alpha[known])])
        coef = np.linalg.lstsq(design, s[known], rcond=None)[0]
    v_a0, v_d0 = float(s.std()) + SPREAD_FLOOR, float(np.sqrt(np.mean(d * d))) + SPREAD_FLOOR
    v_a = np.full(len(BIN_EDGES) - 1, v_a0)
    v_d = np.full(len(BIN_EDGES) - 1, v_d0)
    offset = np.zeros(len(BIN_EDGES) - 1)
    if coef[1] != 0.0:
        residual = s[known] - (coef[0] + coef[1] * lit_share(alpha[known]))
        for k in range(len(v_a)):
            inside = bins == k
            if inside.sum() >= MIN_BIN_PIXELS:
                if BIN_EDGES[k] >= 90.0:  # no direct light: the bin's own mean colour
                    offset[k] = float(residual[inside].mean())
                v_a[k] = float(residual[inside].std()) + SPREAD_FLOOR
                v_d[k] = float(np.sqrt(np.mean(d[known][inside] ** 2))) + SPREAD_FLOOR
    return {"mean": mean, "axis": axis, "coef": coef, "offset": offset, "v_a": v_a, "v_d": v_d,
            "v_a0": np.array(v_a0), "v_d0": np.array(v_d0)}  # fmt: skip


def fit_target(pixels: np.ndarray, alpha: np.ndarray, saturation: float) -> dict[str, np.ndarray]:
    """Both regimes' lines of one target, stacked (regime first); a regime with fewer than
    :data:`MIN_PIXELS` pixels borrows the other's line.

    Raises
    ------
    ValueError
        When the target has fewer than :data:`MIN_PIXELS` pixels in all.
    """
    if len(pixels) < MIN_PIXELS:
        raise ValueError(f"{len(pixels)} pixels; at least {MIN_PIXELS} are needed")
    regime = regime_of(pixels, saturation)
    lines = [
        fit_line(pixels[regime == r], alpha[regime == r])
        if (regime == r).sum() >= MIN_PIXELS
        else None
        for r in range(len(REGIMES))
    ]
    fallback = next(line for line in lines if line is not None)
    filled = [line if line is not None else fallback for line in lines]
    return {key: np.stack([line[key] for line in filled]) for key in fallback}


def probability(
    pixels: np.ndarray, target: dict[str, np.ndarray], alpha: float | None, saturation: float
) -> np.ndarray:
    """The target probability of every pixel (any leading shape, BGR last), at relative azimuth
    ``alpha`` in degrees or uncompensated when None (see the module notes)."""
    flat = pixels.reshape(-1, 3).astype(np.float64)
    regime = regime_of(flat, saturation)
    mean, axis = target["mean"][regime], target["axis"][regime]
    s = np.einsum("ij,ij->i", flat - mean, axis)
    e_d = np.linalg.norm(flat - mean - s[:, None] * axis, axis=1)
    if alpha is None or not np.any(target["coef"][:, 1]):
        s_t, v_a, v_d = 0.0, target["v_a0"][regime], target["v_d0"][regime]
    else:
        k = azimuth_bin(alpha)
        coef = target["coef"][regime]
        s_t = coef[:, 0] + coef[:, 1] * lit_share(alpha) + target["offset"][regime, k]
        v_a, v_d = target["v_a"][regime, k], target["v_d"][regime, k]
    e_a = np.abs(s - s_t)
    p = np.exp(-0.5 * (e_a / v_a) ** 2 - 0.5 * (e_d / v_d) ** 2)
    return p.reshape(pixels.shape[:-1])
