"""``ab-hist``: Zheng's state classifier (3.3, Eq. 3.16-3.20; 5.3). A candidate's CIELab a-b
histograms over its lens disk A1 and annulus A3 are matched by angle against one trained
histogram per colour; the best match wins, and a low discriminative ratio gives ``unknown``.
"""

from __future__ import annotations

import functools
from collections.abc import Iterable, Sequence
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
    TsrkitError,
    hookimpl,
    load_model,
)
from tsrkit_plugins.classifiers.decision import UNKNOWN, best_state, discriminative_ratio
from tsrkit_plugins.classifiers.priors import warm_red
from tsrkit_plugins.shared.regions import (
    labelled_lenses,
    lens_of,
    region_params,
    ring_runs,
)

DEFAULT_MODEL = Path(__file__).parent / "models" / "ab_hist_default"
MODES = ("max", "saturation")


@functools.lru_cache(maxsize=16)
def ab_cells(bins: int, min_chroma: float) -> np.ndarray:
    """The histogram cell of every 8-bit CIELab (a, b) pair, indexed ``256 a + b``.

    A pair in a-bin ``i`` and b-bin ``j`` (each axis cut into ``bins`` equal bins, as
    ``cv2.calcHist`` does: bin ``floor(v * bins / 256)``) has cell ``bins * i + j``; a pair of
    chroma below ``min_chroma`` has the spare cell ``bins * bins``, counted nowhere.
    """
    a, b = np.divmod(np.arange(65536), 256)
    lab = np.column_stack([np.zeros_like(a), a, b]).astype(np.uint8)
    index = (np.arange(256) * bins) // 256
    cell = np.where(chroma(lab) >= min_chroma, index[a] * bins + index[b], bins * bins)
    cell.flags.writeable = False
    return cell


def ab_histograms(cells: np.ndarray, region: np.ndarray, n: int, bins: int) -> np.ndarray:
    """Eq. 3.16-3.18: the a-b histogram of each of ``n`` regions, divided by its pixel count.

    ``cells`` (P,) is the :func:`ab_cells` cell of each pixel (``bins * bins``: not counted)
    and ``region`` (P,) its region (0 to n - 1). An empty region gives an all-zero histogram.

    Returns
    -------
    ndarray of shape (n, bins, bins), float32 (a along rows, b along columns)
    """
    per = bins * bins + 1
    counts = np.bincount(region * per + cells, minlength=n * per).reshape(n, per)[:, :-1]
    total = counts.sum(axis=1).astype(np.float32)[:, None, None]
    hist = counts.astype(np.float32).reshape(n, bins, bins)
    return np.divide(hist, total, out=hist, where=total > 0)


def smooth_histograms(h: np.ndarray, sigma: float) -> np.ndarray:
    """Gaussian blur of each histogram of ``h`` (N, bins, bins) by ``sigma`` bins (0:
    unchanged), so that nearby a-b colours of another camera still overlap the trained ones.

    One ``cv2.GaussianBlur`` over the histograms stacked with rows of zeros between them, wider
    than the kernel's reach, which are what the zero (constant) border gives each alone.
    """
    if not sigma:
        return h
    n, rows, cols = h.shape
    gap = int(np.ceil(4 * sigma)) + 1  # OpenCV's float kernel reaches round(4 sigma) bins
    stacked = np.zeros((n, rows + gap, cols), np.float32)
    stacked[:, :rows] = h
    blurred = cv2.GaussianBlur(
        stacked.reshape(-1, cols), (0, 0), sigma, borderType=cv2.BORDER_CONSTANT
    )
    return blurred.reshape(n, rows + gap, cols)[:, :rows]


def bin_angles(bins: int) -> np.ndarray:
    """The a-b hue angle, in degrees [0, 360), of every bin centre of a ``bins`` x ``bins``
    histogram (a along rows, b along columns)."""
    centre = (np.arange(bins) + 0.5) * 256.0 / bins - 128.0
    return np.mod(np.degrees(np.arctan2(centre[None, :], centre[:, None])), 360.0)


def similarities(h: np.ndarray, refs: np.ndarray) -> np.ndarray:
    """Eq. 3.20: ``1 - 2 acos(cosine(h, h_ref)) / pi`` of every histogram of ``h`` (N, ...)
    against every one of ``refs`` (S, ...), in [0, 1] for histograms; 0 when either is empty.

    Returns
    -------
    ndarray of shape (N, S), float64
    """
    flat = h.reshape(len(h), -1)
    ref = refs.reshape(len(refs), -1)
    norm = np.outer([np.sqrt(v.dot(v)) for v in flat], [np.sqrt(v.dot(v)) for v in ref]).astype(
        h.dtype
    )
    dot = (flat[:, None, :] * ref[None, :, :]).sum(axis=-1)
    cosine = np.clip(np.divide(dot, norm, out=np.zeros_like(dot), where=norm != 0), -1.0, 1.0)
    angle = np.arccos(cosine.astype(np.float64))
    return np.where(norm != 0, 1.0 - 2.0 * angle / np.pi, 0.0)


def mean_saturations(saturation: np.ndarray, region: np.ndarray, n: int) -> np.ndarray:
    """Mean HSV saturation (uint8) of the pixels of each of ``n`` regions (0 for an empty
    one), from each region's histogram of the 256 levels (integer sums: exact)."""
    hist = np.bincount(region * 256 + saturation, minlength=n * 256).reshape(n, 256)
    count = hist.sum(axis=1)
    return np.divide(hist @ np.arange(256), count, out=np.zeros(n), where=count > 0)


def chroma(lab: np.ndarray) -> np.ndarray:
    """CIELab chroma ``sqrt(a^2 + b^2)`` of OpenCV 8-bit Lab (a, b offset by 128)."""
    a = lab[..., 1].astype(np.float32) - 128
    b = lab[..., 2].astype(np.float32) - 128
    return np.sqrt(a * a + b * b)


def lens_histograms(
    image: np.ndarray, lenses: Sequence[Candidate], bins: int, min_chroma: float
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The A1 and A3 histograms of every lens over its pixels of at least ``min_chroma``, and
    whether A1 is the more saturated area.

    The pixels of all lenses' areas are gathered into one row and converted to Lab and HSV
    once (a per-pixel conversion: the same values as area by area).

    Returns
    -------
    tuple of ndarray
        A1 and A3 histograms, each (N, bins, bins), and a boolean (N,).
    """
    if image.ndim == 2:
        image = cv2.cvtColor(image, cv2.COLOR_GRAY2BGR)
    n = len(lenses)
    area = ring_runs(image, [(c.x, c.y, c.radius) for c in lenses])
    run, offset = area.pixels()
    region = (area.owner * 2 + area.annulus).take(run)  # A1 of lens i: 2i, A3: 2i + 1
    where = (area.row * image.shape[1] + area.col).take(run) + offset
    pixels = np.take(image.reshape(-1, image.shape[2]), where, axis=0)[None]  # BGR or BGRA
    lab = cv2.cvtColor(pixels, cv2.COLOR_BGR2LAB)[0]
    saturation = mean_saturations(cv2.cvtColor(pixels, cv2.COLOR_BGR2HSV)[0][:, 1], region, 2 * n)
    ab = (lab[:, 1].astype(np.intp) << 8) | lab[:, 2]
    hist = ab_histograms(ab_cells(bins, min_chroma).take(ab), region, 2 * n, bins)
    return hist[0::2], hist[1::2], saturation[0::2] >= saturation[1::2]


def colour_scores(
    a1: np.ndarray,
    a3: np.ndarray,
    a1_saturated: np.ndarray,
    trained: np.ndarray,
    mode: str,
    sigma: float,
) -> np.ndarray:
    """Eq. 3.19 under either reading, (N, states), on the histograms smoothed by ``sigma``
    bins: the better of the A1 and A3 matches (``max``, the equation as printed) or the
    match of the more saturated area (``saturation``, the prose under it)."""
    if mode == "max":
        both = smooth_histograms(np.concatenate([a1, a3]), sigma)
        return np.maximum(
            similarities(both[: len(a1)], trained), similarities(both[len(a1) :], trained)
        )
    return similarities(smooth_histograms(saturated_area(a1, a3, a1_saturated), sigma), trained)


def saturated_area(a1: np.ndarray, a3: np.ndarray, a1_saturated: np.ndarray) -> np.ndarray:
    """The histogram of the more saturated of A1 and A3, lens by lens."""
    return np.where(a1_saturated[:, None, None], a1, a3)


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
    PARAMS = (
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

    def scores(self, image: np.ndarray, lenses: Sequence[Candidate]) -> np.ndarray:
        """Eq. 3.19 score of every colour for every lens, (N, states)."""
        trained = self.trained
        a1, a3, a1_saturated = lens_histograms(
            image, lenses, trained.shape[1], self.params["min_chroma"]
        )
        return colour_scores(
            a1, a3, a1_saturated, trained, self.params["mode"], self.params["smooth"]
        )

    def classify(self, frame: Frame, candidates: Sequence[Candidate]) -> list[Detection]:
        if not candidates:
            return []
        lenses = [lens_of(frame.image, c, self.params) for c in candidates]
        out = []
        for candidate, row in zip(candidates, self.scores(frame.image, lenses)):
            scores = {state: float(v) for state, v in zip(self.states, row)}
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
            area = saturated_area(
                *lens_histograms(frame.image, [lens], bins, self.params["min_chroma"])
            )
            i = self.states.index(state)
            sums[i] += smooth_histograms(area, self.params["smooth"])[0]
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
