"""``hsi-backprojection``: Lee's traffic-light state estimator (5.3.3-5.3.4, Eq. 5.6-5.8).
Trained hue histograms per state and one saturation and one intensity histogram are
back-projected onto the candidate's region, multiplied per pixel, averaged by a circular filter
of the expected lens size, and the most probable state wins; below a threshold it is unknown.
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from pathlib import Path

import cv2
import numpy as np
from scipy.ndimage import gaussian_filter1d

from tsrkit.api import (
    Candidate,
    Classifier,
    Detection,
    Detector,
    Frame,
    Model,
    ModelError,
    Param,
    Sample,
    TsrkitError,
    hookimpl,
    load_model,
)
from tsrkit_plugins.classifiers.decision import UNKNOWN, best_state, fuse_lights
from tsrkit_plugins.classifiers.priors import warm_red
from tsrkit_plugins.shared.regions import (
    clip_box,
    disk_kernel,
    is_housing,
    labelled_lenses,
    region_params,
    rings,
)

DEFAULT_MODEL = Path(__file__).parent / "models" / "hsi_backprojection_default"
#: OpenCV 8-bit HSV ranges: hue 0-179, saturation and value 0-255 (Lee 5.3.3).
HUE_BINS, SV_BINS = 180, 256
#: The hue angle, in degrees, of every OpenCV hue bin.
HUE_ANGLES = np.arange(HUE_BINS) * 2.0


def scaled_histogram(values: np.ndarray, bins: int) -> np.ndarray:
    """Histogram of integer ``values`` in ``[0, bins)`` scaled so its peak is 1 (Lee 5.3.3)."""
    hist = np.bincount(values.ravel().astype(np.int64), minlength=bins)[:bins].astype(np.float32)
    top = hist.max()
    return hist / top if top > 0 else hist


def smooth_hue(hist: np.ndarray, sigma: float) -> np.ndarray:
    """Circular Gaussian smoothing of a hue histogram by ``sigma`` bins (hue 179 neighbours 0),
    rescaled to peak 1; ``sigma`` 0 returns it unchanged."""
    if not sigma:
        return hist
    wrapped = gaussian_filter1d(hist, sigma, mode="wrap")
    return wrapped / wrapped.max()


def lit_pixels(image: np.ndarray, lens: Candidate) -> np.ndarray:
    """HSV pixels of the lens disk, most saturated-and-bright first (shape ``(n, 3)``).

    Lee selects "traffic light pixels"; ranking by saturation x value puts the lit, coloured
    ones first so that a fixed count per sample keeps them.
    """
    area = rings(image, lens.x, lens.y, lens.radius)
    pixels = cv2.cvtColor(area.patch, cv2.COLOR_BGR2HSV)[area.disk]
    order = np.argsort(-(pixels[:, 1].astype(np.int32) * pixels[:, 2]), kind="stable")
    return pixels[order]


def unclipped(pixels: np.ndarray, clip: int) -> np.ndarray:
    """The HSV ``pixels`` (``(n, 3)``, order kept) whose value is below ``clip``, or all of
    them when none is.

    A deviation from Lee 5.3.3, for cameras other than the training one: a clipped pixel's
    hue is the sensor's, not the lamp's (an over-exposed red lamp images orange to
    yellow-white where its red channel saturates), yet the learned I histogram favours exactly
    those brightest pixels.
    """
    below = pixels[:, 2] < clip
    return pixels[below] if below.any() else pixels


def back_project(
    hsv: np.ndarray, hue: np.ndarray, saturation: np.ndarray, intensity: np.ndarray
) -> np.ndarray:
    """Eq. 5.6-5.7: ``P_state = H_state(h) * S(s) * I(v)`` per pixel, shape ``(states, h, w)``."""
    si = saturation[hsv[..., 1]] * intensity[hsv[..., 2]]
    return hue[:, hsv[..., 0]] * si[None]


def expected_diameter(lens_size_m: float, focal_px: float, distance_m: float) -> float:
    """Eq. 5.8: ``d = 2 D f / L`` pixels, D in metres (read as the lens radius, see the class
    docstring), f in pixels, L in metres."""
    if distance_m <= 0 or focal_px <= 0:
        raise ValueError(
            f"Eq. 5.8 needs a positive focal length and distance; got f={focal_px}, L={distance_m}"
        )
    return 2.0 * lens_size_m * focal_px / distance_m


def low_pass(previous: np.ndarray, current: np.ndarray, weight: float) -> np.ndarray:
    """First-order low-pass over frames: ``weight * previous + (1 - weight) * current``."""
    return weight * previous + (1.0 - weight) * current


class HsiBackprojection(Classifier):
    """HSI histogram back-projection (Lee 2017, 5.3.3-5.3.4).

    The region searched is the lens disk's box for a lens candidate and the whole box for a
    housing (Lee's projected ROI); the circular filter's diameter is Eq. 5.8 when the frame's
    metadata carries ``focal_px`` and ``distance_m``, else ``2 * radius`` of the lens (for a
    housing, ``2 * lens_fraction * short side``). Eq. 5.8 as printed, ``d = 2Df/L``, is twice
    the pinhole image of a lens of diameter D, so D is read as the lens *radius*
    (``lens_size_m``: 0.1 for 200 mm lenses, 0.15 for 300 mm).

    ``state_scores`` are the filtered maxima of ``P_state``. With ``lowpass`` > 0 they are
    smoothed over consecutive frames of one source (each candidate follows the nearest
    candidate of the previous frame within two radii); with ``fuse`` every candidate of a frame
    is taken as a light of one approach and gets the fused state (Lee 5.3.4).
    """

    name = "hsi-backprojection"
    summary = "HSI histogram back-projection with a lens-sized circular filter (trainable)"
    section = "Lee 2017, 5.3.3-5.3.4 Eq. 5.6-5.8"
    PARAMS = (
        Param(
            "model",
            "path",
            None,
            help="trained model (.npz); unset: the shipped default "
            "trained on udacity_mit_tl_crops train",
        ),
        Param(
            "pixels_per_sample",
            "int",
            0,
            min=0,
            help="lit pixels taken from each training "
            "sample; 0: the smallest lens of the training set (Lee 5.3.3)",
            section="5.3.3",
        ),
        Param(
            "hue_smooth",
            "float",
            8.0,
            min=0.0,
            max=30.0,
            help="circular Gaussian sigma, "
            "in hue bins, applied to the trained hue histograms (0: Lee's raw histograms)",
        ),
        Param(
            "clip",
            "int",
            250,
            min=1,
            max=SV_BINS,
            help="pixels whose HSV value "
            "(brightest channel, 0-255) reaches this count as sensor-clipped and get "
            "probability 0 unless nothing else is lit; training leaves them out likewise "
            "(256: every pixel, as Lee does; see unclipped())",
        ),
        Param(
            "red_prior",
            "bool",
            True,
            help="warm-red prior: hues between the trained red "
            "and yellow modes count as red (see priors.py); off: Lee's histograms as trained",
        ),
        Param(
            "threshold",
            "float",
            0.0,
            min=0.0,
            max=1.0,
            help="unknown when the best state's probability is below this (t of 5.3.4)",
            section="5.3.4",
        ),
        Param(
            "lens_size_m",
            "float",
            0.15,
            min=0.0,
            help="D of Eq. 5.8 in metres (lens "
            "radius), used with frame metadata focal_px and distance_m",
            section="Eq. 5.8",
        ),
        Param(
            "lowpass",
            "float",
            0.0,
            min=0.0,
            max=0.99,
            help="weight of the previous frame's probabilities (0: off)",
            section="5.3.4",
        ),
        Param(
            "fuse",
            "bool",
            False,
            help="fuse the candidates of a frame as lights of one "
            "approach: consensus, else the most probable, else unknown",
            section="5.3.4",
        ),
    ) + region_params(lens_fraction=0.3)

    def __init__(self, **params):
        super().__init__(**params)
        self._model: Model | None = None
        self._previous: tuple[str, int, list[tuple[Candidate, np.ndarray]]] | None = None

    @property
    def model(self) -> Model:
        """The trained histograms, loaded on first use (the hue histograms under the warm-red
        prior when ``red_prior`` is set)."""
        if self._model is None:
            path = self.params["model"] or DEFAULT_MODEL
            model = load_model(path, plugin=self.name)
            shapes = {k: v.shape for k, v in model.arrays.items()}
            if (
                shapes.get("hue") != (len(self.states), HUE_BINS)
                or shapes.get("saturation") != (SV_BINS,)
                or shapes.get("intensity") != (SV_BINS,)
            ):
                raise ModelError(
                    f"model {path}: expected hue ({len(self.states)}, {HUE_BINS}), "
                    f"saturation and intensity ({SV_BINS},); got {shapes}"
                )
            if self.params["red_prior"]:
                hue = model.arrays["hue"].copy()
                red, yellow = self.states.index("red"), self.states.index("yellow")
                hue[red], hue[yellow] = warm_red(hue[red], hue[yellow], HUE_ANGLES)
                model = Model({**model.arrays, "hue": hue}, model.info, model.meta)
            self._model = model
        return self._model

    def filter_diameter(self, frame: Frame, candidate: Candidate, housing: bool) -> float:
        """The circular filter's diameter in pixels for ``candidate``."""
        meta = frame.metadata
        if meta.get("focal_px") and meta.get("distance_m"):
            return expected_diameter(
                self.params["lens_size_m"], float(meta["focal_px"]), float(meta["distance_m"])
            )
        if housing:
            x0, y0, x1, y1 = candidate.bbox
            return 2 * self.params["lens_fraction"] * min(x1 - x0, y1 - y0)
        return 2 * candidate.radius

    def probabilities(self, frame: Frame, candidate: Candidate) -> np.ndarray:
        """The filtered maximum of ``P_state`` over the candidate's region, per state, with
        pixels of value >= ``clip`` weighted 0 unless that leaves every probability 0 (see
        :func:`unclipped`)."""
        housing = is_housing(candidate, self.params["region"], self.params["elongation"])
        bbox = (
            candidate.bbox
            if housing
            else (
                candidate.x - candidate.radius,
                candidate.y - candidate.radius,
                candidate.x + candidate.radius,
                candidate.y + candidate.radius,
            )
        )
        x0, y0, x1, y1 = clip_box(bbox, frame.width, frame.height)
        hsv = cv2.cvtColor(frame.image[y0:y1, x0:x1], cv2.COLOR_BGR2HSV)
        arrays = self.model.arrays
        kernel = disk_kernel(self.filter_diameter(frame, candidate, housing) / 2)
        clip = self.params["clip"]
        for cut in (clip, SV_BINS) if clip < SV_BINS else (SV_BINS,):
            intensity = arrays["intensity"].copy()
            intensity[cut:] = 0  # clipped pixels out, unless nothing else is lit
            maps = back_project(hsv, arrays["hue"], arrays["saturation"], intensity)
            probs = np.array(
                [cv2.filter2D(m, -1, kernel, borderType=cv2.BORDER_CONSTANT).max() for m in maps]
            )
            if probs.any():
                break
        return probs

    def smoothed(
        self, frame: Frame, candidates: Sequence[Candidate], current: list[np.ndarray]
    ) -> list[np.ndarray]:
        """Apply the low-pass filter against the previous frame of the same source."""
        weight = self.params["lowpass"]
        previous = self._previous
        self._previous = (frame.source, frame.index, list(zip(candidates, current)))
        if (
            not weight
            or previous is None
            or previous[0] != frame.source
            or previous[1] != frame.index - 1
        ):
            return current
        out = []
        for candidate, probs in zip(candidates, current):
            near = [
                (np.hypot(c.x - candidate.x, c.y - candidate.y), p)
                for c, p in previous[2]
                if np.hypot(c.x - candidate.x, c.y - candidate.y) <= 2 * candidate.radius
            ]
            out.append(low_pass(min(near, key=lambda n: n[0])[1], probs, weight) if near else probs)
        self._previous = (frame.source, frame.index, list(zip(candidates, out)))
        return out

    def classify(self, frame: Frame, candidates: Sequence[Candidate]) -> list[Detection]:
        probs = self.smoothed(frame, candidates, [self.probabilities(frame, c) for c in candidates])
        threshold = self.params["threshold"]
        scores = [dict(zip(self.states, map(float, p))) for p in probs]
        states = [best_state(s) if max(s.values()) >= threshold else UNKNOWN for s in scores]
        if self.params["fuse"]:
            fused = fuse_lights([(st, max(s.values())) for st, s in zip(states, scores)], threshold)
            states = [fused] * len(states)
        return [Detection(c, st, s) for c, st, s in zip(candidates, states, scores)]

    def fit(self, samples: Iterable[Sample], *, detector: Detector | None = None) -> Model:
        """Hue histograms per state and shared S and I histograms from an equal number of lit
        pixels per labelled lens (Lee 5.3.3); deterministic."""
        taken = [
            (state, lit_pixels(frame.image, lens))
            for state, frame, lens in labelled_lenses(samples, self.states, self.params)
        ]
        if not taken:
            raise TsrkitError(
                "hsi-backprojection: no training samples with a red, yellow or green label"
            )
        count = self.params["pixels_per_sample"] or min(len(p) for _, p in taken)
        kept = [(st, unclipped(p, self.params["clip"])[:count]) for st, p in taken]
        pixels = {
            s: np.concatenate([p for st, p in kept if st == s] or [np.zeros((0, 3), np.uint8)])
            for s in self.states
        }
        missing = [s for s in self.states if not len(pixels[s])]
        if missing:
            raise TsrkitError(f"hsi-backprojection: no training samples for {', '.join(missing)}")
        every = np.concatenate(list(pixels.values()))
        hue = [
            smooth_hue(scaled_histogram(pixels[s][:, 0], HUE_BINS), self.params["hue_smooth"])
            for s in self.states
        ]
        return Model(
            arrays={
                "hue": np.stack(hue),
                "saturation": scaled_histogram(every[:, 1], SV_BINS),
                "intensity": scaled_histogram(every[:, 2], SV_BINS),
            },
            info={
                "states": list(self.states),
                "pixels_per_sample": int(count),
                "samples": len(taken),
            },
        )


@hookimpl
def register_classifiers(register):
    register(HsiBackprojection)
