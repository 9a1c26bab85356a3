"""Lee's learned colour detector: AdaBoost on (hue, saturation) per pixel, then blobs.

A boosted set of decision stumps scores every (hue, saturation) pair; the score becomes a
probability, the probability map is thresholded, and connected blobs become candidate boxes.
Lee 2017, section 3.2 (Eq. 3.1 and the two unnumbered equations after it). One model file holds
one booster per colour; ``target=lights`` runs red, yellow and green together and gives each
blob the colour whose posterior wins. Shipped default: ``models/adaboost_hsv_default``.

Not ``skops.io``: the booster is evaluated once over the whole (hue, saturation) plane into Lee's
lookup table; its stumps as arrays are that table's inputs, so the fitted object is not needed.
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

import cv2
import numpy as np

from tsrkit.api import (
    STATES,
    Candidate,
    Detector,
    Frame,
    Model,
    Param,
    Sample,
    TsrkitError,
    clip_box,
    hookimpl,
    iou_matrix,
    load_model,
)

if TYPE_CHECKING:  # scikit-learn loads when a model is fitted or read, not on import
    from sklearn.ensemble import AdaBoostClassifier
    from sklearn.tree import DecisionTreeClassifier

#: OpenCV's full-range 8-bit hue and saturation both take 256 values.
LEVELS = 256
STUMP_KEYS = ("feature", "threshold", "left", "right", "alpha")
#: The colours each ``target`` value trains and detects.
TARGET_COLOURS = {
    "lights": ("red", "yellow", "green"),
    "red": ("red",),
    "yellow": ("yellow",),
    "green": ("green",),
    "orange": ("orange",),
}
#: Trained with ``tsrkit train adaboost-hsv`` on roboflow_cinta_v2_id (CC BY 4.0); see its JSON.
DEFAULT_MODEL = Path(__file__).parent / "models" / "adaboost_hsv_default"


def hsv_planes(image: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Hue (0-255 for 0-360 deg), saturation and value planes of a BGR uint8 image."""
    hsv = cv2.cvtColor(image, cv2.COLOR_BGR2HSV_FULL)
    return hsv[..., 0], hsv[..., 1], hsv[..., 2]


def hs_index(hue: np.ndarray, sat: np.ndarray) -> np.ndarray:
    """The flat index ``hue * 256 + sat`` into the (hue, saturation) plane."""
    return (hue.astype(np.intp) << 8) | sat


def color_features(hue: np.ndarray, sat: np.ndarray) -> np.ndarray:
    """The feature vector of each pixel: ``(cos h, sin h, s)``, float32, shape (n, 3).

    Hue is circular (red sits at both ends of the scale), so it enters as a point on the unit
    circle; a stump on ``cos h`` or ``sin h`` cuts the hue circle by a straight line, which
    lets a few stumps isolate red without a seam at 0 deg.
    """
    angle = np.asarray(hue, np.float64).ravel() * (2 * np.pi / LEVELS)
    return np.column_stack(
        [np.cos(angle), np.sin(angle), np.asarray(sat, np.float64).ravel() / (LEVELS - 1)]
    ).astype(np.float32)


def plane_features() -> np.ndarray:
    """Features of every cell of the (hue, saturation) plane, in :func:`hs_index` order."""
    hue, sat = np.divmod(np.arange(LEVELS * LEVELS), LEVELS)
    return color_features(hue, sat)


@dataclass(frozen=True)
class PixelCounts:
    """Per-colour target and background pixel counts over the (hue, saturation) plane.

    ``positive`` and ``negative`` have shape (colours, 65536); ``target_images`` counts, per
    colour, the images holding a box of that colour.
    """

    positive: np.ndarray
    negative: np.ndarray
    images: int
    target_images: np.ndarray

    @property
    def image_priors(self) -> np.ndarray:
        """P(sign) of Eq. 3.1 per colour, read as the share of training images with that colour.

        Clipped to [0.01, 0.99]: a training set of only target images (or none) would
        otherwise make every pixel certain.
        """
        return np.clip(self.target_images / max(self.images, 1), 0.01, 0.99)


def lens_mask(sat: np.ndarray, val: np.ndarray, min_value: int) -> np.ndarray:
    """The lit lens inside one box: the brightest saturated blob.

    Both Roboflow sets box the whole housing, so most of a box is dark housing or sky. Each
    pixel is scored by ``S * V / 255`` (vivid and bright), the box's scores are split by Otsu's
    threshold, and the largest 8-connected part above it is the lens. Pixels darker than
    ``min_value`` never belong to it. A box with no usable pixel gives an empty mask.
    """
    usable = val >= min_value
    if usable.sum() < 2:
        return np.zeros(sat.shape, bool)
    score = ((sat.astype(np.uint16) * val) // 255).astype(np.uint8)
    cut, _ = cv2.threshold(
        score[usable].reshape(-1, 1), 0, 255, cv2.THRESH_BINARY | cv2.THRESH_OTSU
    )
    bright = (score > cut) & usable
    count, labels, stats, _ = cv2.connectedComponentsWithStats(
        bright.astype(np.uint8), connectivity=8
    )
    if count < 2:
        return bright
    return labels == 1 + int(np.argmax(stats[1:, cv2.CC_STAT_AREA]))


def box_target_mask(sat: np.ndarray, val: np.ndarray, labels: str, min_value: int) -> np.ndarray:
    """Which pixels of one box are target pixels: all (``box``) or the lit lens (``lens``)."""
    if labels == "box":
        return np.ones(sat.shape, bool)
    if labels == "lens":
        return lens_mask(sat, val, min_value)
    raise ValueError(f"pixel labelling must be 'box' or 'lens', not {labels!r}")


def pixel_labels(
    sat: np.ndarray,
    val: np.ndarray,
    annotations,
    targets: Sequence[str],
    labels: str,
    hard_negatives: bool,
    min_value: int,
) -> list[tuple[np.ndarray, np.ndarray]]:
    """Target and background masks of one image, one pair per colour in ``targets``.

    Target pixels of colour c: the :func:`box_target_mask` pixels of boxes whose state is c.
    Background: pixels outside every box; with ``lens`` labelling also the lenses of other
    colours' boxes; with ``hard_negatives`` also every box's non-target (unlit housing)
    pixels. Pixels darker than ``min_value`` are neither (their hue is undefined).
    """
    outside = np.ones(sat.shape, bool)
    unlit = np.zeros(sat.shape, bool)
    lit: dict[str, np.ndarray] = {}
    for ann in annotations:
        region = _box_slice(ann.bbox, sat.shape)
        target = box_target_mask(sat[region], val[region], labels, min_value)
        outside[region] = False
        lit.setdefault(ann.state, np.zeros(sat.shape, bool))[region] |= target
        unlit[region] |= ~target
    any_lit = np.logical_or.reduce(list(lit.values())) if lit else np.zeros(sat.shape, bool)
    usable = val >= min_value
    out = []
    for colour in targets:
        positive = lit.get(colour, np.zeros(sat.shape, bool)) & usable
        negative = outside.copy()
        if labels == "lens":
            negative |= any_lit
        if hard_negatives:
            negative |= unlit & ~any_lit
        out.append((positive, negative & usable & ~positive))
    return out


def pixel_histograms(
    samples: Iterable[Sample],
    targets: Sequence[str],
    min_value: int,
    labels: str = "lens",
    hard_negatives: bool = False,
) -> PixelCounts:
    """Count each colour's target and background pixels over the (hue, saturation) plane.

    One pass over ``samples``; the masks come from :func:`pixel_labels`. The histograms have
    65536 cells, indexed by :func:`hs_index`.
    """
    cells = LEVELS * LEVELS
    positive = np.zeros((len(targets), cells), np.int64)
    negative = np.zeros_like(positive)
    target_images = np.zeros(len(targets), np.int64)
    images = 0
    for sample in samples:
        hue, sat, val = hsv_planes(sample.load().image)
        index = hs_index(hue, sat)
        masks = pixel_labels(
            sat, val, sample.annotations, targets, labels, hard_negatives, min_value
        )
        for t, (pos, neg) in enumerate(masks):
            positive[t] += np.bincount(index[pos], minlength=cells)
            negative[t] += np.bincount(index[neg], minlength=cells)
        states = {ann.state for ann in sample.annotations}
        target_images += [colour in states for colour in targets]
        images += 1
    return PixelCounts(positive, negative, images, target_images)


def _box_slice(bbox: Sequence[float], shape: tuple[int, int]) -> tuple[slice, slice]:
    x0, y0, x1, y1 = clip_box(bbox, shape[1], shape[0])
    return slice(y0, y1), slice(x0, x1)


def fit_stumps(
    positive: np.ndarray, negative: np.ndarray, n_estimators: int, seed: int
) -> dict[str, np.ndarray]:
    """Boost ``n_estimators`` decision stumps on the two pixel histograms, classes balanced.

    Every occupied cell of the plane is one training row weighted by its pixel count, each
    class's weights summing to one half (the balanced training set of 3.2, using every pixel).

    Raises
    ------
    ValueError
        When either class has no pixels.
    """
    if positive.sum() == 0 or negative.sum() == 0:
        raise TsrkitError(
            "training needs target and background pixels; found "
            f"{int(positive.sum())} target and {int(negative.sum())} background"
        )
    features = plane_features()
    pos_cells, neg_cells = np.flatnonzero(positive), np.flatnonzero(negative)
    x = np.concatenate([features[pos_cells], features[neg_cells]])
    y = np.r_[np.ones(pos_cells.size), np.zeros(neg_cells.size)]
    weight = np.r_[
        positive[pos_cells] / (2 * positive.sum()), negative[neg_cells] / (2 * negative.sum())
    ]
    from sklearn.ensemble import AdaBoostClassifier
    from sklearn.tree import DecisionTreeClassifier

    booster = AdaBoostClassifier(
        DecisionTreeClassifier(max_depth=1), n_estimators=n_estimators, random_state=seed
    )
    booster.fit(x, y, sample_weight=weight)
    return stump_arrays(booster)


def stump_arrays(booster: AdaBoostClassifier) -> dict[str, np.ndarray]:
    """The stumps of a fitted binary booster as plain arrays.

    ``left``/``right`` are the votes (+1 target, -1 background) for ``x[feature] <= threshold``
    and otherwise; ``alpha`` is half of scikit-learn's SAMME weight ``log((1-e)/e)``, i.e. the
    discrete-AdaBoost weight for which g(f) below is Friedman et al.'s probability estimate.
    A stump that found no split gets ``threshold = inf`` and votes the same on both sides.
    """
    rows = [
        _stump_row(tree, weight / 2)
        for tree, weight in zip(booster.estimators_, booster.estimator_weights_)
    ]
    table = np.array(rows, np.float64).reshape(-1, 5)
    out = {key: table[:, i] for i, key in enumerate(STUMP_KEYS)}
    out["feature"] = out["feature"].astype(np.int64)
    return out


def _stump_row(tree: DecisionTreeClassifier, alpha: float) -> tuple[float, ...]:
    t = tree.tree_

    def vote(node: int) -> float:
        return 1.0 if tree.classes_[np.argmax(t.value[node][0])] == 1 else -1.0

    if t.node_count == 1:
        return 0, np.inf, vote(0), vote(0), alpha
    return (
        int(t.feature[0]),
        float(t.threshold[0]),
        vote(t.children_left[0]),
        vote(t.children_right[0]),
        alpha,
    )


def boosted_margin(features: np.ndarray, stumps: dict[str, np.ndarray]) -> np.ndarray:
    """Lee Eq. after 3.1: ``f(x) = sum_i alpha_i h_i(x)`` with stump votes ``h_i`` in {-1, +1}."""
    chosen = features[:, stumps["feature"]].astype(np.float64)
    votes = np.where(chosen <= stumps["threshold"], stumps["left"], stumps["right"])
    return votes @ stumps["alpha"]


def margin_probability(margin: np.ndarray) -> np.ndarray:
    """Lee's g: ``g(f) = e^f / (e^f + e^-f)`` (= logistic(2f), Friedman et al. 2000)."""
    from scipy.special import expit  # on first use: scipy.special costs 0.2 s to import

    return expit(2.0 * np.asarray(margin, np.float64))


def posterior(likelihood: np.ndarray, prior: float) -> np.ndarray:
    """Lee Eq. 3.1, ``P(sign|x) = eta P(x|sign) P(sign)``, with eta normalising over two classes.

    The booster is trained on balanced classes, so g(f) estimates the target probability under
    equal priors; this reading treats g and 1 - g as the two likelihoods and applies the prior.
    Lee takes P(sign) "from the ground truth of our training data" right before counting
    positive and negative training images, so the prior is read as the share of training
    images holding the target (:attr:`PixelCounts.image_prior`); the share of target pixels
    (well under 1 % for traffic lights) would suppress every pixel. ``prior = 0.5`` leaves g
    unchanged.
    """
    target = likelihood * prior
    return target / (target + (1.0 - likelihood) * (1.0 - prior))


def probability_table(stumps: dict[str, np.ndarray], prior: float) -> np.ndarray:
    """The posterior of every (hue, saturation) cell, float32, shape (65536,)."""
    return posterior(margin_probability(boosted_margin(plane_features(), stumps)), prior).astype(
        np.float32
    )


def winning_colour(tables: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Per (hue, saturation) cell, the highest posterior over colours and that colour's index.

    ``tables`` has shape (colours, 65536); returns the float32 maximum and the uint8 argmax.
    """
    return tables.max(axis=0).astype(np.float32), tables.argmax(axis=0).astype(np.uint8)


def probability_map(
    image: np.ndarray, table: np.ndarray, colour: np.ndarray, min_value: int
) -> tuple[np.ndarray, np.ndarray]:
    """Per-pixel target probability and colour index of a BGR image by table lookup.

    Pixels darker than ``min_value`` get probability 0.
    """
    hue, sat, val = hsv_planes(image)
    index = hs_index(hue, sat)
    prob = table[index]
    prob[val < min_value] = 0.0
    return prob, colour[index]


def blob_colours(
    label_image: np.ndarray, prob: np.ndarray, colour: np.ndarray, labels: np.ndarray, colours: int
) -> tuple[np.ndarray, np.ndarray]:
    """Mean probability and probability-weighted majority colour of the blobs ``labels``."""
    fg = np.flatnonzero(label_image)
    blob = label_image.ravel()[fg]
    weight = prob.ravel()[fg]
    size = int(label_image.max()) + 1
    means = np.bincount(blob, weights=weight, minlength=size) / np.maximum(
        np.bincount(blob, minlength=size), 1
    )
    votes = np.bincount(
        blob * colours + colour.ravel()[fg], weights=weight, minlength=size * colours
    ).reshape(size, colours)
    return means[labels], votes[labels].argmax(axis=1)


def blob_boxes(binary: np.ndarray, min_size: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """8-connected blobs whose width or height reaches ``min_size``.

    Returns
    -------
    boxes : ndarray of shape (n, 4), float64, ``(x0, y0, x1, y1)`` exclusive of x1, y1
    labels : ndarray of int
        The blob label of each box in ``label_image``.
    label_image : ndarray of int32, the blob label of every pixel (0: background)
    """
    _count, label_image, stats, _ = cv2.connectedComponentsWithStats(
        binary.astype(np.uint8), connectivity=8
    )
    x, y, w, h = (stats[1:, i] for i in range(4))
    keep = np.flatnonzero((w >= min_size) | (h >= min_size))
    boxes = np.column_stack([x, y, x + w, y + h])[keep].astype(np.float64)
    return boxes, (keep + 1), label_image


def largest_first_nms(boxes: np.ndarray, overlap: float, limit: int) -> np.ndarray:
    """Indices of boxes kept by non-maximum suppression that prefers the larger box (3.2)."""
    areas = (boxes[:, 2] - boxes[:, 0]) * (boxes[:, 3] - boxes[:, 1])
    kept: list[int] = []
    for i in np.argsort(-areas, kind="stable"):
        if len(kept) == limit:
            break
        if not kept or iou_matrix(boxes[i : i + 1], boxes[kept]).max() <= overlap:
            kept.append(int(i))
    return np.array(kept, np.intp)


def expand_two_colour(box: np.ndarray, ratio: float, height: int) -> np.ndarray:
    """Grow a wider-than-tall blob downwards to ``height = ratio * width`` (3.2, last paragraph).

    A regulatory work-zone sign is orange on top and white below, so only its orange band is
    found; Lee "heuristically increased the bounding box based on the aspect ratio". This
    reading extends the bottom edge, clipped to the image.
    """
    x0, y0, x1, y1 = box
    if x1 - x0 <= y1 - y0:
        return box
    return np.array([x0, y0, x1, min(y0 + ratio * (x1 - x0), height)])


class AdaBoostHSV(Detector):
    """Per-pixel AdaBoost colour classifier with blob extraction (Lee 2017, 3.2).

    Detection defaults suit traffic lights (lenses of 5-20 px) and were chosen by validation on
    the shipped model's training set (benchmarks/RESULTS.lee.md). Lee's work-zone values are
    ``min_size=30, max_boxes=1, threshold=0.5`` (3.2: "the largest bounding box when the width
    or height is bigger than 30 pixels").
    """

    name = "adaboost-hsv"
    summary = "AdaBoost stumps on hue/saturation per pixel, probability map, largest blobs"
    section = "Lee 2017, 3.2 (Eq. 3.1)"
    PARAMS = (
        Param(
            "model",
            "path",
            None,
            help="trained model (tsrkit train adaboost-hsv ...); "
            "unset: the shipped red/yellow/green model (trained on roboflow_cinta_v2_id)",
        ),
        Param(
            "target",
            "str",
            "lights",
            choices=tuple(TARGET_COLOURS),
            help="colour to train and detect; lights = red, yellow and green, each box "
            "taking the colour whose posterior wins",
            section="3.2",
        ),
        Param(
            "labels",
            "str",
            "lens",
            choices=("lens", "box"),
            help="training target pixels: the lit lens in each box (Otsu on S*V, largest "
            "blob) or every pixel of the box (round 1; right for filled signs)",
        ),
        Param(
            "hard_negatives",
            "bool",
            False,
            help="training: also use the unlit housing pixels of boxes as background",
        ),
        Param(
            "n_estimators",
            "int",
            50,
            min=1,
            max=1000,
            help="number of weak learners H",
            section="3.2",
        ),
        Param(
            "min_value",
            "int",
            50,
            min=0,
            max=255,
            help="pixels darker than this V are background (hue undefined); training too",
        ),
        Param(
            "prior",
            "float",
            None,
            min=0.001,
            max=0.999,
            help="P(sign) of Eq. 3.1 for every colour; default: the share of training "
            "images holding the colour",
            section="Eq. 3.1",
        ),
        Param("threshold", "float", 0.9, min=0, max=1, help="probability threshold (Lee: 0.5)"),
        Param(
            "min_size",
            "int",
            3,
            min=1,
            help="keep blobs whose width or height reaches this many pixels (Lee: 30)",
            section="3.2",
        ),
        Param(
            "nms_overlap",
            "float",
            0.3,
            min=0,
            max=1,
            help="a box overlapping a larger kept box by more IoU is dropped",
        ),
        Param(
            "max_boxes",
            "int",
            3,
            min=1,
            help="boxes kept per frame, largest first (Lee: 1, the largest)",
            section="3.2",
        ),
        Param(
            "expand_ratio",
            "float",
            0.0,
            min=0,
            help="two-colour signs: grow wide blobs to height = ratio * width (0: off)",
            section="3.2",
        ),
        Param("seed", "int", 0, help="random state of the booster"),
    )

    def __init__(self, **params):
        super().__init__(**params)
        self._table: np.ndarray | None = None
        self._colour: np.ndarray | None = None

    @property
    def colours(self) -> tuple[str, ...]:
        """The colours this instance trains and detects (from ``target``)."""
        return TARGET_COLOURS[self.params["target"]]

    def fit(self, samples: Iterable[Sample], *, detector: Detector | None = None) -> Model:
        """Learn one booster per colour from annotated boxes; see :func:`pixel_labels`.

        When ``samples`` is a :class:`~tsrkit.core.types.Dataset`, its licence and citation are
        recorded in the model's info (the shipped model's data terms travel with it).
        """
        p = self.params
        source = getattr(samples, "info", {})
        counts = pixel_histograms(
            samples, self.colours, p["min_value"], p["labels"], p["hard_negatives"]
        )
        arrays = {}
        for t, colour in enumerate(self.colours):
            stumps = fit_stumps(
                counts.positive[t], counts.negative[t], p["n_estimators"], p["seed"]
            )
            arrays.update({f"{colour}_{key}": value for key, value in stumps.items()})
        return Model(
            arrays=arrays,
            info={
                "targets": list(self.colours),
                "labels": p["labels"],
                "priors": dict(zip(self.colours, counts.image_priors.tolist())),
                "target_pixels": dict(zip(self.colours, counts.positive.sum(axis=1).tolist())),
                "background_pixels": dict(zip(self.colours, counts.negative.sum(axis=1).tolist())),
                "images": counts.images,
                "target_images": dict(zip(self.colours, counts.target_images.tolist())),
                "data_licence": source.get("licence"),
                "data_citation": source.get("citation"),
            },
        )

    def use_model(self, model: Model) -> None:
        """Build the lookup tables from ``model`` (a fitted or loaded model)."""
        missing = [c for c in self.colours if c not in model.info.get("targets", ())]
        if missing:
            raise TsrkitError(
                f"adaboost-hsv: the model detects {model.info.get('targets')} "
                f"but target={self.params['target']!r} needs {missing}"
            )
        tables = np.stack(
            [
                probability_table(
                    {key: np.asarray(model.arrays[f"{colour}_{key}"]) for key in STUMP_KEYS},
                    self.params["prior"]
                    if self.params["prior"] is not None
                    else float(model.info["priors"][colour]),
                )
                for colour in self.colours
            ]
        )
        self._table, self._colour = winning_colour(tables)

    def table(self) -> np.ndarray:
        """The (hue, saturation) posterior table (best colour), loading the model on first use."""
        if self._table is None:
            self.use_model(load_model(self.params["model"] or DEFAULT_MODEL, plugin=self.name))
        assert self._table is not None
        return self._table

    def detect(self, frame: Frame) -> list[Candidate]:
        p = self.params
        table = self.table()
        assert self._colour is not None  # set with the table
        prob, colour = probability_map(frame.image, table, self._colour, p["min_value"])
        boxes, labels, label_image = blob_boxes(prob > p["threshold"], p["min_size"])
        if not len(boxes):
            return []
        kept = largest_first_nms(boxes, p["nms_overlap"], p["max_boxes"])
        means, winners = blob_colours(label_image, prob, colour, labels[kept], len(self.colours))
        out = []
        for i, mean, winner in zip(kept, means, winners):
            box = boxes[i]
            if p["expand_ratio"] > 0:
                box = expand_two_colour(box, p["expand_ratio"], frame.height)
            state = self.colours[winner]
            out.append(Candidate.from_box(box, float(mean), state if state in STATES else None))
        return out


@hookimpl
def register_detectors(register):
    register(AdaBoostHSV)
