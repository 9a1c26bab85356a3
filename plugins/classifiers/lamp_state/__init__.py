"""``lamp-state``: a trainable state classifier that reads the lit lamp's colour, its rim and its
position in the housing, learned from several cameras at once.

Beyond the documents: Zheng's ab-hist and Lee's hsi-backprojection stay available,
unchanged, beside it. Features: :mod:`.features`; model: scikit-learn's
``HistGradientBoostingClassifier`` stored with skops (explicit trusted types, no pickle; see
``tsrkit_plugins.shared.persistence``). ``red_yellow`` is a state of its own where the
training data labels it (DTLD); other labels (arrows, off) are passed over in training. Where
no training set labels it, a light read red or amber whose housing has its top and middle slots
both lit, the top one red (:func:`~.features.two_lit` above ``red_yellow_ratio``), is read
red+amber (:func:`red_yellow`); a box taller than wide but too square to be read as a housing is
read so too (:func:`~.features.red_amber_rows`).
The classes are not reweighted, and the learned red probability counts ``red_prior`` times
(:func:`prefer_red`): red is the most common state of every set and the costly one to miss, so
a lamp whose colour sits between red and amber (orange-red LEDs, white cores) reads red.
``colour_weight`` mixes in a second model learned from the lamp's CIELab colour alone
(:mod:`.colour`: the full model's hue histograms let another camera's halo outweigh the core).
``ab_hist_weight`` mixes ab-hist's normalised scores into the learned probabilities (a late
fusion, :func:`blend`; measured in ``benchmarks/RESULTS.state.md``).
The model's trees are evaluated for all of a frame's candidates in one pass
(``tsrkit_plugins.shared.forest``) and turned into probabilities by the estimator's own
loss: scikit-learn's ``predict_proba`` to the bit, without its per-tree calls
(``tests/classifiers/test_lamp_state_oracle.py``).
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from pathlib import Path
from typing import TYPE_CHECKING

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
    ParamError,
    Sample,
    TsrkitError,
    hookimpl,
    load_model,
)
from tsrkit_plugins.classifiers.lamp_state.colour import (
    COLOUR,
    COLOUR_ARRAY,
    colour_columns,
    mix,
)
from tsrkit_plugins.classifiers.lamp_state.features import (
    N_FEATURES,
    TWO_LIT,
    VERSION,
    lamp_features,
    red_amber_rows,
)
from tsrkit_plugins.classifiers.lamp_state.views import around_lights, quarter_turn
from tsrkit_plugins.shared.forest import Forest
from tsrkit_plugins.shared.persistence import estimator_arrays, load_estimator

if TYPE_CHECKING:  # scikit-learn loads when a model is fitted or read, not on import
    from sklearn.ensemble import HistGradientBoostingClassifier

#: The states lamp-state can learn (those present in the training data are learned).
STATES = ("red", "yellow", "green", "red_yellow")
DEFAULT_MODEL = Path(__file__).parent / "models" / "lamp_state_default"


#: Exposure range of the jittered views (a gain, drawn log-uniform): other cameras' exposure,
#: up to the over-exposed white cores with a coloured rim of dash-cams.
EXPOSURE = (0.8, 3.0)


def colour_jitter(image: np.ndarray, rng: np.random.Generator) -> np.ndarray:
    """``image`` as another camera might see it: channel gains in [0.85, 1.15] (white balance)
    times one exposure gain in :data:`EXPOSURE` (bright lamps clip to white), and a gamma in
    [0.8, 1.25] (response curve), drawn from ``rng``."""
    gains = rng.uniform(0.85, 1.15, 3)
    gamma = rng.uniform(0.8, 1.25)
    gains = gains * np.exp(rng.uniform(np.log(EXPOSURE[0]), np.log(EXPOSURE[1])))
    scaled = np.clip(image.astype(np.float32) * (gains / 255.0), 0.0, 1.0)
    return (255.0 * scaled**gamma).astype(np.uint8)


def labelled_features(
    samples: Iterable[Sample], copies: int = 0, seed: int = 0, turned: float = 0.0
) -> tuple[np.ndarray, np.ndarray]:
    """Features and state indices of every annotation in :data:`STATES`, plus ``copies``
    colour-jittered views of each (:func:`colour_jitter`); of a frame none of whose lights is
    wider than tall, each jittered view is also turned a quarter (either way, :mod:`.views`)
    with probability ``turned``. Seeded: deterministic. The views are made of the part of the
    frame the features read (:func:`~.views.around_lights`), with the same values."""
    rng = np.random.default_rng(seed)
    turns = np.random.default_rng([seed, 1])
    rows, labels = [], []
    for sample in samples:
        wanted = [a for a in sample.annotations if a.state in STATES]
        if not wanted:
            continue
        image, boxes = around_lights(sample.load().image, [a.bbox for a in wanted])
        upright = all(y1 - y0 >= x1 - x0 for x0, y0, x1, y1 in boxes)
        for view in range(copies + 1):
            seen, at = image, boxes
            if view:
                seen = colour_jitter(image, rng)
                if upright and turns.random() < turned:
                    seen, at = quarter_turn(seen, boxes, bool(turns.random() < 0.5))
            rows.append(lamp_features(seen, [Candidate.from_box(b, 1.0) for b in at]))
            labels += [STATES.index(a.state) for a in wanted]
    if not rows:
        return np.zeros((0, N_FEATURES), np.float32), np.zeros(0, np.int64)
    return np.concatenate(rows), np.array(labels, np.int64)


def blend(
    probability: np.ndarray, states: Sequence[str], other: np.ndarray, weight: float
) -> np.ndarray:
    """``(1 - weight)`` x lamp-state's ``probability`` (columns: ``states``) plus ``weight`` x
    another classifier's scores ``other`` (columns: :data:`STATES`, each row normalised to sum
    1), as an (N, len(STATES)) table.

    Examples
    --------
    >>> blend(np.array([[0.8, 0.2]]), ["red", "green"], np.array([[0.0, 3.0, 1.0, 0.0]]), 0.5)
    array([[0.4  , 0.375, 0.225, 0.   ]])
    """
    table = np.zeros((len(probability), len(STATES)))
    table[:, [STATES.index(s) for s in states]] = probability
    other = other / np.maximum(other.sum(axis=1, keepdims=True), 1e-9)
    return (1 - weight) * table + weight * other


def prefer_red(probability: np.ndarray, states: Sequence[str], factor: float) -> np.ndarray:
    """``probability`` (columns: ``states``) with its red column times ``factor``, each row
    renormalised to sum 1.

    Examples
    --------
    >>> prefer_red(np.array([[0.4, 0.6]]), ["red", "yellow"], 2.0)
    array([[0.57142857, 0.42857143]])
    """
    out = probability * np.where(np.asarray(states) == "red", factor, 1.0)
    return out / np.maximum(out.sum(axis=1, keepdims=True), 1e-12)


def red_yellow(table: np.ndarray, features: np.ndarray, ratio: float) -> np.ndarray:
    """``table`` (columns: :data:`STATES`) with the top state and red+amber swapped on the rows
    read red or yellow whose :func:`~.features.two_lit` (column ``TWO_LIT`` of ``features``)
    exceeds ``ratio``.

    Examples
    --------
    >>> features = np.zeros((2, N_FEATURES)); features[:, TWO_LIT] = (0.9, 0.2)
    >>> red_yellow(np.array([[0.7, 0.2, 0.1, 0.0], [0.2, 0.7, 0.1, 0.0]]), features, 0.5)
    array([[0. , 0.2, 0.1, 0.7],
           [0.2, 0.7, 0.1, 0. ]])
    """
    out = table.copy()
    top = np.argmax(table, axis=1)
    both = STATES.index("red_yellow")
    read = np.isin(top, [STATES.index("red"), STATES.index("yellow")])
    rows = np.flatnonzero(read & (features[:, TWO_LIT] > ratio))
    out[rows, top[rows]], out[rows, both] = table[rows, both], table[rows, top[rows]]
    return out


def fit_estimator(
    features: np.ndarray, labels: np.ndarray, params
) -> tuple[HistGradientBoostingClassifier, list[str]]:
    """The classifier of ``labels`` (indices into :data:`STATES`) and the states it knows."""
    from sklearn.ensemble import HistGradientBoostingClassifier

    present = sorted(set(labels.tolist()))
    estimator = HistGradientBoostingClassifier(
        max_iter=params["iterations"],
        max_leaf_nodes=params["leaves"],
        learning_rate=params["learning_rate"],
        class_weight=None,
        early_stopping=False,
        random_state=params["seed"],
    ).fit(features, np.searchsorted(present, labels))
    return estimator, [STATES[i] for i in present]


def fit_colour(features: np.ndarray, labels: np.ndarray, params) -> HistGradientBoostingClassifier:
    """The colour model (:mod:`.colour`) of ``labels``: :func:`fit_estimator` on the lamp's
    CIELab columns of ``features``."""
    return fit_estimator(colour_columns(features), labels, params)[0]


def learned_probability(
    estimator: HistGradientBoostingClassifier,
    colour: HistGradientBoostingClassifier,
    features: np.ndarray,
    weight: float,
) -> np.ndarray:
    """The full model's and the colour model's ``predict_proba`` of ``features`` mixed with
    the colour model's ``weight`` (:func:`~.colour.mix`), as ``classify`` reads them."""
    colour_probability = colour.predict_proba(colour_columns(features))
    return mix(estimator.predict_proba(features), colour_probability, weight)


class LampState(Classifier):
    """Lit-lamp colour, rim colour and position in the housing, gradient boosted."""

    name = "lamp-state"
    summary = "learned state: lamp and rim colour plus lit position in the housing (trainable)"
    section = "beyond the documents"
    PARAMS = (
        Param(
            "model",
            "path",
            None,
            help="trained model (tsrkit train lamp-state); unset: the shipped model, trained on "
            "openly licensed sets only (MIT, VGIS, KR valid, cinTA valid)",
        ),
        Param("iterations", "int", 100, min=10, max=2000, help="training: boosting iterations"),
        Param("leaves", "int", 15, min=4, max=255, help="training: leaves per tree"),
        Param("learning_rate", "float", 0.1, min=0.001, max=1.0, help="training: learning rate"),
        Param(
            "copies",
            "int",
            3,
            min=0,
            max=20,
            help="training: colour-jittered views added per light (camera white balance and "
            "response), for states that carry over to unseen cameras",
        ),
        Param(
            "turned",
            "float",
            0.5,
            min=0.0,
            max=1.0,
            help="training: share of the jittered views of frames without horizontal heads "
            "turned a quarter (either way), so that horizontal heads are learned",
        ),
        Param("seed", "int", 0, min=0, help="training: seed of the jitter and the trees"),
        Param(
            "colour_weight",
            "float",
            0.3,
            min=0.0,
            max=1.0,
            help="weight of the second model, learned from the lamp's CIELab colour alone (core "
            "and rim), mixed with the full model's probabilities; 0 reads the full model alone, "
            "as does a model trained without a colour model (older models keep their outputs)",
        ),
        Param(
            "ab_hist_weight",
            "float",
            0.0,
            min=0.0,
            max=1.0,
            help="weight of the fused classifier's scores (normalised) mixed with the learned "
            "probabilities; 0.5 is the late fusion of benchmarks/RESULTS.state.md",
        ),
        Param(
            "fused",
            "classifier",
            "ab-hist",
            help="the classifier whose scores ab_hist_weight mixes in, with its own parameters "
            "('ab-hist model=PATH'); '' for none (then ab_hist_weight must be 0)",
        ),
        Param(
            "red_prior",
            "float",
            2.0,
            min=1.0,
            max=10.0,
            help="the learned red probability counts this many times (red is the common and "
            "the costly state: an ambiguous red/amber reads red); 1 reads the learned "
            "probabilities as they are",
        ),
        Param(
            "red_yellow_ratio",
            "float",
            0.5,
            min=0.0,
            max=1.0,
            help="a light read red or amber is read red+amber when its housing's (or its box's, "
            "if taller than wide) top slot is red and it and the middle slot are lit above this "
            "share of the brightest slot's height over the bottom one; 1 switches it off",
        ),
    )

    def __init__(self, **params):
        super().__init__(**params)
        if self.params["ab_hist_weight"] > 0 and self.params["fused"] is None:
            raise ParamError(
                "classifier 'lamp-state': ab_hist_weight > 0 needs a 'fused' classifier"
            )
        self._estimator: HistGradientBoostingClassifier | None = None
        self._forest: Forest | None = None
        self._colour: tuple[HistGradientBoostingClassifier, Forest] | None = None
        self._states: tuple[str, ...] = ()

    @property
    def estimator(self) -> HistGradientBoostingClassifier:
        """The trained classifier, loaded on first use.

        Raises
        ------
        tsrkit.plugin.models.ModelError
            A missing, corrupt or foreign model, or one of another feature layout or count.
        """
        if self._estimator is None:
            where = str(self.params["model"] or DEFAULT_MODEL)
            model = load_model(where, plugin=self.name)
            if model.info.get("layout") != VERSION:
                raise ModelError(
                    f"model {where}: feature layout {model.info.get('layout')!r}, this "
                    f"lamp-state reads {VERSION}; retrain it (tsrkit train lamp-state)"
                )
            states = model.info.get("states")
            if not isinstance(states, list) or not set(states) <= set(STATES):
                raise ModelError(f"model {where}: 'states' must be a list of {STATES}")
            estimator = load_estimator(model, where, classes=list(range(len(states))))
            if estimator.n_features_in_ != N_FEATURES:
                raise ModelError(
                    f"model {where}: {estimator.n_features_in_} features, this lamp-state "
                    f"reads {N_FEATURES}; retrain it (tsrkit train lamp-state)"
                )
            self._colour = self._colour_model(model, where, len(states))
            self._estimator, self._states = estimator, tuple(states)
        return self._estimator

    @staticmethod
    def _colour_model(
        model: Model, where: str, states: int
    ) -> tuple[HistGradientBoostingClassifier, Forest] | None:
        """The colour model of ``model`` and its trees, or None when it holds none (a model
        trained before it: the full model is read alone)."""
        if COLOUR_ARRAY not in model.arrays:
            return None
        colour = load_estimator(model, where, classes=list(range(states)), name=COLOUR_ARRAY)
        if colour.n_features_in_ != COLOUR.stop - COLOUR.start:
            raise ModelError(
                f"model {where}: its colour model reads {colour.n_features_in_} features, "
                f"not the {COLOUR.stop - COLOUR.start} Lab means; retrain it"
            )
        return colour, Forest.of(colour, where, binary=False)

    @property
    def forest(self) -> Forest:
        """The estimator's trees as flat arrays, for one-pass prediction."""
        if self._forest is None:
            where = str(self.params["model"] or DEFAULT_MODEL)
            self._forest = Forest.of(self.estimator, where, binary=False)
        return self._forest

    def probability(self, features: np.ndarray) -> np.ndarray:
        """The estimator's ``predict_proba`` of ``features`` mixed with its colour model's
        (``colour_weight``, :func:`learned_probability`), to the bit: one pass over each
        model's trees (:attr:`forest`), the sums turned into probabilities by the estimator's
        own loss."""
        full = self.estimator._loss.predict_proba(self.forest.raw(features))
        weight = self.params["colour_weight"]
        if self._colour is None or weight == 0:
            return full
        colour, trees = self._colour
        return mix(full, colour._loss.predict_proba(trees.raw(colour_columns(features))), weight)

    def classify(self, frame: Frame, candidates: Sequence[Candidate]) -> list[Detection]:
        if not candidates:
            return []
        features = lamp_features(frame.image, candidates)
        probability = prefer_red(self.probability(features), self._states, self.params["red_prior"])
        weight = self.params["ab_hist_weight"]
        known = set(self._states)
        if weight > 0:
            found = self.params["fused"].plugin.classify(frame, candidates)
            known |= {s for d in found for s in d.state_scores}
            other = np.array([[d.state_scores.get(s, 0.0) for s in STATES] for d in found])
        else:
            other = np.zeros((len(candidates), len(STATES)))
        ratio = self.params["red_yellow_ratio"]
        rule = red_amber_rows(frame.image, candidates, features)
        table = red_yellow(blend(probability, self._states, other, weight), rule, ratio)
        if ratio < 1:
            known.add("red_yellow")
        columns = [k for k, s in enumerate(STATES) if s in known]
        names = [STATES[k] for k in columns]
        best = [STATES[k] for k in np.argmax(table, axis=1).tolist()]
        return [
            Detection(candidate, state, dict(zip(names, row)))
            for candidate, state, row in zip(candidates, best, table[:, columns].tolist())
        ]

    def fit(self, samples: Iterable[Sample], *, detector: Detector | None = None) -> Model:
        """Learn the states of the annotated lights of ``samples`` and of ``copies``
        colour-jittered views of each (deterministic for a given ``seed``): the full model and
        the colour model (:mod:`.colour`), both from the same rows.

        Raises
        ------
        TsrkitError
            Fewer than two states among the annotations.
        """
        features, labels = labelled_features(
            samples, self.params["copies"], self.params["seed"], self.params["turned"]
        )
        present = sorted(set(labels.tolist()))
        if len(present) < 2:
            raise TsrkitError(
                f"lamp-state: {len(labels)} labelled lights of {len(present)} state(s); need "
                f"at least two of {', '.join(STATES)}"
            )
        estimator, states = fit_estimator(features, labels, self.params)
        counts = np.bincount(np.searchsorted(present, labels), minlength=len(states))
        colour = fit_colour(features, labels, self.params)
        return Model(
            arrays={**estimator_arrays(estimator), **estimator_arrays(colour, COLOUR_ARRAY)},
            info={
                "layout": VERSION,
                "states": states,
                "counts": {s: int(n) for s, n in zip(states, counts)},
            },
        )


@hookimpl
def register_classifiers(register):
    register(LampState)
