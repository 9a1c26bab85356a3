"""Templates, patches and their comparison for TL-recognizer's validation (Mascetti 2016, 3.5).

Two layouts are available. ``lens``: the patch is the levelled minimum bounding rectangle (MBR) of
a contour, as 3.5 describes it, compared with a lit disc. ``housing`` (the default): the patch
covers the signal head the lens implies (Figs. 5-6, 15e: the template is a picture of the lit
optical unit together with its dark background screen). In a vertical 3-lens head the red lens is
at the top, yellow in the middle and green at the bottom, so the patch extends from the lens by
two lens pitches in the direction of the unlit units, plus a margin all around; in a horizontal
head red is on the left and green on the right. The housing template is the dark screen with the
lit disc at its colour's position, the two other lenses dim, and a lighter surround in the margin
(the head stands out against what is behind it). Extending the patch beyond the MBR is our
reading of the templates of Fig. 15e, not a step the text of 3.5 spells out; it is what rejects
round street lamps, which match a bare disc as well as a lens does.

A folder given by the user (``red.png``, ``yellow.png``, ``green.png``) replaces the generated
templates, e.g. with pedestrian figures; each image is resized to the patch shape. Patches are
sampled from the full-resolution frame straight at template size (rotation, crop and resize in one
warp).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import cv2
import numpy as np

from tsrkit.api import TsrkitError, read_image

#: Colours of the generated templates (BGR): a lit lens as a fixed exposure records it.
LENS_BGR = {"green": (190, 255, 80), "yellow": (40, 200, 255), "red": (60, 40, 255)}
#: The background screen around the lens (BGR).
SCREEN_BGR = (25, 25, 25)
#: An unlit lens of the housing template (BGR).
DIM_BGR = (45, 45, 45)
#: What surrounds the housing in the template's margin (BGR): a daylight-to-dusk sky grey; the
#: contrast with the screen is what a bare lamp lacks (a night sky behind a head scores low).
SURROUND_BGR = (160, 160, 160)
#: Width of the screen beyond the lenses, in lens diameters (EN 12368 heads: about a fifth).
SCREEN_BORDER = 0.2
TEMPLATE_STATES = ("red", "yellow", "green")
#: Position of each colour's lens in a 3-lens head, top to bottom or left to right.
LENS_INDEX = {"red": 0, "yellow": 1, "green": 2}
ORIENTATIONS = ("vertical", "horizontal")


@dataclass(frozen=True)
class Layout:
    """What a patch covers: the bare lens, or the housing of a 3-lens head around it.

    ``pitch`` (centre distance of neighbouring lenses) and ``margin`` (around the housing) are in
    lens diameters; ``size`` is the patch side across the head in pixels.
    """

    housing: bool
    size: int
    pitch: float = 1.3
    margin: float = 0.5

    def extents(self, state: str) -> tuple[float, float, float]:
        """Patch extents from the lens centre in lens diameters: (before, after, half across).

        ``before`` runs up (vertical) or left (horizontal), ``after`` down or right.
        """
        if not self.housing:
            return 0.5, 0.5, 0.5
        k = LENS_INDEX[state]
        return (
            k * self.pitch + 0.5 + self.margin,
            (2 - k) * self.pitch + 0.5 + self.margin,
            0.5 + self.margin,
        )

    def shape(self) -> tuple[int, int]:
        """Patch (along, across) sides in pixels; the same for every state."""
        before, after, across = self.extents("yellow")
        return int(round(self.size * (before + after) / (2 * across))), self.size


def patch_box(
    box_uv: tuple[float, float, float, float], state: str, orientation: str, layout: Layout
) -> tuple[float, float, float, float]:
    """The levelled rectangle a patch covers, for the lens MBR ``box_uv`` of colour ``state``."""
    u0, v0, u1, v1 = box_uv
    cu, cv, du, dv = (u0 + u1) / 2, (v0 + v1) / 2, u1 - u0, v1 - v0
    before, after, across = layout.extents(state)
    if orientation == "vertical":
        return cu - across * du, cv - before * dv, cu + across * du, cv + after * dv
    return cu - before * du, cv - across * dv, cu + after * du, cv + across * dv


def patch_size(orientation: str, layout: Layout) -> tuple[int, int]:
    """Patch ``(width, height)`` in pixels for an orientation."""
    along, across = layout.shape()
    return (across, along) if orientation == "vertical" else (along, across)


def _disc(image: np.ndarray, centre: tuple[float, float], radius: float, colour) -> None:
    """Fill a disc of ``image`` (float, in place)."""
    yy, xx = np.mgrid[: image.shape[0], : image.shape[1]]
    image[(xx - centre[0]) ** 2 + (yy - centre[1]) ** 2 <= radius**2] = colour


def _finish(image: np.ndarray, sigma: float) -> np.ndarray:
    """Soften edges by a Gaussian as optics do and convert to BGR uint8."""
    image = cv2.GaussianBlur(image, (0, 0), sigma)
    return np.clip(np.rint(image), 0, 255).astype(np.uint8)


def _check_state(state: str, size: int) -> None:
    """Raise ValueError for a state without a default template or a size under 4 pixels."""
    if state not in LENS_BGR:
        raise ValueError(
            f"no default template for state {state!r}; expected one of {', '.join(TEMPLATE_STATES)}"
        )
    if size < 4:
        raise ValueError(f"template size must be at least 4 pixels; got {size}")


def disc_template(state: str, size: int) -> np.ndarray:
    """A lit disc of ``state``'s colour filling a ``size`` x ``size`` template (BGR uint8).

    The edge is softened by a Gaussian (sigma = size / 32).
    """
    _check_state(state, size)
    image = np.full((size, size, 3), SCREEN_BGR, np.float32)
    _disc(image, ((size - 1) / 2, (size - 1) / 2), size / 2, LENS_BGR[state])
    return _finish(image, size / 32)


def housing_template(state: str, orientation: str, layout: Layout) -> np.ndarray:
    """A 3-lens head with ``state``'s lens lit, the others dim, in a lighter surround (BGR uint8).

    The dark screen reaches :data:`SCREEN_BORDER` lens diameters beyond the lenses (or the whole
    margin, if smaller); the rest of the margin is the surround.
    The image covers what :func:`patch_box` covers, at :func:`patch_size`; the edges are softened
    by a Gaussian (sigma = one 32nd of the lens diameter).
    """
    _check_state(state, layout.size)
    before, _after, across = layout.extents(state)
    lens_px = layout.size / (2 * across)  # lens diameter in template pixels
    along, side = layout.shape()
    image = np.full((along, side, 3), SURROUND_BGR, np.float32)
    m = int(round(max(layout.margin - SCREEN_BORDER, 0.0) * lens_px))
    image[m : along - m, m : side - m] = SCREEN_BGR
    first = (before - LENS_INDEX[state] * layout.pitch) * lens_px  # centre of lens 0, along
    for k in range(3):
        colour = LENS_BGR[state] if k == LENS_INDEX[state] else DIM_BGR
        _disc(
            image, ((side - 1) / 2, first + k * layout.pitch * lens_px - 0.5), lens_px / 2, colour
        )
    image = _finish(image, lens_px / 32)
    return image if orientation == "vertical" else np.ascontiguousarray(image.transpose(1, 0, 2))


def default_template(state: str, orientation: str, layout: Layout) -> np.ndarray:
    """The generated template of a state: a housing for the housing layout, else a lit disc."""
    if layout.housing:
        return housing_template(state, orientation, layout)
    return disc_template(state, layout.size)


def folder_template(folder: str, state: str) -> np.ndarray:
    """The user's template image ``folder/<state>.*`` (BGR).

    Raises
    ------
    TsrkitError
        When the folder lacks an image for the state.
    """
    found = sorted(Path(folder).glob(f"{state}.*"))
    if not found:
        raise TsrkitError(
            f"templates folder {folder}: no image named {state}.* "
            f"(expected red.*, yellow.* and green.*)"
        )
    return read_image(found[0])


def load_templates(folder: str | None, layout: Layout) -> dict[tuple[str, str], np.ndarray]:
    """Templates per (state, orientation), BGR at :func:`patch_size`: generated or ``folder``'s."""
    out = {}
    for state in TEMPLATE_STATES:
        for orientation in ORIENTATIONS:
            image = (
                default_template(state, orientation, layout)
                if folder is None
                else folder_template(folder, state)
            )
            out[state, orientation] = cv2.resize(
                image, patch_size(orientation, layout), interpolation=cv2.INTER_AREA
            )
    return out


def warp_matrices(
    boxes_uv: np.ndarray,
    roll: float,
    centre: tuple[float, float],
    size: tuple[int, int],
) -> np.ndarray:
    """The affine maps ``(N, 2, 3)`` from the pixels of a ``size`` (w, h) patch to the image
    pixels of each levelled rectangle ``(u0, v0, u1, v1)`` of ``boxes_uv`` (N, 4).

    Patch pixel ``(j, i)``'s centre goes to the levelled ``(u0 + (j + 1/2) su, v0 + (i + 1/2)
    sv)``, rotated by the roll about ``centre``. Without roll the rotation is the identity and
    the maps are written out for all boxes at once, with the same numbers as the product of the
    two matrices that a rolled box gets.
    """
    width, height = size
    boxes = np.asarray(boxes_uv, dtype=np.float64).reshape(-1, 4)
    su, sv = (boxes[:, 2] - boxes[:, 0]) / width, (boxes[:, 3] - boxes[:, 1]) / height
    out = np.zeros((len(boxes), 2, 3))
    if roll == 0:
        out[:, 0, 0], out[:, 1, 1] = su, sv
        out[:, 0, 2] = boxes[:, 0] + su / 2 + centre[0]
        out[:, 1, 2] = boxes[:, 1] + sv / 2 + centre[1]
        return out
    c, s = np.cos(roll), np.sin(roll)
    to_xy = np.array([[c, s], [-s, c]])
    for k, (u0, v0) in enumerate(boxes[:, :2]):
        to_uv = np.array([[su[k], 0.0, u0 + su[k] / 2], [0.0, sv[k], v0 + sv[k] / 2]])
        out[k, :, :2] = to_xy @ to_uv[:, :2]
        out[k, :, 2] = to_xy @ to_uv[:, 2] + centre
    return out


def warp_patch(image: np.ndarray, matrix: np.ndarray, size: tuple[int, int]) -> np.ndarray:
    """The patch of ``size`` (w, h) that the map ``matrix`` of :func:`warp_matrices` samples
    (bilinear, border replicated)."""
    return cv2.warpAffine(
        image,
        matrix,
        size,
        flags=cv2.INTER_LINEAR | cv2.WARP_INVERSE_MAP,
        borderMode=cv2.BORDER_REPLICATE,
    )


def extract_patch(
    image: np.ndarray,
    box_uv: tuple[float, float, float, float],
    roll: float,
    centre: tuple[float, float],
    size: int | tuple[int, int],
) -> np.ndarray:
    """Sample the levelled rectangle ``box_uv`` of ``image`` at ``size`` (side or (w, h); 3.5).

    ``box_uv = (u0, v0, u1, v1)`` are pixel-edge extents in the levelled frame of
    :func:`tl_geometry.level_coordinates`; the patch is rotated on the fly, as the paper does, by
    one affine warp from patch pixels to image pixels (bilinear, border replicated).
    """
    shape = (int(size), int(size)) if isinstance(size, int | np.integer) else (size[0], size[1])
    return warp_patch(image, warp_matrices(np.array([box_uv]), roll, centre, shape)[0], shape)


def ncc(patch: np.ndarray, template: np.ndarray) -> float:
    """Normalised cross-correlation of two same-sized BGR images, in [-1, 1] (3.5, ref. [21]).

    OpenCV's ``TM_CCOEFF_NORMED`` with the patch the size of the template: each channel's mean
    is removed and the products summed over channels. A flat patch scores 0.
    """
    if patch.shape != template.shape:
        raise ValueError(f"patch {patch.shape} and template {template.shape} differ in shape")
    score = float(cv2.matchTemplate(patch, template, cv2.TM_CCOEFF_NORMED)[0, 0])
    return score if np.isfinite(score) else 0.0


def ncc_batch(patches: np.ndarray, template: np.ndarray, floor: float = 0.0) -> np.ndarray:
    """:func:`ncc` of each patch of a stack ``(N, h, w, 3)`` with one template, in float64.

    The same formula (per-channel means removed, products summed over channels, over the root
    of the product of the sums of squares), from per-channel sums of the 8-bit values, which
    float64 holds exactly: it agrees with OpenCV's value up to float rounding, except on
    (nearly) flat patches, where rounding decides OpenCV's value: NaN for a patch whose sum of
    squared deviations is at most ``floor``.
    """
    count, channels = len(patches), patches.shape[-1]
    pixels = patches[0].size // channels if count else 1
    x = patches.reshape(count, -1).astype(np.float64)
    t = template.reshape(-1).astype(np.float64)
    channel_of = np.tile(np.eye(channels), (pixels, 1))  # sums per channel as a product
    sums = x @ channel_of
    t_sums = t @ channel_of
    numerator = x @ t - sums @ t_sums / pixels
    energy = np.einsum("nk,nk->n", x, x) - (sums * sums).sum(axis=1) / pixels
    t_energy = float(t @ t - t_sums @ t_sums / pixels)
    out = np.full(count, np.nan)
    usable = (energy > floor) & (energy > 0) & (t_energy > 0)
    np.divide(numerator, np.sqrt(np.maximum(energy, 0) * t_energy), out=out, where=usable)
    return out
