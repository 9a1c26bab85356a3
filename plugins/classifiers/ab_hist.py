"""``ab-hist``: Zheng's state classifier (3.3, Eq. 3.16-3.20; 5.3). A candidate's CIELab a-b
histograms over its lens disk A1 and annulus A3 are matched by angle against one trained
histogram per colour; the best match wins, and a low discriminative ratio gives ``unknown``.
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from pathlib import Path

import cv2
import numpy as np

from tsrkit.errors import TsrkitError
from tsrkit.hookspecs import hookimpl
from tsrkit.models import Model, ModelError, load_model
from tsrkit.params import Param
from tsrkit.plugin import Classifier, Detector
from tsrkit.types import Candidate, Detection, Frame, Sample
from tsrkit_plugins.classifiers.decision import UNKNOWN, best_state, discriminative_ratio
from tsrkit_plugins.classifiers.priors import warm_red
from tsrkit_plugins.classifiers.regions import labelled_lenses, lens_of, region_params, rings

DEFAULT_MODEL = Path(__file__).parent / "models" / "ab_hist_default"
MODES = ("max", "saturation")


def ab_histogram(lab: np.ndarray, mask: np.ndarray, bins: int) -> np.ndarray:
    """Eq. 3.16-3.18: the a-b histogram of the masked pixels, divided by their count.

    ``lab`` is OpenCV's 8-bit CIELab (a and b offset by 128, range 0-255); each axis is cut
    into ``bins`` equal bins. An empty mask gives an all-zero histogram.
    """
    count = int(np.count_nonzero(mask))
    hist = cv2.calcHist([lab], [1, 2], mask.astype(np.uint8), [bins, bins], [0, 256, 0, 256])
    return hist / count if count else hist


def smooth_histogram(h: np.ndarray, sigma: float) -> np.ndarray:
    """Gaussian blur of a histogram by ``sigma`` bins (0: unchanged), so that nearby a-b
    colours of another camera still overlap the trained ones."""
    return cv2.GaussianBlur(h, (0, 0), sigma, borderType=cv2.BORDER_CONSTANT) if sigma else h


def bin_angles(bins: int) -> np.ndarray:
    """The a-b hue angle, in degrees [0, 360), of every bin centre of a ``bins`` x ``bins``
    histogram (a along rows, b along columns)."""
    centre = (np.arange(bins) + 0.5) * 256.0 / bins - 128.0
    return np.mod(np.degrees(np.arctan2(centre[None, :], centre[:, None])), 360.0)


def similarity(h: np.ndarray, h_ref: np.ndarray) -> float:
    """Eq. 3.20: ``1 - 2 acos(cosine(h, h_ref)) / pi``, in [0, 1] for histograms; 0 when
    either histogram is empty."""
    norm = float(np.linalg.norm(h) * np.linalg.norm(h_ref))
    if norm == 0:
        return 0.0
    cosine = float(np.clip(np.sum(h * h_ref) / norm, -1.0, 1.0))
    return float(1.0 - 2.0 * np.arccos(cosine) / np.pi)


def mean_saturation(hsv: np.ndarray, mask: np.ndarray) -> float:
    """Mean HSV saturation of the masked pixels (0 for an empty mask)."""
    return float(hsv[..., 1][mask].mean()) if mask.any() else 0.0


def chroma(lab: np.ndarray) -> np.ndarray:
    """CIELab chroma ``sqrt(a^2 + b^2)`` of OpenCV 8-bit Lab (a, b offset by 128)."""
    a = lab[..., 1].astype(np.float32) - 128
    b = lab[..., 2].astype(np.float32) - 128
    return np.sqrt(a * a + b * b)


def lens_histograms(
    image: np.ndarray, lens: Candidate, bins: int, min_chroma: float, sigma: float
) -> tuple[np.ndarray, np.ndarray, bool]:
    """The A1 and A3 histograms of ``lens`` over its pixels of at least ``min_chroma``,
    smoothed by ``sigma`` bins, and whether A1 is the more saturated area."""
    area = rings(image, lens.x, lens.y, lens.radius)
    lab = cv2.cvtColor(area.patch, cv2.COLOR_BGR2LAB)
    hsv = cv2.cvtColor(area.patch, cv2.COLOR_BGR2HSV)
    a1_saturated = mean_saturation(hsv, area.disk) >= mean_saturation(hsv, area.annulus)
    coloured = chroma(lab) >= min_chroma
    return (
        smooth_histogram(ab_histogram(lab, area.disk & coloured, bins), sigma),
        smooth_histogram(ab_histogram(lab, area.annulus & coloured, bins), sigma),
        a1_saturated,
    )


def colour_score(
    a1: np.ndarray, a3: np.ndarray, a1_saturated: bool, trained: np.ndarray, mode: str
) -> float:
    """Eq. 3.19 under either reading: the better of the A1 and A3 matches (``max``, the
    equation as printed) or the match of the more saturated area (``saturation``, the prose
    under it)."""
    if mode == "max":
        return max(similarity(a1, trained), similarity(a3, trained))
    return similarity(a1 if a1_saturated else a3, trained)


class AbHist(Classifier):
    """CIELab a-b histogram matching (Zheng 2016, 3.3).

    Training keeps, per colour, the mean of the samples' histograms of the more saturated of
    A1 and A3 (Zheng trains on the single annotated area holding the colour; this picks it by
    the same saturation rule as Eq. 3.19's prose). ``state_scores`` are the Eq. 3.19 scores;
    the confidence is their maximum and the discriminative ratio ``1 - min/max`` (5.3).
    """

    name = "ab-hist"
    summary = "CIELab a-b histogram angle matching of lens disk and annulus (trainable)"
    section = "Zheng 2016, 3.3 Eq. 3.16-3.20, 5.3"
    params = (
        Param(
            "model",
            "path",
            None,
            help="trained model (.npz); unset: the shipped default "
            "trained on udacity_mit_tl_crops train",
        ),
        Param(
            "bins",
            "int",
            32,
            min=2,
            max=256,
            help="bins per axis of the a-b histogram "
            "(used when training; a loaded model brings its own)",
            section="Eq. 3.18",
        ),
        Param(
            "mode",
            "str",
            "saturation",
            choices=MODES,
            help="Eq. 3.19 reading: max over A1/A3, or the more saturated area",
            section="Eq. 3.19",
        ),
        Param(
            "min_chroma",
            "float",
            10.0,
            min=0.0,
            max=180.0,
            help="leave pixels of lower "
            "CIELab chroma (grey housing, white-hot centres) out of the histograms; 0 keeps "
            "every pixel as Zheng does",
        ),
        Param(
            "smooth",
            "float",
            3.0,
            min=0.0,
            max=16.0,
            help="Gaussian sigma, in bins, "
            "applied to every histogram before matching; 0 matches raw histograms as Zheng "
            "does",
        ),
        Param(
            "red_prior",
            "bool",
            True,
            help="warm-red prior: a-b angles between the trained "
            "red and yellow modes count as red (see priors.py); off: Zheng's histograms as "
            "trained",
        ),
        Param(
            "min_ratio",
            "float",
            0.0,
            min=0.0,
            max=1.0,
            help="discriminative ratio below which the state is unknown",
            section="5.3",
        ),
    ) + region_params(lens_fraction=0.4)

    def __init__(self, **params):
        super().__init__(**params)
        self._trained: np.ndarray | None = None

    @property
    def trained(self) -> np.ndarray:
        """The trained histograms, one per state, loaded on first use (with the warm-red
        prior applied when ``red_prior`` is set)."""
        if self._trained is None:
            model = load_model(self.params["model"] or DEFAULT_MODEL, plugin=self.name)
            hist = model.arrays.get("histograms")
            if hist is None or hist.ndim != 3 or hist.shape[0] != len(self.states):
                raise ModelError(
                    f"model {self.params['model'] or DEFAULT_MODEL}: expected "
                    f"'histograms' of shape ({len(self.states)}, bins, bins)"
                )
            if self.params["red_prior"]:
                red, yellow = self.states.index("red"), self.states.index("yellow")
                hist = hist.copy()
                hist[red], hist[yellow] = warm_red(
                    hist[red], hist[yellow], bin_angles(hist.shape[1])
                )
            self._trained = hist
        return self._trained

    def scores(self, image: np.ndarray, lens: Candidate) -> dict[str, float]:
        """Eq. 3.19 score of every colour for one lens."""
        trained = self.trained
        a1, a3, a1_saturated = lens_histograms(
            image, lens, trained.shape[1], self.params["min_chroma"], self.params["smooth"]
        )
        return {
            state: colour_score(a1, a3, a1_saturated, trained[i], self.params["mode"])
            for i, state in enumerate(self.states)
        }

    def classify(self, frame: Frame, candidates: Sequence[Candidate]) -> list[Detection]:
        out = []
        for candidate in candidates:
            scores = self.scores(frame.image, lens_of(frame.image, candidate, self.params))
            state = best_state(scores)
            if discriminative_ratio(scores) < self.params["min_ratio"]:
                state = UNKNOWN
            out.append(Detection(candidate, state, scores))
        return out

    def fit(self, samples: Iterable[Sample], *, detector: Detector | None = None) -> Model:
        """Mean histogram per colour over the labelled lenses of ``samples`` (deterministic)."""
        bins = self.params["bins"]
        sums = np.zeros((len(self.states), bins, bins), np.float64)
        counts = np.zeros(len(self.states), np.int64)
        for state, frame, lens in labelled_lenses(samples, self.states, self.params):
            a1, a3, a1_saturated = lens_histograms(
                frame.image, lens, bins, self.params["min_chroma"], self.params["smooth"]
            )
            i = self.states.index(state)
            sums[i] += a1 if a1_saturated else a3
            counts[i] += 1
        missing = [s for s, n in zip(self.states, counts) if n == 0]
        if missing:
            raise TsrkitError(f"ab-hist: no training samples for {', '.join(missing)}")
        return Model(
            arrays={
                "histograms": (sums / counts[:, None, None]).astype(np.float32),
                "counts": counts,
            },
            info={"states": list(self.states), "bins": bins},
        )


@hookimpl
def register_classifiers(register):
    register(AbHist)
