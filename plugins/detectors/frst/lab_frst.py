"""LAB-FRST: Siogkas et al.'s lens detector as Zheng re-implemented it for comparison.

The CIELab feature map L*(a+b) makes red lenses bright and green lenses dark; the fast radial
symmetry transform of each part picks round spots, and the five strongest of each become
candidates hinted red (bright) or green (dark). Source: Zheng 2016, section 5.2.2.
"""

from __future__ import annotations

import cv2
import numpy as np

from tsrkit.api import Candidate, Detector, Frame, Param, hookimpl
from tsrkit_plugins.detectors.frst.frst import frst


def lab_feature_map(image: np.ndarray) -> np.ndarray:
    """Siogkas's feature map L * (a + b) of a BGR uint8 image (Zheng 5.2.2).

    Scaling: OpenCV's 8-bit CIELab conversion gives ``L8 = 255 L/100`` and ``a8 = a + 128``,
    ``b8 = b + 128``; we use ``L = L8 / 255`` in [0, 1] and ``a = (a8 - 128) / 128``,
    ``b = (b8 - 128) / 128`` in [-1, 1), so the map lies in [-2, 2). Red and yellow light is
    positive, green (and blue) light negative, grey and dark pixels near zero.
    """
    check_bgr(image)
    return feature_from_lab(cv2.cvtColor(image, cv2.COLOR_BGR2Lab))


def check_bgr(image: np.ndarray) -> None:
    """Raise ValueError unless ``image`` is BGR uint8."""
    if image.ndim != 3 or image.shape[2] != 3 or image.dtype != np.uint8:
        raise ValueError(f"lab-frst needs a BGR uint8 image; got {image.dtype} {image.shape}")


def feature_from_lab(lab: np.ndarray) -> np.ndarray:
    """:func:`lab_feature_map` from OpenCV's 8-bit CIELab image."""
    lightness = lab[..., 0].astype(np.float32)
    chroma = lab[..., 1].astype(np.float32) + lab[..., 2] - 256.0
    return lightness * chroma * np.float32(1.0 / (255.0 * 128.0))


def frame_feature_map(frame: Frame) -> np.ndarray:
    """:func:`lab_feature_map` of a frame, computed once for all its detectors (its views:
    the CIELab conversion and the map are shared; read-only)."""
    check_bgr(frame.image)
    views = frame.views
    return views.map("L*(a+b)", lambda image: feature_from_lab(views.colour(cv2.COLOR_BGR2Lab)))


def symmetry_maps(
    feature: np.ndarray, radii, alpha: float, beta: float, orientation_only: bool
) -> tuple[np.ndarray, np.ndarray]:
    """Bright-spot map of the positive part and dark-spot map of the negative part.

    Zheng 5.2.2: "the positive and negative parts of the CIELab based feature map are transformed
    separately". We read this as the FRST of ``max(F, 0)`` voting only at positively-affected
    pixels (bright symmetry) and of ``min(F, 0)`` voting only at negatively-affected pixels (dark
    symmetry, sign flipped so that both maps are positive at their spots).
    """
    bright = frst(np.maximum(feature, 0), radii, alpha, beta, "bright", orientation_only)
    dark = frst(np.minimum(feature, 0), radii, alpha, beta, "dark", orientation_only)
    return bright, -dark


def spot_candidates(symmetry: np.ndarray, fraction: float, top: int, state: str) -> list[Candidate]:
    """The ``top`` strongest 8-connected spots of ``symmetry >= fraction * max`` (Zheng 5.2.2).

    Components are labelled inside the bounding box of the above-threshold pixels only (the
    rest of the map is background). Each spot becomes a candidate at its centroid, in
    continuous coordinates (pixel ``(i, j)`` covers ``[j, j+1) x [i, i+1)``, so its centre is
    ``(j + 0.5, i + 0.5)``), with half the longer side of its bounding box as radius and its
    peak symmetry value as score. The radius is the size of the half-maximum spot, as Zheng
    describes, and is usually smaller than the lens.
    """
    peak = float(symmetry.max())
    if peak <= 0:
        return []
    rows, cols = np.nonzero(symmetry >= fraction * peak)
    top_row, left = rows.min(), cols.min()
    window = symmetry[top_row : rows.max() + 1, left : cols.max() + 1]
    mask = (window >= fraction * peak).astype(np.uint8)
    count, labels, stats, centroids = cv2.connectedComponentsWithStats(mask, connectivity=8)
    on = labels > 0
    scores = np.zeros(count - 1)
    np.maximum.at(scores, labels[on] - 1, window[on])
    best = np.argsort(-scores, kind="stable")[:top]
    sides = np.maximum(stats[1:, cv2.CC_STAT_WIDTH], stats[1:, cv2.CC_STAT_HEIGHT])
    return [
        Candidate.from_circle(
            centroids[i + 1][0] + left + 0.5,
            centroids[i + 1][1] + top_row + 0.5,
            sides[i] / 2,
            scores[i],
            state,
        )
        for i in best
    ]


class LabFrst(Detector):
    """LAB-FRST baseline (Siogkas et al. via Zheng 2016, 5.2.2).

    Zheng 5.2.2 sets radii 1..10, alpha 3, binarisation at half the maximum and 8-connectivity;
    it also says "the orientation flag is set to be true" for the inventor's code, which we cannot
    see. We default to the full transform F_n = (M_n/k_n)(|O~_n|/k_n)^alpha and expose the
    orientation-based variant as ``orientation_only``. Zheng gives no gradient threshold, so
    ``beta`` defaults to 0 (every non-zero gradient votes).
    """

    name = "lab-frst"
    summary = (
        "CIELab L*(a+b) map, fast radial symmetry transform, top bright (red) and "
        "dark (green) spots"
    )
    section = "Zheng 2016, 5.2.2; Loy & Zelinsky 2003"
    PARAMS = (
        Param(
            "radii",
            "ints",
            tuple(range(1, 11)),
            min=1,
            max=64,
            help="FRST radii n in pixels",
            section="Zheng 5.2.2",
        ),
        Param(
            "alpha",
            "float",
            3.0,
            min=0.1,
            max=10,
            help="FRST radial strictness",
            section="Zheng 5.2.2",
        ),
        Param(
            "beta",
            "float",
            0.0,
            min=0,
            max=0.99,
            help="gradient threshold as a fraction of the largest gradient (not stated by Zheng)",
            section="Loy & Zelinsky 2003",
        ),
        Param(
            "fraction",
            "float",
            0.5,
            min=0.01,
            max=1,
            help="binarise each symmetry map at this fraction of its maximum",
            section="Zheng 5.2.2",
        ),
        Param(
            "top",
            "int",
            5,
            min=1,
            max=100,
            help="spots kept per polarity (bright = red, dark = green)",
            section="Zheng 5.2.2",
        ),
        Param(
            "orientation_only",
            "bool",
            False,
            help="use the orientation-based FRST (no magnitude projection)",
            section="Loy & Zelinsky 2003",
        ),
    )

    def detect(self, frame: Frame) -> list[Candidate]:
        """Up to ``top`` red-hinted and ``top`` green-hinted candidates, strongest first."""
        p = self.params
        feature = frame_feature_map(frame)
        bright, dark = symmetry_maps(
            feature, p["radii"], p["alpha"], p["beta"], p["orientation_only"]
        )
        found = spot_candidates(bright, p["fraction"], p["top"], "red") + spot_candidates(
            dark, p["fraction"], p["top"], "green"
        )
        return sorted(found, key=lambda c: -c.score)


@hookimpl
def register_detectors(register):
    """Register the LAB-FRST detector."""
    register(LabFrst)
