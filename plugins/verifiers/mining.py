"""Training data of the learned verifier: a detector's candidates labelled by Zheng's rule, and
hard negatives.

A candidate is positive when its centre lies in the minimum enclosing circle of a ground-truth
box of its frame (Zheng 2016, 5.2.1, :func:`tsrkit.eval.matching.centre_hits`), negative
otherwise. Negatives also come from synthetic road scenes without any lit light
(:mod:`tsrkit.synth`: dark housings, lamps, headlights, windows). A positive hitting a housing
box (elongated: real housing-boxed sets, rendered heads) also gets a box label, whether its
fitted housing meets that box (the ``box_rank`` model's target, :func:`box_labels`).
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Iterator, Sequence
from dataclasses import dataclass
from itertools import chain

import numpy as np

from tsrkit.api import Candidate, Detector, Frame, Sample, centre_hits, iou_matrix, scatter_heads
from tsrkit_plugins.verifiers.augment import Augmentation
from tsrkit_plugins.verifiers.pasting import crop_frames
from tsrkit_plugins.verifiers.unlit import no_light_frames

#: Candidates of one frame -> the candidates the verifier will see (e.g. after a housing stage).
Stage = Callable[[Frame, list[Candidate]], list[Candidate]]
#: Seed of the synthetic scenes with rendered lit heads (positives).
HEADS_SEED = 77
#: A box whose long side is at least this many times its short side boxes a housing (a lens
#: box, as KR's, is about square): only those give box labels.
HOUSING_ASPECT = 1.5


@dataclass
class Labelled:
    """Feature rows of candidates, their labels, the index of the frame they came from and
    their box labels (:func:`box_labels`: 1 / 0, or -1 where there is none)."""

    features: np.ndarray
    labels: np.ndarray
    frames: np.ndarray
    boxes: np.ndarray

    @classmethod
    def concat(cls, parts: Sequence[Labelled], width: int) -> Labelled:
        """All parts stacked (an empty set of ``width`` columns when there are none)."""
        if not parts:
            empty = np.zeros(0, np.int8)
            return cls(np.zeros((0, width), np.float32), empty, np.zeros(0, int), empty)
        return cls(
            np.concatenate([p.features for p in parts]),
            np.concatenate([p.labels for p in parts]),
            np.concatenate([p.frames for p in parts]),
            np.concatenate([p.boxes for p in parts]),
        )


def centre_labels(candidates: Sequence[Candidate], boxes: Sequence[Sequence[float]]) -> np.ndarray:
    """1 for every candidate whose centre lies in a box's enclosing circle, else 0 (Zheng 5.2.1).

    Examples
    --------
    >>> from tsrkit.core.types import Candidate
    >>> c = [Candidate.from_circle(10, 10, 2, 1.0), Candidate.from_circle(40, 10, 2, 1.0)]
    >>> centre_labels(c, [(6, 0, 14, 20)]).tolist()
    [1, 0]
    """
    if not candidates:
        return np.zeros(0, np.int8)
    if not boxes:
        return np.zeros(len(candidates), np.int8)
    hits = centre_hits([(c.x, c.y) for c in candidates], boxes)
    return np.asarray(hits.any(axis=1), dtype=np.int8)


def box_labels(candidates: Sequence[Candidate], boxes: Sequence[Sequence[float]]) -> np.ndarray:
    """For each candidate whose centre hits housing boxes (Zheng 5.2.1; boxes at least
    :data:`HOUSING_ASPECT` times as long as wide): 1 when its reported box (the fitted housing,
    ``object_bbox``) has IoU >= 0.5 with one of them, else 0; -1 for every other candidate (a
    negative, or a hit on lens boxes only).

    Examples
    --------
    >>> from dataclasses import replace
    >>> from tsrkit.core.types import Candidate
    >>> on = replace(Candidate.from_circle(10, 5, 2, 1.0), housing=(6, 0, 14, 21))
    >>> off = replace(Candidate.from_circle(10, 15, 2, 1.0), housing=(0, 13, 30, 21))
    >>> far = Candidate.from_circle(90, 5, 2, 1.0)
    >>> box_labels([on, off, far], [(6, 0, 14, 20)]).tolist()
    [1, 0, -1]
    >>> box_labels([on], [(6, 0, 14, 10)]).tolist()  # a lens box: no box label
    [-1]
    """
    labels = np.full(len(candidates), -1, np.int8)
    box = np.asarray(boxes, float).reshape(-1, 4)
    sides = np.stack([box[:, 2] - box[:, 0], box[:, 3] - box[:, 1]], axis=1)
    housing = sides.max(axis=1) >= HOUSING_ASPECT * sides.min(axis=1)
    if not candidates or not housing.any():
        return labels
    box = box[housing]
    hits = centre_hits([(c.x, c.y) for c in candidates], box)
    fits = iou_matrix([c.object_bbox for c in candidates], box) >= 0.5
    hit = np.asarray(hits.any(axis=1))
    labels[hit] = np.asarray((hits & fits).any(axis=1))[hit]
    return labels


@dataclass(frozen=True)
class Heads:
    """The rendered-head scenes: how many, the share of horizontal heads and of light rims
    (:func:`tsrkit.synth.heads.scatter_heads`)."""

    count: int = 0
    horizontal: float = 0.2
    rims: float = 0.0

    @property
    def tag(self) -> str:
        """Names the options in the scenes' sources ('' for the first defaults)."""
        if (self.horizontal, self.rims) == (0.2, 0.0):
            return ""
        return f"+h{self.horizontal:g}r{self.rims:g}"


def head_frames(heads: Heads, seed: int = HEADS_SEED) -> Iterator[tuple[Frame, list]]:
    """``heads.count`` synthetic 1280x720 no-light scenes, each with 5 rendered lit heads of
    jittered scale, colour, blur and exposure (:func:`tsrkit.synth.heads.scatter_heads`), and
    their housing boxes: positives of cameras no real training set shows."""
    rng = np.random.default_rng(seed)
    for frame in no_light_frames(heads.count, seed):
        image = frame.image.copy()
        boxes = scatter_heads(image, rng, horizontal=heads.horizontal, rims=heads.rims)
        yield Frame(image, f"synth-heads{heads.tag}:{seed}:{frame.source}"), boxes


@dataclass(frozen=True)
class Crops:
    """The pasted-crop scenes (:mod:`pasting`): how many, into the real training frames or
    synthetic ones, with the training sets' own housings as crops too, the share turned."""

    count: int = 0
    on_real: bool = False
    own: bool = False
    rotate: float = 0.0


def labelled_candidates(
    samples: Iterable[Sample],
    detector: Detector,
    stage: Stage,
    features: Callable[[np.ndarray, Sequence[Candidate]], np.ndarray],
    width: int,
    no_light: int,
    heads: Heads = Heads(),
    augmentation: Augmentation | None = None,
    crops: Crops = Crops(),
) -> Labelled:
    """Run ``detector`` (then ``stage``) on every sample (on each of its ``augmentation``
    views: :mod:`augment`), on ``no_light`` synthetic frames (and their camera looks), on the
    synthetic frames with rendered lit heads of ``heads`` (:func:`head_frames`) and on the
    frames with pasted real heads of ``crops``
    (:func:`tsrkit_plugins.verifiers.pasting.crop_frames`, whose crop set is read first: pasted
    into the samples or into synthetic scenes, with the samples' own housings as crops or not);
    return every candidate's features, its Zheng label, its frame index and its box label
    (:func:`box_labels`)."""
    samples = list(samples)
    pasted = crop_frames(
        crops.count,
        samples if crops.on_real else (),
        training=samples if crops.own else (),
        rotate=crops.rotate,
    )
    parts = []
    views = augmentation or Augmentation()
    frames: Iterator[tuple[Frame, Sequence[Sequence[float]]]] = (
        view for s in samples for view in views.views(s.load(), [a.bbox for a in s.annotations])
    )
    synthetic = (
        view for f in no_light_frames(no_light) for view in chain([(f, [])], views.looked(f, []))
    )
    for index, (frame, boxes) in enumerate(chain(frames, synthetic, head_frames(heads), pasted)):
        candidates = stage(frame, detector.detect(frame))
        if not candidates:
            continue
        parts.append(
            Labelled(
                features(frame.image, candidates),
                centre_labels(candidates, boxes),
                np.full(len(candidates), index),
                box_labels(candidates, boxes),
            )
        )
    return Labelled.concat(parts, width)


def hard_negatives(probability: np.ndarray, labels: np.ndarray, count: int) -> np.ndarray:
    """Indices of the ``count`` negatives scored most positive (ties: earlier first).

    Examples
    --------
    >>> hard_negatives(np.array([0.9, 0.2, 0.8, 0.7]), np.array([1, 0, 0, 0]), 2).tolist()
    [2, 3]
    """
    negatives = np.flatnonzero(labels == 0)
    order = np.argsort(-probability[negatives], kind="stable")
    return np.sort(negatives[order[:count]])
