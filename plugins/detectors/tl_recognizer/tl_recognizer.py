"""TL-recognizer (Mascetti et al. 2016): HSV range filters, contour pruning, template validation.

Per colour pass (green and "yellowRed", 4.1) the frame reduced by the resize factor (4.2) is range
filtered in HSV (3.3, Table 6), its contours are levelled by the horizon roll and pruned by size
(3.4), and each survivor's full-resolution patch is compared with a template by NCC (3.5). By
default the patch covers the 3-lens housing the lens implies (``context=housing``, see
:mod:`tl_templates`); ``context=lens`` validates the bare contour MBR against a lit disc.
"""

from __future__ import annotations

from collections.abc import Iterable
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass

import cv2
import numpy as np

from tsrkit.api import Candidate, Detector, Frame, Model, Param, Sample, hookimpl, load_model
from tsrkit_plugins.detectors.tl_recognizer import tl_geometry as geo
from tsrkit_plugins.detectors.tl_recognizer.tl_templates import (
    ORIENTATIONS,
    Layout,
    load_templates,
    ncc,
    ncc_batch,
    patch_box,
    patch_size,
    warp_matrices,
    warp_patch,
)

#: Filters of the ranges array: rows of ``ranges[k] = [[h, s, v]_min, [h, s, v]_max]``.
FILTERS = ("green", "yellowred_first", "yellowred_second")
#: The colour passes of 4.1 and the filter rows each one ORs together.
PASSES = {"green": (0,), "yellowred": (1, 2)}
#: How far below the threshold T a contour's float64 NCC may lie and still be scored by OpenCV
#: (the two differ by float rounding, orders of magnitude less).
NCC_MARGIN = 0.02
#: Patches whose summed squared deviation from their channel means is at most this are flat
#: enough for rounding to decide OpenCV's NCC: always scored by OpenCV.
FLAT_ENERGY = 1000.0


def table6_ranges(green_h, yellowred_h, s_range, v_range) -> np.ndarray:
    """The range-filter bounds of Table 6 as a (3, 2, 3) array (filter, min/max, H/S/V)."""
    hues = (
        (green_h[0], green_h[1]),
        (yellowred_h[0], yellowred_h[1]),
        (yellowred_h[2], yellowred_h[3]),
    )
    return np.array(
        [[[lo, s_range[0], v_range[0]], [hi, s_range[1], v_range[1]]] for lo, hi in hues],
        dtype=np.float64,
    )


def range_mask(hsv: np.ndarray, ranges: np.ndarray, rows: tuple[int, ...]) -> np.ndarray:
    """Binary image of the pixels inside any of the filters ``rows`` (3.3, Algorithm 1 line 4)."""
    mask = cv2.inRange(hsv, ranges[rows[0], 0], ranges[rows[0], 1])
    for row in rows[1:]:
        mask |= cv2.inRange(hsv, ranges[row, 0], ranges[row, 1])
    return mask


def reduced_hsv(image: np.ndarray, factor: int) -> np.ndarray:
    """The frame divided by ``factor`` on both sides (area averaging), in HSV (4.2)."""
    small = (
        image
        if factor == 1
        else cv2.resize(
            image,
            (max(1, image.shape[1] // factor), max(1, image.shape[0] // factor)),
            interpolation=cv2.INTER_AREA,
        )
    )
    return cv2.cvtColor(small, cv2.COLOR_BGR2HSV)


def enclosed_cores(hsv: np.ndarray, mask: np.ndarray, core_v: int, ring_share: float) -> np.ndarray:
    """``mask`` plus the bright blobs outside it that are mostly ringed by ``mask`` pixels.

    An overexposed lens records as a white core (low S, V near 255) inside a coloured ring, and
    the range filter keeps only the ring (3.3). A core is an 8-connected blob of pixels with
    V >= ``core_v`` outside ``mask``; it joins the mask when at least ``ring_share`` of the pixels
    bordering it are in ``mask``. Not in the paper, whose fixed exposure (3.2) avoids white cores.

    Examples
    --------
    >>> import numpy as np
    >>> hsv = np.zeros((5, 5, 3), np.uint8); hsv[2, 2] = (0, 0, 255)
    >>> ring = np.full((5, 5), 255, np.uint8); ring[2, 2] = 0
    >>> int(enclosed_cores(hsv, ring, 230, 0.5)[2, 2])
    255
    """
    core = ((hsv[..., 2] >= core_v) & (mask == 0)).astype(np.uint8)
    count, labels = cv2.connectedComponents(core, connectivity=8)
    if count <= 1:
        return mask
    grown = cv2.dilate(labels.astype(np.float32), np.ones((3, 3), np.uint8)).astype(np.int64)
    border = (core == 0) & (grown > 0)
    total = np.bincount(grown[border], minlength=count)
    ringed = np.bincount(grown[border & (mask > 0)], minlength=count)
    accept = ringed >= ring_share * np.maximum(total, 1)
    accept[0] = False
    return np.where(accept[labels], np.uint8(255), mask)


def extract_contours(mask: np.ndarray) -> list[np.ndarray]:
    """Outer contours of the white blobs (Suzuki-Abe border following, 3.3 / Algorithm 1 line 5)."""
    contours, _ = cv2.findContours(mask, cv2.RETR_EXTERNAL, cv2.CHAIN_APPROX_SIMPLE)
    return list(contours)


def levelled_boxes(
    contours: list[np.ndarray], scale: tuple[float, float], roll: float, centre: tuple[float, float]
) -> np.ndarray:
    """Pixel-edge extents ``(u0, v0, u1, v1)`` of reduced-frame contours, levelled (line 8).

    All contours' points are scaled to the full frame and levelled in one array operation and
    reduced per contour, so a cluttered frame's thousands of contours cost no Python loop.
    """
    if not contours:
        return np.zeros((0, 4))
    pts = np.concatenate([c.reshape(-1, 2) for c in contours]).astype(np.float64)
    pts = (pts + 0.5) * scale - 0.5
    uv = geo.level_coordinates(pts, roll, centre)
    starts = np.cumsum([0] + [len(c) for c in contours[:-1]])
    low, high = np.minimum.reduceat(uv, starts), np.maximum.reduceat(uv, starts)
    pad_u, pad_v = scale[0] / 2, scale[1] / 2
    return np.column_stack(
        [low[:, 0] - pad_u, low[:, 1] - pad_v, high[:, 0] + pad_u, high[:, 1] + pad_v]
    )


def image_boxes(boxes_uv: np.ndarray, roll: float, centre: tuple[float, float]) -> np.ndarray:
    """Axis-aligned frame boxes ``(x0, y0, x1, y1)`` around levelled boxes (N, 4)."""
    u0, v0, u1, v1 = boxes_uv.T
    corners = np.stack([u0, v0, u1, v0, u1, v1, u0, v1], axis=1).reshape(-1, 2)
    xy = geo.image_coordinates(corners, roll, centre).reshape(-1, 4, 2)
    return np.concatenate([xy.min(axis=1), xy.max(axis=1)], axis=1)


def red_or_yellow(
    patch_bgr: np.ndarray,
    s_min: float,
    v_min: float,
    red_h: tuple[int, int],
    yellow_h: tuple[int, int],
) -> str:
    """Red when the lit pixels of a patch hold more red hues than yellow ones, else yellow (4.1).

    Only pixels with S >= ``s_min`` and V >= ``v_min`` are counted (our reading: the hue of the
    dark background screen is noise). One patch of :func:`red_or_yellow_states`.
    """
    return red_or_yellow_states(patch_bgr[None], s_min, v_min, red_h, yellow_h)[0]


def red_or_yellow_states(
    patches_bgr: np.ndarray,
    s_min: float,
    v_min: float,
    red_h: tuple[int, int],
    yellow_h: tuple[int, int],
) -> list[str]:
    """:func:`red_or_yellow` of each patch of a stack ``(N, h, w, 3)``, in one HSV conversion
    (per pixel, so the same values as patch by patch)."""
    count, height, width = patches_bgr.shape[:3]
    if count == 0:
        return []
    hsv = cv2.cvtColor(patches_bgr.reshape(count * height, width, 3), cv2.COLOR_BGR2HSV)
    hsv = hsv.reshape(count, height * width, 3)
    lit = (hsv[..., 1] >= s_min) & (hsv[..., 2] >= v_min)
    hue = hsv[..., 0]
    reds = np.count_nonzero(lit & (hue >= red_h[0]) & (hue <= red_h[1]), axis=1)
    yellows = np.count_nonzero(lit & (hue >= yellow_h[0]) & (hue <= yellow_h[1]), axis=1)
    return ["red" if r > y else "yellow" for r, y in zip(reds, yellows)]


@dataclass(frozen=True)
class Camera:
    """What pruning knows of the camera: focal length (None: unknown), pitch and roll (radians)."""

    focal_px: float | None
    pitch: float
    roll: float


class TlRecognizer(Detector):
    name = "tl-recognizer"
    summary = "HSV range filters, contour pruning and template NCC validation; assigns the state"
    section = "Mascetti 2016, 3.2-3.5, 4.1-4.2, 5.2, Table 6"
    PARAMS = (
        Param(
            "green_h",
            "ints",
            (70, 95),
            min=0,
            max=180,
            length=2,
            help="hue range of the green filter (OpenCV scale)",
            section="Table 6",
        ),
        Param(
            "yellowred_h",
            "ints",
            (0, 25, 166, 180),
            min=0,
            max=180,
            length=4,
            help="the two hue ranges of the yellowRed filter",
            section="Table 6, 4.1",
        ),
        Param(
            "s_range",
            "ints",
            (100, 255),
            min=0,
            max=255,
            length=2,
            help="saturation range of every filter",
            section="Table 6",
        ),
        Param(
            "v_range",
            "ints",
            (80, 255),
            min=0,
            max=255,
            length=2,
            help="value range of every filter",
            section="Table 6",
        ),
        Param(
            "red_h",
            "ints",
            (160, 179),
            min=0,
            max=180,
            length=2,
            help="pure red hues counted for the red/yellow split",
            section="4.1",
        ),
        Param(
            "yellow_h",
            "ints",
            (10, 30),
            min=0,
            max=180,
            length=2,
            help="pure yellow hues counted for the red/yellow split",
            section="4.1",
        ),
        Param(
            "threshold",
            "float",
            0.586,
            min=-1,
            max=1,
            help="NCC above which a patch is a lit lens (T)",
            section="3.5, 5.2",
        ),
        Param(
            "resize_factor",
            "int",
            3,
            min=1,
            max=16,
            help="extraction and pruning on the frame reduced by this factor",
            section="4.2",
        ),
        Param(
            "template_size",
            "int",
            32,
            min=4,
            max=256,
            help="side of the square templates in pixels",
            section="3.5",
        ),
        Param(
            "templates",
            "path",
            None,
            help="folder with red.*, yellow.*, green.* template images, resized to the patch "
            "(default: generated housings or lit discs)",
            section="3.5",
        ),
        Param(
            "context",
            "str",
            "lens",
            choices=("lens", "housing"),
            help="validate the bare lens MBR (the paper's text; the default, which keeps "
            "recall on real sets), or the 3-lens housing the lens implies (rejects "
            "round street lamps, but loses horizontal and 4-lens heads)",
            section="3.5, Figs. 5, 6, 15e",
        ),
        Param(
            "orientation",
            "str",
            "vertical",
            choices=("vertical", "horizontal", "both"),
            help="housing orientation (red top/left, green bottom/right); both: better score",
            section="2.4",
        ),
        Param(
            "lens_pitch",
            "float",
            1.3,
            min=1,
            help="centre distance of neighbouring lenses in lens diameters (housing context)",
        ),
        Param(
            "margin",
            "float",
            0.5,
            min=0,
            help="margin around the housing in lens diameters (housing context)",
        ),
        Param(
            "fill_cores",
            "bool",
            False,
            help="add white lens cores ringed by the colour to the range-filter mask "
            "(not in the paper; false is the paper's extraction)",
            section="3.3",
        ),
        Param(
            "core_v",
            "int",
            230,
            min=0,
            max=255,
            help="smallest V of a white lens core (fill_cores)",
        ),
        Param(
            "ring_share",
            "float",
            0.5,
            min=0,
            max=1,
            help="share of a core's border pixels that must pass the colour filter (fill_cores)",
        ),
        Param(
            "focal_px",
            "float",
            None,
            min=1,
            help="focal length in pixels, if frames lack metadata 'focal_px'",
            section="3.4",
        ),
        Param(
            "pitch_deg",
            "float",
            0.0,
            min=-90,
            max=90,
            help="camera pitch (up positive), if frames lack 'pitch_deg'",
            section="Property 1",
        ),
        Param(
            "roll_deg",
            "float",
            0.0,
            min=-180,
            max=180,
            help="camera roll, if frames lack 'roll_deg'",
            section="Property 1",
        ),
        Param(
            "lens_m",
            "float",
            0.2,
            min=0.01,
            help="lens height and width in metres",
            section="2.4, Property 2",
        ),
        Param(
            "horizontal_m",
            "floats",
            (2.5, 20.0),
            min=0,
            length=2,
            help="allowed horizontal distance to the light",
            section="2.4, Property 2",
        ),
        Param(
            "vertical_m",
            "floats",
            (0.5, 4.0),
            length=2,
            help="allowed height of the light above the camera",
            section="2.4, Property 2",
        ),
        Param(
            "max_rotation_deg",
            "float",
            45.0,
            min=0,
            max=89,
            help="maximum rotation distance of a light towards the user",
            section="2.4, Prop. 3",
        ),
        Param(
            "width_slack",
            "float",
            0.15,
            min=0,
            max=1,
            help="relative tolerance of the width test for pixel quantisation (not in the paper)",
        ),
        Param(
            "size_px",
            "floats",
            (3.0, 400.0),
            min=0,
            length=2,
            help="lens height range in full-resolution pixels when focal_px is unknown",
        ),
        Param(
            "min_aspect",
            "float",
            0.5,
            min=0.01,
            max=1,
            help="smallest width/height (and height/width) ratio when focal_px is unknown",
        ),
        Param(
            "threads",
            "int",
            1,
            min=1,
            max=2,
            help="threads for the colour passes (2 runs green and yellowRed together)",
            section="4.2",
        ),
        Param(
            "fit_ranges",
            "bool",
            True,
            help="training: derive the range-filter bounds (Figure 16) before T; false "
            "tunes T alone on the current ranges",
            section="5.2",
        ),
        Param(
            "fit_coverage",
            "float",
            1.0,
            min=0.5,
            max=1,
            help="training: share of annotated lens pixels the derived ranges include",
            section="5.2, Figure 16",
        ),
        Param(
            "model",
            "path",
            None,
            help="model from 'tsrkit train tl-recognizer' (ranges and T)",
            section="5.2",
        ),
    )

    def __init__(self, **params):
        super().__init__(**params)
        p = self.params
        self.ranges = table6_ranges(p["green_h"], p["yellowred_h"], p["s_range"], p["v_range"])
        self.threshold = p["threshold"]
        if p["model"] is not None:
            model = load_model(p["model"], plugin=self.name)
            self.ranges = np.asarray(model.arrays["ranges"], dtype=np.float64)
            self.threshold = float(model.arrays["threshold"])
        self.layout = Layout(
            p["context"] == "housing", p["template_size"], p["lens_pitch"], p["margin"]
        )
        self.orientations = ORIENTATIONS if p["orientation"] == "both" else (p["orientation"],)
        self.templates = load_templates(p["templates"], self.layout)

    def camera(self, frame: Frame) -> Camera:
        """Focal length, pitch and roll from the frame's metadata, else from the parameters."""
        meta, p = frame.metadata, self.params
        focal = meta.get("focal_px", p["focal_px"])
        return Camera(
            None if focal is None else float(focal),
            float(np.radians(meta.get("pitch_deg", p["pitch_deg"]))),
            float(np.radians(meta.get("roll_deg", p["roll_deg"]))),
        )

    def detect(self, frame: Frame) -> list[Candidate]:
        """Lit lenses whose NCC exceeds T, best first; ``state`` is red, yellow or green."""
        return [c for c in self._found(frame, self.threshold) if c.score > self.threshold]

    def scored(self, frame: Frame) -> list[Candidate]:
        """Every contour that survives pruning, scored by NCC but not thresholded, best first."""
        return self._found(frame, None)

    def _found(self, frame: Frame, threshold: float | None) -> list[Candidate]:
        """The candidates of both colour passes, best first; with ``threshold``, only those
        whose NCC exceeds it (see :meth:`_scores`)."""
        image = frame.image
        hsv = reduced_hsv(image, self.params["resize_factor"])
        camera = self.camera(frame)
        jobs = [(hsv, image, colour, camera, threshold) for colour in PASSES]
        if self.params["threads"] > 1:
            with ThreadPoolExecutor(self.params["threads"]) as pool:
                found = list(pool.map(lambda job: self._colour_pass(*job), jobs))
        else:
            found = [self._colour_pass(*job) for job in jobs]
        return sorted((c for part in found for c in part), key=lambda c: -c.score)

    def _colour_pass(
        self,
        hsv: np.ndarray,
        image: np.ndarray,
        colour: str,
        camera: Camera,
        threshold: float | None = None,
    ) -> list[Candidate]:
        """Extraction, pruning and validation for one colour (Algorithm 1, lines 3-16)."""
        mask = range_mask(hsv, self.ranges, PASSES[colour])
        if self.params["fill_cores"]:
            mask = enclosed_cores(hsv, mask, self.params["core_v"], self.params["ring_share"])
        scale = (image.shape[1] / hsv.shape[1], image.shape[0] / hsv.shape[0])
        centre = ((image.shape[1] - 1) / 2, (image.shape[0] - 1) / 2)
        boxes = levelled_boxes(extract_contours(mask), scale, camera.roll, centre)
        kept = [tuple(box) for box in boxes[self._pruned(boxes, camera)]]
        if not kept:
            return []
        states, lenses = self._states(image, kept, colour, camera.roll, centre)
        scores = self._scores(image, kept, states, lenses, camera.roll, centre, threshold)
        frame_boxes = image_boxes(np.array(kept), camera.roll, centre)
        return [
            Candidate.from_box(tuple(box), score, state)
            for box, score, state in zip(frame_boxes, scores, states)
            if score is not None
        ]

    def _pruned(self, boxes_uv: np.ndarray, camera: Camera) -> np.ndarray:
        """Which levelled boxes ``(N, 4)`` pass :meth:`_passes_pruning` (the pixel size and
        aspect bounds compared for all boxes at once when the focal length is unknown)."""
        if camera.focal_px is not None:
            return np.array([self._passes_pruning(tuple(b), camera) for b in boxes_uv], bool)
        width, height = boxes_uv[:, 2] - boxes_uv[:, 0], boxes_uv[:, 3] - boxes_uv[:, 1]
        aspect = width / height
        low, high = self.params["size_px"]
        least = self.params["min_aspect"]
        return (low <= height) & (height <= high) & (least <= aspect) & (aspect <= 1 / least)

    def _passes_pruning(self, box_uv, camera: Camera) -> bool:
        """Property 2 and 3 with a known focal length, else pixel size and aspect bounds (3.4)."""
        u0, v0, u1, v1 = box_uv
        width, height = u1 - u0, v1 - v0
        p = self.params
        if camera.focal_px is None:
            aspect = width / height
            return (
                p["size_px"][0] <= height <= p["size_px"][1]
                and p["min_aspect"] <= aspect <= 1 / p["min_aspect"]
            )
        return geo.passes_distance_and_width(
            v0,
            v1,
            width,
            focal_px=camera.focal_px,
            pitch=camera.pitch,
            lens_m=p["lens_m"],
            horizontal_m=p["horizontal_m"],
            vertical_m=p["vertical_m"],
            max_rotation=np.radians(p["max_rotation_deg"]),
            width_slack=p["width_slack"],
        )

    def _states(
        self, image: np.ndarray, boxes: list, colour: str, roll: float, centre: tuple[float, float]
    ) -> tuple[list[str], np.ndarray | None]:
        """Each contour's state: the pass's colour, or for yellowRed the red/yellow split on the
        lens patches (4.1), which are returned too (sampled at template size)."""
        if colour != "yellowred":
            return [colour] * len(boxes), None
        size = (self.params["template_size"],) * 2
        matrices = warp_matrices(np.array(boxes), roll, centre, size)
        lenses = np.stack([warp_patch(image, m, size) for m in matrices])
        states = red_or_yellow_states(
            lenses,
            self.ranges[1, 0, 1],
            self.ranges[1, 0, 2],
            self.params["red_h"],
            self.params["yellow_h"],
        )
        return states, lenses

    def _scores(
        self,
        image: np.ndarray,
        boxes: list,
        states: list[str],
        lenses: np.ndarray | None,
        roll: float,
        centre: tuple[float, float],
        threshold: float | None,
    ) -> list[float | None]:
        """Each contour's NCC with its state's template, the best over the allowed
        orientations (3.5); None for those a ``threshold`` rules out.

        The score is OpenCV's NCC (:func:`ncc`). With a ``threshold``, a contour whose NCC,
        computed in float64 for all patches at once (:func:`ncc_batch`), is below it by more
        than :data:`NCC_MARGIN` in every orientation cannot pass it and is not scored by OpenCV
        (the two computations differ by rounding only, far below the margin; nearly flat patches,
        :data:`FLAT_ENERGY`, are always scored by OpenCV); the others get OpenCV's value, so the
        candidates kept are those of the per-contour computation.
        """
        patches = {
            o: self._patches(image, boxes, states, lenses, o, roll, centre)
            for o in self.orientations
        }
        maybe = np.ones(len(boxes), bool)
        if threshold is not None:
            maybe[:] = False
            for orientation, stack in patches.items():
                for state in set(states):
                    rows = np.array([s == state for s in states])
                    template = self.templates[state, orientation]
                    approx = ncc_batch(stack[rows], template, FLAT_ENERGY)
                    maybe[rows] |= ~(approx <= threshold - NCC_MARGIN)
        return [
            max(ncc(patches[o][i], self.templates[states[i], o]) for o in self.orientations)
            if maybe[i]
            else None
            for i in range(len(boxes))
        ]

    def _patches(
        self,
        image: np.ndarray,
        boxes: list,
        states: list[str],
        lenses: np.ndarray | None,
        orientation: str,
        roll: float,
        centre: tuple[float, float],
    ) -> np.ndarray:
        """The patches a lens of each state implies in a head of ``orientation``, stacked.

        ``lenses`` are the lens MBRs already sampled at template size, if any; where a patch is
        that very rectangle at that size (the bare-lens layout), it is reused, not sampled again.
        """
        size = patch_size(orientation, self.layout)
        wanted = [patch_box(b, state, orientation, self.layout) for b, state in zip(boxes, states)]
        reuse = lenses is not None and size == lenses.shape[2:0:-1]
        todo = [i for i, box in enumerate(wanted) if not (reuse and box == boxes[i])]
        out = np.empty((len(boxes), size[1], size[0], 3), np.uint8)
        if lenses is not None and reuse:
            out[:] = lenses
        matrices = warp_matrices(np.array([wanted[i] for i in todo]), roll, centre, size)
        for i, matrix in zip(todo, matrices):
            out[i] = warp_patch(image, matrix, size)
        return out

    def fit(self, samples: Iterable[Sample], *, detector: Detector | None = None) -> Model:
        """Derive range bounds (Figure 16) and T (5.2) from annotated samples."""
        from tsrkit_plugins.detectors.tl_recognizer.tl_tuning import fit_model

        return fit_model(self, samples)


@hookimpl
def register_detectors(register):
    register(TlRecognizer)
