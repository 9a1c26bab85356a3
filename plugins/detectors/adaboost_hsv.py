"""Lee's learned colour detector: AdaBoost on (hue, saturation) per pixel, then blobs.

A boosted set of decision stumps scores every (hue, saturation) pair; the score becomes a
probability, the probability map is thresholded, and connected blobs become candidate boxes.
Lee 2017, section 3.2 (Eq. 3.1 and the two unnumbered equations after it).
"""
from __future__ import annotations

from collections.abc import Iterable, Sequence
from dataclasses import dataclass

import cv2
import numpy as np
from scipy.special import expit
from sklearn.ensemble import AdaBoostClassifier
from sklearn.tree import DecisionTreeClassifier

from tsrkit.errors import TsrkitError
from tsrkit.eval.matching import iou_matrix
from tsrkit.hookspecs import hookimpl
from tsrkit.models import Model, load_model
from tsrkit.params import Param
from tsrkit.plugin import Detector
from tsrkit.types import STATES, Candidate, Frame, Sample

#: OpenCV's full-range 8-bit hue and saturation both take 256 values.
LEVELS = 256
STUMP_KEYS = ("feature", "threshold", "left", "right", "alpha")


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
    return np.column_stack([np.cos(angle), np.sin(angle),
                            np.asarray(sat, np.float64).ravel() / (LEVELS - 1)]).astype(np.float32)


def plane_features() -> np.ndarray:
    """Features of every cell of the (hue, saturation) plane, in :func:`hs_index` order."""
    hue, sat = np.divmod(np.arange(LEVELS * LEVELS), LEVELS)
    return color_features(hue, sat)


@dataclass(frozen=True)
class PixelCounts:
    """Target and background pixel counts over the (hue, saturation) plane, and image counts."""

    positive: np.ndarray
    negative: np.ndarray
    images: int
    target_images: int

    @property
    def image_prior(self) -> float:
        """P(sign) of Eq. 3.1 read as the share of training images that hold a target box.

        Clipped to [0.01, 0.99]: a training set of only target images (or none) would
        otherwise make every pixel certain.
        """
        return float(np.clip(self.target_images / max(self.images, 1), 0.01, 0.99))


def pixel_histograms(samples: Iterable[Sample], target: str, min_value: int) -> PixelCounts:
    """Count target and background pixels over the (hue, saturation) plane.

    Target pixels lie inside a box whose state is ``target``; background pixels lie outside
    every box; pixels inside boxes of other states are not used. Pixels darker than
    ``min_value`` (V) are not used either: their hue is undefined. The histograms have 65536
    cells, indexed by :func:`hs_index`.
    """
    positive = np.zeros(LEVELS * LEVELS, np.int64)
    negative = np.zeros_like(positive)
    images = target_images = 0
    for sample in samples:
        hue, sat, val = hsv_planes(sample.load().image)
        inside = np.zeros(hue.shape, bool)
        any_box = np.zeros(hue.shape, bool)
        for ann in sample.annotations:
            region = _box_slice(ann.bbox, hue.shape)
            any_box[region] = True
            if ann.state == target:
                inside[region] = True
        usable = val >= min_value
        index = hs_index(hue, sat)
        positive += np.bincount(index[inside & usable], minlength=LEVELS * LEVELS)
        negative += np.bincount(index[~any_box & usable], minlength=LEVELS * LEVELS)
        images += 1
        target_images += any(ann.state == target for ann in sample.annotations)
    return PixelCounts(positive, negative, images, target_images)


def _box_slice(bbox: Sequence[float], shape: tuple[int, int]) -> tuple[slice, slice]:
    x0, y0, x1, y1 = bbox
    rows = slice(max(int(np.floor(y0)), 0), min(int(np.ceil(y1)), shape[0]))
    cols = slice(max(int(np.floor(x0)), 0), min(int(np.ceil(x1)), shape[1]))
    return rows, cols


def fit_stumps(positive: np.ndarray, negative: np.ndarray, n_estimators: int,
               seed: int) -> dict[str, np.ndarray]:
    """Boost ``n_estimators`` decision stumps on the two pixel histograms, classes balanced.

    Every occupied cell of the plane is one training row weighted by its pixel count, each
    class's weights summing to one half (the balanced training set of 3.2, using every pixel).

    Raises
    ------
    ValueError
        When either class has no pixels.
    """
    if positive.sum() == 0 or negative.sum() == 0:
        raise ValueError("training needs target and background pixels; found "
                         f"{int(positive.sum())} target and {int(negative.sum())} background")
    features = plane_features()
    pos_cells, neg_cells = np.flatnonzero(positive), np.flatnonzero(negative)
    x = np.concatenate([features[pos_cells], features[neg_cells]])
    y = np.r_[np.ones(pos_cells.size), np.zeros(neg_cells.size)]
    weight = np.r_[positive[pos_cells] / (2 * positive.sum()),
                   negative[neg_cells] / (2 * negative.sum())]
    booster = AdaBoostClassifier(DecisionTreeClassifier(max_depth=1), n_estimators=n_estimators,
                                 random_state=seed)
    booster.fit(x, y, sample_weight=weight)
    return stump_arrays(booster)


def stump_arrays(booster: AdaBoostClassifier) -> dict[str, np.ndarray]:
    """The stumps of a fitted binary booster as plain arrays.

    ``left``/``right`` are the votes (+1 target, -1 background) for ``x[feature] <= threshold``
    and otherwise; ``alpha`` is half of scikit-learn's SAMME weight ``log((1-e)/e)``, i.e. the
    discrete-AdaBoost weight for which g(f) below is Friedman et al.'s probability estimate.
    A stump that found no split gets ``threshold = inf`` and votes the same on both sides.
    """
    rows = [_stump_row(tree, weight / 2)
            for tree, weight in zip(booster.estimators_, booster.estimator_weights_)]
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
    return (int(t.feature[0]), float(t.threshold[0]), vote(t.children_left[0]),
            vote(t.children_right[0]), alpha)


def boosted_margin(features: np.ndarray, stumps: dict[str, np.ndarray]) -> np.ndarray:
    """Lee Eq. after 3.1: ``f(x) = sum_i alpha_i h_i(x)`` with stump votes ``h_i`` in {-1, +1}."""
    chosen = features[:, stumps["feature"]].astype(np.float64)
    votes = np.where(chosen <= stumps["threshold"], stumps["left"], stumps["right"])
    return votes @ stumps["alpha"]


def margin_probability(margin: np.ndarray) -> np.ndarray:
    """Lee's g: ``g(f) = e^f / (e^f + e^-f)`` (= logistic(2f), Friedman et al. 2000)."""
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
    return posterior(margin_probability(boosted_margin(plane_features(), stumps)),
                     prior).astype(np.float32)


def probability_map(image: np.ndarray, table: np.ndarray, min_value: int) -> np.ndarray:
    """Per-pixel target probability of a BGR image by table lookup; dark pixels get 0."""
    hue, sat, val = hsv_planes(image)
    prob = table[hs_index(hue, sat)]
    prob[val < min_value] = 0.0
    return prob


def blob_boxes(binary: np.ndarray,
               min_size: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """8-connected blobs whose width or height reaches ``min_size``.

    Returns
    -------
    boxes : ndarray of shape (n, 4), float64, ``(x0, y0, x1, y1)`` exclusive of x1, y1
    labels : ndarray of int
        The blob label of each box in ``label_image``.
    label_image : ndarray of int32, the blob label of every pixel (0: background)
    """
    count, label_image, stats, _ = cv2.connectedComponentsWithStats(
        binary.astype(np.uint8), connectivity=8)
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
        if not kept or iou_matrix(boxes[i:i + 1], boxes[kept]).max() <= overlap:
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
    """Per-pixel AdaBoost colour classifier with blob extraction (Lee 2017, 3.2)."""

    name = "adaboost-hsv"
    summary = "AdaBoost stumps on hue/saturation per pixel, probability map, largest blobs"
    section = "Lee 2017, 3.2 (Eq. 3.1)"
    params = (
        Param("model", "path", None, help="trained model (tsrkit train adaboost-hsv ...)"),
        Param("target", "str", "red", choices=("red", "yellow", "green", "orange"),
              help="target colour; training uses boxes of this state", section="3.2"),
        Param("n_estimators", "int", 50, min=1, max=1000, help="number of weak learners H",
              section="3.2"),
        Param("min_value", "int", 50, min=0, max=255,
              help="pixels darker than this V are background (hue undefined); training too"),
        Param("prior", "float", None, min=0.001, max=0.999,
              help="P(sign) of Eq. 3.1; default: the share of training images with a target",
              section="Eq. 3.1"),
        Param("threshold", "float", 0.5, min=0, max=1, help="probability threshold"),
        Param("min_size", "int", 30, min=1,
              help="keep blobs whose width or height reaches this many pixels", section="3.2"),
        Param("nms_overlap", "float", 0.3, min=0, max=1,
              help="a box overlapping a larger kept box by more IoU is dropped"),
        Param("max_boxes", "int", 1, min=1,
              help="boxes kept per frame, largest first (Lee keeps the largest)", section="3.2"),
        Param("expand_ratio", "float", 0.0, min=0,
              help="two-colour signs: grow wide blobs to height = ratio * width (0: off)",
              section="3.2"),
        Param("seed", "int", 0, help="random state of the booster"),
    )

    def __init__(self, **params):
        super().__init__(**params)
        self._table: np.ndarray | None = None

    def fit(self, samples: Iterable[Sample]) -> Model:
        """Learn the target colour from annotated boxes; see :func:`pixel_histograms`."""
        p = self.params
        counts = pixel_histograms(samples, p["target"], p["min_value"])
        stumps = fit_stumps(counts.positive, counts.negative, p["n_estimators"], p["seed"])
        return Model(arrays=stumps, info={
            "target": p["target"], "prior": counts.image_prior,
            "target_pixels": int(counts.positive.sum()),
            "background_pixels": int(counts.negative.sum()),
            "images": counts.images, "target_images": counts.target_images})

    def use_model(self, model: Model) -> None:
        """Build the lookup table from ``model`` (a fitted or loaded model)."""
        if model.info.get("target") != self.params["target"]:
            raise TsrkitError(f"adaboost-hsv: the model detects '{model.info.get('target')}' "
                              f"but target={self.params['target']!r}")
        prior = self.params["prior"] if self.params["prior"] is not None \
            else float(model.info["prior"])
        stumps = {key: np.asarray(model.arrays[key]) for key in STUMP_KEYS}
        self._table = probability_table(stumps, prior)

    def table(self) -> np.ndarray:
        """The (hue, saturation) posterior table, loading the model on first use."""
        if self._table is None:
            if self.params["model"] is None:
                raise TsrkitError("adaboost-hsv needs a model: train one with "
                                  "'tsrkit train adaboost-hsv --dataset ... --param target=... "
                                  "--out M' and pass --param model=M")
            self.use_model(load_model(self.params["model"], plugin=self.name))
        return self._table

    def detect(self, frame: Frame) -> list[Candidate]:
        p = self.params
        prob = probability_map(frame.image, self.table(), p["min_value"])
        boxes, labels, label_image = blob_boxes(prob > p["threshold"], p["min_size"])
        if not len(boxes):
            return []
        means = np.bincount(label_image.ravel(), weights=prob.ravel())[labels] / \
            np.bincount(label_image.ravel())[labels]
        state = p["target"] if p["target"] in STATES else None
        out = []
        for i in largest_first_nms(boxes, p["nms_overlap"], p["max_boxes"]):
            box = boxes[i]
            if p["expand_ratio"] > 0:
                box = expand_two_colour(box, p["expand_ratio"], frame.height)
            out.append(Candidate.from_box(box, float(means[i]), state))
        return out


@hookimpl
def register_detectors(register):
    register(AdaBoostHSV)
