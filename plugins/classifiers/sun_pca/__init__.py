"""``sun-pca``: Lee's Sun-position-compensated colour model (2017, 4.3) as a classifier (which
target colour a candidate shows) and as a detector (probability map, threshold, morphology,
components, shape filtering), both reading one trained model (:mod:`.model`).

A frame's relative azimuth comes from its metadata, the run's parameters or a GPS log
(:mod:`tsrkit.sun.relative`); a frame without them is read by the uncompensated form of the model
and says so in its record's notes, which the report counts.
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from functools import cached_property
from pathlib import Path

import cv2
import numpy as np

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
    Track,
    TsrkitError,
    frame_facts,
    hookimpl,
    load_model,
    read_track,
    sun_view,
)
from tsrkit_plugins.classifiers.sun_pca.model import BIN_EDGES, fit_target, probability
from tsrkit_plugins.shared.regions import labelled_lenses, lens_of, region_params

DEFAULT_MODEL = Path(__file__).parent / "models" / "sun_pca_default"
FALLBACK_NOTE = "sun-pca: no Sun facts (time, position, heading); uncompensated model"
SECTION = "Lee 2017, 4.3 (4.1.1 geometry, 4.2 relative azimuth)"
#: The model's arrays, each stacked over targets then regimes.
ARRAYS = ("mean", "axis", "coef", "offset", "v_a", "v_d", "v_a0", "v_d0")

SUN_PARAMS = (
    Param("model", "path", None,
          help="trained model (tsrkit train sun-pca); unset: the shipped default, trained on "
          "rendered Sun-lit scenes (orange work-zone and red stop signs)"),
    Param("targets", "str", "orange,red",
          help="target colours to learn, comma-separated annotation states (training only)"),
    Param("saturation", "float", 250.0, min=1.0, max=255.0, section="4.3, Figure 4.7",
          help="red level from which a pixel is on the saturated (surface reflection) line"),
    Param("compensate", "bool", True,
          help="use the Sun's relative azimuth; off: the uncompensated model on every frame"),
    Param("utc", "str", None, help="time of every frame (ISO 8601 with zone, or UTC seconds)"),
    Param("start_utc", "str", None,
          help="time of a video's first frame; the frame's timestamp is added"),
    Param("lat", "float", None, min=-90.0, max=90.0, help="camera latitude, degrees"),
    Param("lon", "float", None, min=-180.0, max=180.0, help="camera longitude, degrees"),
    Param("heading_deg", "float", None, min=-360.0, max=360.0,
          help="viewing direction, degrees clockwise from north"),
    Param("relative_azimuth_deg", "float", None, min=0.0, max=180.0, section="4.2",
          help="the Sun's relative azimuth itself (0: Sun behind the camera)"),
    Param("gps", "path", None,
          help="GPS log (CSV or the whitespace format) giving position and heading by time"),
)  # fmt: skip


class SunModelMixin:
    """What the classifier and detector share: the model, and a frame's relative azimuth."""

    name = "sun-pca"
    section = SECTION
    params: dict
    notes: tuple[str, ...] = ()

    @cached_property
    def model(self) -> Model:
        path = self.params["model"] or DEFAULT_MODEL
        model = load_model(path, plugin="sun-pca")
        targets = model.info.get("targets")
        if not targets or any(model.arrays.get(k) is None for k in ARRAYS):
            raise ModelError(f"model {path}: not a sun-pca model (needs targets and {ARRAYS})")
        if any(len(model.arrays[k]) != len(targets) for k in ARRAYS):
            raise ModelError(f"model {path}: arrays do not match its {len(targets)} targets")
        return model

    @cached_property
    def track(self) -> Track | None:
        return read_track(self.params["gps"]) if self.params["gps"] else None

    def target(self, name: str) -> dict[str, np.ndarray]:
        """The fitted lines of target ``name``."""
        i = list(self.model.info["targets"]).index(name)
        return {k: self.model.arrays[k][i] for k in ARRAYS}

    def relative_azimuth(self, frame: Frame) -> float | None:
        """The frame's relative azimuth, or None (uncompensated); sets :attr:`notes`."""
        view = None
        if self.params["compensate"]:
            view = sun_view(frame_facts(frame.metadata, frame.timestamp, self.params, self.track))
        self.notes = () if view is not None or not self.params["compensate"] else (FALLBACK_NOTE,)
        return None if view is None else view.relative_azimuth

    def probabilities(self, image: np.ndarray, alpha: float | None) -> dict[str, np.ndarray]:
        """Every target's probability over ``image`` (or a patch)."""
        return {
            name: probability(image, self.target(name), alpha, self.params["saturation"])
            for name in self.model.info["targets"]
        }


def core_pixels(image: np.ndarray, lens: Candidate, fraction: float) -> np.ndarray:
    """The pixels within ``fraction`` of the lens radius of its centre (at least the centre)."""
    h, w = image.shape[:2]
    r = max(fraction * lens.radius, 0.5)
    x0, x1 = max(int(lens.x - r), 0), min(int(np.ceil(lens.x + r)) + 1, w)
    y0, y1 = max(int(lens.y - r), 0), min(int(np.ceil(lens.y + r)) + 1, h)
    yy, xx = np.mgrid[y0:y1, x0:x1]
    inside = (xx + 0.5 - lens.x) ** 2 + (yy + 0.5 - lens.y) ** 2 <= r * r
    patch = image[y0:y1, x0:x1][inside]
    if len(patch) == 0:
        cy, cx = min(max(int(lens.y), 0), h - 1), min(max(int(lens.x), 0), w - 1)
        patch = image[cy : cy + 1, cx : cx + 1].reshape(-1, 3)
    return patch


def coloured(pixels: np.ndarray) -> np.ndarray:
    """The pixels of some colour and light (HSV S >= 60, V >= 40): legends, borders and dark
    housings are left out of training."""
    hsv = cv2.cvtColor(pixels.reshape(-1, 1, 3), cv2.COLOR_BGR2HSV).reshape(-1, 3)
    return pixels[(hsv[:, 1] >= 60) & (hsv[:, 2] >= 40)]


class SunPcaClassifier(SunModelMixin, Classifier):
    """Which target colour a candidate shows: the mean target probability over its core."""

    summary = "Sun-compensated PCA colour model: the candidate's target colour (trainable)"
    states: tuple[str, ...] = ()
    PARAMS = SUN_PARAMS + (
        Param("core", "float", 0.8, min=0.1, max=1.0,
              help="fraction of the lens radius whose pixels are read"),
        Param("min_score", "float", 0.05, min=0.0, max=1.0,
              help="mean probability below which the state is unknown"),
    ) + region_params(lens_fraction=0.4)  # fmt: skip

    def classify(self, frame: Frame, candidates: Sequence[Candidate]) -> list[Detection]:
        self.states = tuple(self.model.info["targets"])
        alpha = self.relative_azimuth(frame)
        out = []
        for candidate in candidates:
            lens = lens_of(frame.image, candidate, self.params)
            pixels = core_pixels(frame.image, lens, self.params["core"])
            scores = {k: float(v.mean()) for k, v in self.probabilities(pixels, alpha).items()}
            state = max(scores, key=scores.__getitem__)
            if scores[state] < self.params["min_score"]:
                state = "unknown"
            out.append(Detection(candidate, state, scores))
        return out

    def fit(self, samples: Iterable[Sample], *, detector: Detector | None = None) -> Model:
        """PCA lines per target and regime from the coloured core pixels of every annotated
        target; frames without Sun facts train the uncompensated form only (counted in the
        model's ``info``).

        Raises
        ------
        ValueError
            When a target has too few pixels.
        """
        targets = tuple(t.strip() for t in self.params["targets"].split(",") if t.strip())
        pixels: dict[str, list[np.ndarray]] = {t: [] for t in targets}
        angles: dict[str, list[np.ndarray]] = {t: [] for t in targets}
        alphas: dict[str, float | None] = {}
        for state, frame, lens in labelled_lenses(samples, targets, self.params):
            if frame.source not in alphas:
                alphas[frame.source] = self.relative_azimuth(frame)
            angle = alphas[frame.source]
            found = coloured(core_pixels(frame.image, lens, self.params["core"]))
            pixels[state].append(found.astype(np.float64))
            angles[state].append(np.full(len(found), np.nan if angle is None else angle))
        fitted = []
        for t in targets:
            try:
                fitted.append(
                    fit_target(
                        np.concatenate(pixels[t]) if pixels[t] else np.zeros((0, 3)),
                        np.concatenate(angles[t]) if angles[t] else np.zeros(0),
                        self.params["saturation"],
                    )
                )
            except ValueError as exc:
                raise TsrkitError(f"sun-pca: target '{t}': {exc}") from None
        arrays = {k: np.stack([f[k] for f in fitted]) for k in ARRAYS}
        return Model(
            arrays=arrays,
            info={
                "targets": list(targets),
                "bin_edges_deg": BIN_EDGES.tolist(),
                "frames_with_sun": sum(a is not None for a in alphas.values()),
                "frames_without_sun": sum(a is None for a in alphas.values()),
                "compensated": bool(np.any(arrays["coef"][:, :, 1])),
            },
        )


class SunPcaDetector(SunModelMixin, Detector):
    """Lee 4.3's detector: target probability per pixel, threshold, morphology, connected
    components, then the segment's probability, size, ratio and fill (shape) decide."""

    summary = "Sun-compensated PCA colour model: regions of a target colour (e.g. work-zone orange)"
    PARAMS = SUN_PARAMS + (
        Param("target", "str", "orange", help="the target colour to detect (a model target)"),
        Param("pixel_threshold", "float", 0.45, min=0.0, max=1.0,
              help="pixel probability from which a pixel is of the target colour"),
        Param("segment_threshold", "float", 0.35, min=0.0, max=1.0,
              help="mean probability a segment needs"),
        Param("open_size", "int", 3, min=1, max=31, help="morphological opening, pixels"),
        Param("close_size", "int", 21, min=1, max=41, help="morphological closing, pixels"),
        Param("min_area", "int", 60, min=1, help="smallest segment, pixels"),
        Param("min_aspect", "float", 0.6, min=0.05, max=1.0,
              help="smallest width/height and height/width ratio of a segment's box"),
        Param("min_fill", "float", 0.35, min=0.0, max=1.0,
              help="smallest share of its box a segment fills"),
    )  # fmt: skip

    def detect(self, frame: Frame) -> list[Candidate]:
        name = self.params["target"]
        if name not in self.model.info["targets"]:
            raise ModelError(f"sun-pca: target '{name}' not in model {self.model.info['targets']}")
        alpha = self.relative_azimuth(frame)
        p = probability(frame.image, self.target(name), alpha, self.params["saturation"])
        mask = (p >= self.params["pixel_threshold"]).astype(np.uint8)
        for op, size in ((cv2.MORPH_OPEN, "open_size"), (cv2.MORPH_CLOSE, "close_size")):
            kernel = cv2.getStructuringElement(cv2.MORPH_ELLIPSE, (self.params[size],) * 2)
            mask = cv2.morphologyEx(mask, op, kernel)
        count, labels, stats, _ = cv2.connectedComponentsWithStats(mask, connectivity=8)
        found = []
        for k in range(1, count):
            x, y, w, h, area = (int(v) for v in stats[k])
            score = float(p[labels == k].mean())
            if (
                area < self.params["min_area"]
                or score < self.params["segment_threshold"]
                or min(w / h, h / w) < self.params["min_aspect"]
                or area / (w * h) < self.params["min_fill"]
            ):
                continue
            found.append(Candidate.from_box((x, y, x + w, y + h), score, state=name))
        return sorted(found, key=lambda c: -c.score)


@hookimpl
def register_classifiers(register):
    register(SunPcaClassifier)


@hookimpl
def register_detectors(register):
    register(SunPcaDetector)
