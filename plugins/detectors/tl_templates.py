"""Templates, patches and their comparison for TL-recognizer's validation (Mascetti 2016, 3.5).

The default template of each colour is a generated lit disc on a dark background screen; a
folder given by the user (``red.png``, ``yellow.png``, ``green.png``) replaces them, e.g. with
pedestrian figures. A patch is the levelled minimum bounding rectangle of a contour, sampled from
the full-resolution frame straight at template size (rotation, crop and resize in one warp).
"""
from __future__ import annotations

from pathlib import Path

import cv2
import numpy as np

from tsrkit.errors import TsrkitError
from tsrkit.inputs import read_image

#: Colours of the generated templates (BGR): a lit lens as a fixed exposure records it.
LENS_BGR = {"green": (190, 255, 80), "yellow": (40, 200, 255), "red": (60, 40, 255)}
#: The background screen around the lens (BGR).
SCREEN_BGR = (25, 25, 25)
TEMPLATE_STATES = ("red", "yellow", "green")


def disc_template(state: str, size: int) -> np.ndarray:
    """A lit disc of ``state``'s colour filling a ``size`` x ``size`` template (BGR uint8).

    The edge is softened by a Gaussian (sigma = size / 32) as optics do.
    """
    if state not in LENS_BGR:
        raise ValueError(f"no default template for state {state!r}; expected one of "
                         f"{', '.join(TEMPLATE_STATES)}")
    if size < 4:
        raise ValueError(f"template size must be at least 4 pixels; got {size}")
    image = np.full((size, size, 3), SCREEN_BGR, np.float32)
    yy, xx = np.mgrid[:size, :size]
    centre = (size - 1) / 2
    image[(xx - centre) ** 2 + (yy - centre) ** 2 <= (size / 2) ** 2] = LENS_BGR[state]
    image = cv2.GaussianBlur(image, (0, 0), size / 32)
    return np.clip(np.rint(image), 0, 255).astype(np.uint8)


def load_templates(folder: str | None, size: int) -> dict[str, np.ndarray]:
    """Templates per state, ``size`` x ``size`` BGR: generated discs or ``folder``'s images.

    Raises
    ------
    TsrkitError
        When ``folder`` is given but lacks an image for a state.
    """
    if folder is None:
        return {state: disc_template(state, size) for state in TEMPLATE_STATES}
    out = {}
    for state in TEMPLATE_STATES:
        found = sorted(Path(folder).glob(f"{state}.*"))
        if not found:
            raise TsrkitError(f"templates folder {folder}: no image named {state}.* "
                              f"(expected red.*, yellow.* and green.*)")
        out[state] = cv2.resize(read_image(found[0]), (size, size), interpolation=cv2.INTER_AREA)
    return out


def extract_patch(image: np.ndarray, box_uv: tuple[float, float, float, float], roll: float,
                  centre: tuple[float, float], size: int) -> np.ndarray:
    """Sample the levelled rectangle ``box_uv`` of ``image`` at ``size`` x ``size`` (3.5).

    ``box_uv = (u0, v0, u1, v1)`` are pixel-edge extents in the levelled frame of
    :func:`tl_geometry.level_coordinates`; the patch is rotated on the fly, as the paper does, by
    one affine warp from patch pixels to image pixels (bilinear, border replicated).
    """
    u0, v0, u1, v1 = box_uv
    su, sv = (u1 - u0) / size, (v1 - v0) / size
    c, s = np.cos(roll), np.sin(roll)
    # patch pixel (j, i) centre -> levelled (u, v) -> image (x, y)
    to_uv = np.array([[su, 0.0, u0 + su / 2], [0.0, sv, v0 + sv / 2]])
    to_xy = np.array([[c, s], [-s, c]])
    matrix = np.hstack([to_xy @ to_uv[:, :2], (to_xy @ to_uv[:, 2] + centre)[:, None]])
    return cv2.warpAffine(image, matrix, (size, size), flags=cv2.INTER_LINEAR | cv2.WARP_INVERSE_MAP,
                          borderMode=cv2.BORDER_REPLICATE)


def ncc(patch: np.ndarray, template: np.ndarray) -> float:
    """Normalised cross-correlation of two same-sized BGR images, in [-1, 1] (3.5, ref. [21]).

    OpenCV's ``TM_CCOEFF_NORMED`` with the patch the size of the template: each channel's mean
    is removed and the products summed over channels. A flat patch scores 0.
    """
    if patch.shape != template.shape:
        raise ValueError(f"patch {patch.shape} and template {template.shape} differ in shape")
    score = float(cv2.matchTemplate(patch, template, cv2.TM_CCOEFF_NORMED)[0, 0])
    return score if np.isfinite(score) else 0.0
