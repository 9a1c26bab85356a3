"""``verifier``: a learned stage that rescores or rejects the candidates of any detector.

Beyond the three documents: a gradient-boosted classifier (scikit-learn's
``HistGradientBoostingClassifier``) reads features of each candidate and its housing
(:mod:`features`: HOG, Lab/HSV statistics of lens, annulus, surround and housing, surround
darkness, geometry, frame position, the detector's score) and gives the probability that the
candidate is a lit traffic light. The candidate's score is that probability, blended with the
detector's own score by ``prior`` (the ``union`` detector's agreement score holds on
cameras the model never saw, where the probability drops); candidates scoring below
``threshold``, or below ``relative`` x the best score of their frame, are dropped. Trained by
``tsrkit train verifier --detector X`` on that detector's candidates labelled by Zheng's centre
rule (5.2.1), with hard-negative mining (:mod:`mining`).

``box_rank`` (weight w > 0) adds a second classifier of the same features, trained only on the
positives that hit a housing box (housing-boxed real sets, rendered heads), which gives the
probability that the candidate's fitted housing meets that box at IoU >= 0.5. It only orders:
the keep decision stays on the score above (threshold, relative), and a kept candidate
reports that score x (1 - w + w x box probability), never more than the decision score.
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from dataclasses import replace
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from tsrkit.api import (
    Candidate,
    Detector,
    Frame,
    Model,
    ModelError,
    Param,
    Sample,
    TsrkitError,
    Verifier,
    hookimpl,
    load_model,
)
from tsrkit_plugins.shared.forest import Forest
from tsrkit_plugins.shared.persistence import BOX_ARRAY, estimator_arrays, load_estimator
from tsrkit_plugins.verifiers.augment import Augmentation
from tsrkit_plugins.verifiers.features import candidate_features, feature_names, layout
from tsrkit_plugins.verifiers.mining import (
    Crops,
    Heads,
    Labelled,
    Stage,
    hard_negatives,
    labelled_candidates,
)

if TYPE_CHECKING:  # scikit-learn loads when a model is fitted or read, not on import
    from sklearn.ensemble import HistGradientBoostingClassifier

DEFAULT_MODEL = Path(__file__).parent / "models" / "verifier_default"


def passes(scores: Sequence[float], threshold: float, relative: float = 0.0) -> np.ndarray:
    """Which of one frame's candidate ``scores`` are kept: at least ``threshold`` and at least
    ``relative`` x the frame's best score.

    Examples
    --------
    >>> passes([0.9, 0.5, 0.3, 0.1], 0.2, 0.5).tolist()
    [True, True, False, False]
    >>> passes([0.25, 0.1], 0.2, 0.5).tolist()
    [True, False]
    """
    values = np.asarray(scores, dtype=float)
    if not len(values):
        return np.zeros(0, bool)
    return (values >= threshold) & (values >= relative * values.max())


class LearnedVerifier(Verifier):
    """Rescore candidates by a learned probability of being a lit light; drop the unlikely."""

    name = "verifier"
    summary = "learned candidate verifier: HOG, colour and housing features, gradient boosting"
    section = "beyond the documents; labels by Zheng 5.2.1"
    PARAMS = (
        Param(
            "model",
            "path",
            None,
            help="trained model (tsrkit train verifier); default: the shipped model, trained "
            "on openly licensed data only (see the README)",
        ),
        Param(
            "threshold",
            "float",
            0.5,
            min=0.0,
            max=1.0,
            help="candidates whose probability is below this are rejected",
        ),
        Param(
            "prior",
            "float",
            0.0,
            min=0.0,
            max=1.0,
            help="weight of the detector's own score in the candidate's score: "
            "(1 - prior) x probability + prior x detector score clipped to [0, 1]; for "
            "detectors scoring in [0, 1] such as union (its members' agreement), which holds "
            "across cameras where the learned probability may not; 0: the probability alone",
        ),
        Param(
            "relative",
            "float",
            0.0,
            min=0.0,
            max=1.0,
            help="candidates scoring below this fraction of their frame's best score are "
            "rejected too (an unseen camera shifts every score of a frame together; the "
            "frame's ranking holds better than the absolute score); 0: off",
        ),
        Param(
            "after",
            "verifier",
            "housing",
            help="a verifier run on the candidates before the features are read, in training "
            "and at run time ('housing': the housing stage fits each candidate's housing, "
            "whose box the features read and the records report; 'housing pad=2' with its "
            "own parameters); '' for none. A model remembers the stage it was trained after",
        ),
        Param(
            "box_rank",
            "float",
            0.0,
            min=0.0,
            max=1.0,
            help="weight w of the box model in the order of the kept candidates: each reports "
            "its score x (1 - w + w x the probability that its fitted housing meets the light's "
            "box at IoU >= 0.5); which candidates are kept does not change (threshold and "
            "relative read the score before it). Training with w > 0 fits the box model on "
            "the positives hitting housing boxes (not lens boxes); 0: off",
        ),
        Param("iterations", "int", 150, min=10, max=2000, help="training: boosting iterations"),
        Param("leaves", "int", 15, min=4, max=255, help="training: leaves per tree"),
        Param("learning_rate", "float", 0.1, min=0.001, max=1.0, help="training: learning rate"),
        Param(
            "negative_ratio",
            "float",
            3.0,
            min=0.5,
            max=100.0,
            help="training: negatives per positive in the first round (a seeded random draw)",
        ),
        Param(
            "mining_rounds",
            "int",
            1,
            min=0,
            max=5,
            help="training: rounds that add as many of the highest-scored remaining "
            "negatives (hard negatives) and refit",
        ),
        Param(
            "synthetic_frames",
            "int",
            120,
            min=0,
            max=10000,
            help="training: synthetic 1280x720 scenes without a lit light, mined for negatives "
            "(120 rather than 30 lowered leave-one-dataset-out false positives on every "
            "held-out set; 200 cost cinTA hits: benchmarks/RESULTS.verifier.md)",
        ),
        Param(
            "head_frames",
            "int",
            40,
            min=0,
            max=10000,
            help="training: synthetic 1280x720 scenes with 5 rendered lit heads each (jittered "
            "scale, colour, blur and exposure), whose candidates on a head are positives",
        ),
        Param(
            "head_horizontal",
            "float",
            0.5,
            min=0.0,
            max=1.0,
            help="training: the share of the rendered heads hung horizontally (Japan's, "
            "Korea's heads; 0.2 before horizontal heads were a held-out camera)",
        ),
        Param(
            "head_rims",
            "float",
            0.3,
            min=0.0,
            max=1.0,
            help="training: the share of the rendered heads with a light rim around the dark "
            "face (as Japan's heads show against dark hillsides; 0: none)",
        ),
        Param(
            "crop_frames",
            "int",
            80,
            min=0,
            max=10000,
            help="training: scenes with 5 real head crops pasted in each (udacity_mit_tl_crops "
            "train, housing height 10-110 px at 720 px, feathered edge: pasting.py), whose "
            "candidates on a crop are positives; needs that dataset (0: off). 80 on real "
            "backgrounds raised leave-one-dataset-out recall and hits on every held-out set "
            "(benchmarks/RESULTS.verifier.md)",
        ),
        Param(
            "crop_backgrounds",
            "str",
            "real",
            choices=("synthetic", "real"),
            help="training: what crop_frames paste into: the real training frames (spread "
            "evenly, clear of their boxes) or synthetic daylight no-light scenes (more false "
            "positives held out)",
        ),
        Param(
            "crop_own",
            "bool",
            True,
            help="training: crop_frames also paste the training sets' own housing boxes, cut "
            "out (a head of one camera on another camera's frame; lens boxes are not cut)",
        ),
        Param(
            "crop_rotate",
            "float",
            0.3,
            min=0.0,
            max=1.0,
            help="training: the share of pasted crops turned a quarter turn (vertical heads "
            "made horizontal and the reverse; 0: none)",
        ),
        Param(
            "augment_scales",
            "floats",
            (1.0,),
            min=0.25,
            max=3.0,
            help="training: every real training frame is seen resized by each of these factors "
            "(1: as it is), the detector and housing stage re-run on it, boxes scaled with it "
            "(a camera's other distances and resolutions: augment.py)",
        ),
        Param(
            "augment_colour",
            "int",
            2,
            min=0,
            max=10,
            help="training: extra full-size views of every real training frame and synthetic "
            "no-light scene under a random camera look (exposure, gamma, white balance, "
            "saturation, blur, JPEG: augment.py); 2 lowered leave-one-dataset-out false "
            "positives and raised held-out DTLD recall (benchmarks/RESULTS.verifier.md)",
        ),
        Param("seed", "int", 0, min=0, help="training: seed of the negative draw and the trees"),
    )

    def __init__(self, **params):
        super().__init__(**params)
        self._augmentation = Augmentation(  # checked now: a bad value fails before training
            tuple(self.params["augment_scales"]),
            self.params["augment_colour"],
            self.params["seed"],
        )
        self._estimator: HistGradientBoostingClassifier | None = None
        self._forest: Forest | None = None
        self._box_forest: Forest | None = None

    @property
    def estimator(self) -> HistGradientBoostingClassifier:
        """The trained classifier, loaded on first use.

        Raises
        ------
        tsrkit.plugin.models.ModelError
            A missing, corrupt or foreign model, or one trained on another feature layout.
        """
        if self._estimator is None:
            where = self._where()
            model = load_model(where, plugin=self.name)
            trained_on = model.info.get("layout")
            if trained_on != layout():
                version = trained_on.get("version") if isinstance(trained_on, dict) else None
                raise ModelError(
                    f"model {where}: trained on another feature layout (version {version!r}; "
                    f"this verifier reads version {layout()['version']}); retrain it "
                    "(tsrkit train verifier)"
                )
            after = str(model.info.get("after", ""))
            if after.split()[:1] != self._after().split()[:1]:
                raise ModelError(
                    f"model {where}: trained after the stage {after!r}, but this verifier runs "
                    f"after {self._after()!r}; set -p after={after} or retrain"
                )
            self._estimator = load_estimator(model, where)
            if self.params["box_rank"] > 0:
                if BOX_ARRAY not in model.arrays:
                    raise ModelError(
                        f"model {where}: has no box model; retrain it with -p box_rank=W "
                        "(W > 0) or set -p box_rank=0"
                    )
                box = load_estimator(model, where, name=BOX_ARRAY)
                self._box_forest = Forest.of(box, where)
        return self._estimator

    def _where(self) -> str:
        return str(self.params["model"] or DEFAULT_MODEL)

    @property
    def forest(self) -> Forest:
        """The estimator's trees as flat arrays (:mod:`forest`), for one-pass prediction."""
        if self._forest is None:
            self._forest = Forest.of(self.estimator, self._where())
        return self._forest

    @property
    def box_forest(self) -> Forest:
        """The box model's trees (loaded with the estimator when ``box_rank`` > 0).

        Raises
        ------
        tsrkit.plugin.models.ModelError
            ``box_rank`` is 0 (no box model is read).
        """
        self.estimator  # noqa: B018 (loads both models)
        if self._box_forest is None:
            raise ModelError("verifier: box_rank is 0; no box model is read")
        return self._box_forest

    def probabilities(self, frame: Frame, candidates: Sequence[Candidate]) -> np.ndarray:
        """The probability that each candidate is a lit traffic light (the estimator's
        ``predict_proba``, computed in one pass over its trees: :mod:`forest`)."""
        if not candidates:
            return np.zeros(0)
        return self.forest.probability(candidate_features(frame.image, candidates))

    def scores(
        self, frame: Frame, candidates: Sequence[Candidate], gate: bool = False
    ) -> tuple[list[Candidate], np.ndarray, np.ndarray]:
        """The candidates after the ``after`` stage, each one's decision score (the
        probability blended with the detector's score by ``prior``: what ``threshold`` and
        ``relative`` read) and the score it reports (the decision score, scaled by the box
        model where ``box_rank`` > 0). ``gate``: only the candidates that pass ``threshold``
        and ``relative`` (the box model reads those only)."""
        candidates = list(self._stage()(frame, list(candidates)))
        if not candidates:
            return candidates, np.zeros(0), np.zeros(0)
        features = candidate_features(frame.image, candidates)
        prior = self.params["prior"]
        own = np.clip([c.score for c in candidates], 0.0, 1.0)
        decision = (1.0 - prior) * self.forest.probability(features) + prior * own
        if gate:
            keep = passes(decision, self.params["threshold"], self.params["relative"])
            candidates = [c for c, k in zip(candidates, keep) if k]
            features, decision = features[keep], decision[keep]
        weight = self.params["box_rank"]
        if weight == 0 or not candidates:
            return candidates, decision, decision
        fits = self.box_forest.probability(features)
        return candidates, decision, decision * (1.0 - weight + weight * fits)

    def verify(self, frame: Frame, candidates: Sequence[Candidate]) -> list[Candidate]:
        kept, _, score = self.scores(frame, candidates, gate=True)
        return sorted(
            (replace(c, score=float(p)) for c, p in zip(kept, score)), key=lambda c: -c.score
        )

    def _after(self) -> str:
        """The spec of the stage run before this verifier ('' for none)."""
        return str(self.params["after"] or "")

    def _stage(self) -> Stage:
        part = self.params["after"]
        if part is None:
            return lambda frame, candidates: candidates
        before = part.plugin
        return lambda frame, candidates: before.verify(frame, candidates) if candidates else []

    def fit(self, samples: Iterable[Sample], *, detector: Detector | None = None) -> Model:
        """Learn to verify ``detector``'s candidates on ``samples`` (deterministic).

        Every real frame is seen at each factor of ``augment_scales`` and in
        ``augment_colour`` camera looks (:mod:`augment`). Every candidate is labelled by
        Zheng's centre rule; candidates of
        ``synthetic_frames`` no-light scenes are negatives, and those of ``head_frames`` scenes
        with rendered lit heads and ``crop_frames`` scenes with pasted real heads
        (:mod:`pasting`) are labelled by the heads' housings. The first round draws
        ``negative_ratio`` negatives per positive (seeded); each mining round adds as many of
        the remaining negatives the current model scores highest, and refits.

        Raises
        ------
        TsrkitError
            No detector, no positive or no negative candidate to learn from, or
            ``crop_frames`` > 0 without the crop set.
        """
        if detector is None:
            raise TsrkitError("verifier: fit needs the detector whose candidates it verifies")
        data = labelled_candidates(
            samples,
            detector,
            self._stage(),
            candidate_features,
            len(feature_names()),
            self.params["synthetic_frames"],
            Heads(
                self.params["head_frames"], self.params["head_horizontal"], self.params["head_rims"]
            ),
            self._augmentation,
            Crops(
                self.params["crop_frames"],
                self.params["crop_backgrounds"] == "real",
                self.params["crop_own"],
                self.params["crop_rotate"],
            ),
        )
        return self.fit_labelled(data)

    def fit_labelled(self, data: Labelled) -> Model:
        """Learn from labelled feature rows (:meth:`fit` after running the detector).

        Raises
        ------
        TsrkitError
            No positive or no negative row to learn from.
        """
        positives = np.flatnonzero(data.labels == 1)
        negatives = np.flatnonzero(data.labels == 0)
        if not len(positives) or not len(negatives):
            raise TsrkitError(
                f"verifier: {len(positives)} positive and {len(negatives)} negative candidates; "
                "need both (is the detector finding the annotated lights?)"
            )
        rng = np.random.default_rng(self.params["seed"])
        step = int(round(self.params["negative_ratio"] * len(positives)))
        chosen = np.sort(rng.permutation(negatives)[:step])
        estimator = self._fit_once(data.features, data.labels, np.concatenate([positives, chosen]))
        for _ in range(self.params["mining_rounds"]):
            rest = np.setdiff1d(negatives, chosen)
            if not len(rest):
                break
            probability = estimator.predict_proba(data.features[rest])[:, 1]
            hard = rest[hard_negatives(probability, data.labels[rest], step)]
            chosen = np.union1d(chosen, hard)
            estimator = self._fit_once(
                data.features, data.labels, np.concatenate([positives, chosen])
            )
        arrays = estimator_arrays(estimator)
        info = {
            "layout": layout(),
            "after": self._after(),
            "positives": int(len(positives)),
            "negatives": int(len(negatives)),
            "negatives_used": int(len(chosen)),
            "frames": int(data.frames.max() + 1) if len(data.frames) else 0,
        }
        if self.params["box_rank"] > 0:
            arrays |= self._fit_box(data)
            info["box_fits"] = int(np.count_nonzero(data.boxes == 1))
            info["box_misfits"] = int(np.count_nonzero(data.boxes == 0))
        return Model(arrays=arrays, info=info)

    def _fit_box(self, data: Labelled) -> dict[str, np.ndarray]:
        """The box model's arrays: fitted on every candidate with a box label.

        Raises
        ------
        TsrkitError
            No candidate whose housing fits, or none whose housing misses.
        """
        rows = np.flatnonzero(data.boxes >= 0)
        fits = int(np.count_nonzero(data.boxes[rows] == 1))
        if not fits or fits == len(rows):
            raise TsrkitError(
                f"verifier: box_rank needs candidates on housing boxes whose housing fits and "
                f"others whose housing misses; got {fits} and {len(rows) - fits} (train on "
                "housing-boxed data or rendered heads, or set box_rank=0)"
            )
        return estimator_arrays(self._fit_once(data.features, data.boxes, rows), BOX_ARRAY)

    def _fit_once(
        self, features: np.ndarray, labels: np.ndarray, rows: np.ndarray
    ) -> HistGradientBoostingClassifier:
        from sklearn.ensemble import HistGradientBoostingClassifier

        rows = np.sort(rows)
        estimator = HistGradientBoostingClassifier(
            max_iter=self.params["iterations"],
            max_leaf_nodes=self.params["leaves"],
            learning_rate=self.params["learning_rate"],
            class_weight="balanced",
            early_stopping=False,
            random_state=self.params["seed"],
        )
        return estimator.fit(features[rows], labels[rows])


@hookimpl
def register_verifiers(register):
    register(LearnedVerifier)
