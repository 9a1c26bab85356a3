"""lamp-state batched (one-pass trees, one conversion per stack, looked-up hue bins and chroma)
gives exactly the features, states and scores of the computation it replaced
(tests/oracles/lamp_state_oracle.py), on real frames of three cameras and on synthetic ones."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from oracles import lamp_state_oracle as oracle
from oracles.frames import annotated_frames
from oracles.lamps import training_set
from threadpoolctl import threadpool_limits

import tsrkit
from tsrkit.core.types import Candidate, Frame
from tsrkit.plugin.models import Model, ModelError, save_model
from tsrkit.plugin.registry import get_registry
from tsrkit_plugins.classifiers.lamp_state.features import VERSION, housing_of, lamp_features
from tsrkit_plugins.shared.forest import Forest
from tsrkit_plugins.shared.persistence import estimator_arrays

PARAMS = [{}, {"ab_hist_weight": 0.5}, {"red_yellow_ratio": 1.0, "red_prior": 1.0}]


def housed(rng, width, height, n=30):
    """Lenses of radius 0.6-20 px anywhere in the frame (some cut by its border or wholly
    outside it), each with a tall (vertical head) or wide (horizontal head) housing."""
    out = []
    for k, r in enumerate(rng.uniform(0.6, 20, n)):
        x, y = rng.uniform(-30, width + 30), rng.uniform(-30, height + 30)
        lens = Candidate.from_circle(x, y, r, 1.0)
        long, short = rng.uniform(4, 8) * r, 1.3 * r
        box = (x - short, y - short, x + long, y + short)
        if k % 2:
            box = (x - short, y - short, x + short, y + long)
        out.append(dataclasses.replace(lens, housing=box, housing_score=0.5))
    return out


def frames(shared_datasets):
    """Two frames of each real detection set (lens and housing boxes) and two synthetic
    1280x720 scenes, each with candidates: its annotated boxes (read as housings when
    elongated), the housing stage's fit around their centres, random lenses with and
    without housings and random tall and wide boxes read as housings."""
    rng = np.random.default_rng(7)
    stage = get_registry().create("verifier", "housing")
    out = []
    for image, boxes in annotated_frames(shared_datasets):
        frame = Frame(image, "t")
        h, w = image.shape[:2]
        lenses = [Candidate.from_circle(c.x, c.y, max(c.radius / 3, 1.0), 1.0) for c in boxes]
        lenses += [
            Candidate.from_circle(x, y, r, 1.0)
            for x, y, r in rng.uniform((-10, -10, 0.6), (w + 10, h + 10, 20), (20, 3))
        ]
        # boxes without a fitted housing, read as housings (tall and wide), their lit lens found,
        # and annotated boxes given as their own housings (the lit lens found in them too)
        read_as_housings = [Candidate.from_box(c.housing, 1.0) for c in housed(rng, w, h, 10)]
        own = [dataclasses.replace(c, housing=c.bbox) for c in read_as_housings[:5] + boxes]
        out.append(
            (
                frame,
                boxes + stage.verify(frame, lenses) + housed(rng, w, h) + read_as_housings + own,
            )
        )
    return out


@pytest.fixture(scope="module")
def real(shared_datasets):
    return frames(shared_datasets)


@pytest.fixture(autouse=True)
def one_thread():
    """scikit-learn's prediction on one OpenMP thread: two on a loaded machine take seconds
    (the thread count does not change its sums)."""
    with threadpool_limits(1):
        yield


def test_features_equal_the_oracle(real):
    for frame, candidates in real:
        assert sum(c.housing is not None for c in candidates) > 20
        expected = oracle.lamp_features(frame.image, candidates)
        assert np.array_equal(lamp_features(frame.image, candidates), expected)
        assert np.array_equal(lamp_features(frame.image, candidates[3:4]), expected[3:4])
        # fitted horizontal housings alone, boxes read as housings alone, own housings alone
        for kind in (fitted_wide, unfitted, own_housing):
            some = [c for c in candidates if kind(c)]
            assert some
            expected = oracle.lamp_features(frame.image, some)
            assert np.array_equal(lamp_features(frame.image, some), expected)


def fitted_wide(candidate):
    box = candidate.housing
    return box is not None and box[2] - box[0] > box[3] - box[1]


def unfitted(candidate):
    return candidate.housing is None and housing_of(candidate) is not None


def own_housing(candidate):
    return candidate.housing == candidate.bbox


@pytest.mark.parametrize("params", PARAMS, ids=str)
def test_states_and_scores_equal_the_oracle(real, params):
    classifier = tsrkit.classifier("lamp-state", **params)
    checked = 0
    for frame, candidates in real:
        if params.get("ab_hist_weight"):  # ab-hist refuses lenses outside the frame
            h, w = frame.image.shape[:2]
            candidates = [c for c in candidates if 0 < c.x < w - 1 and 0 < c.y < h - 1]
        found = classifier.classify(frame, candidates)
        assert [d.candidate for d in found] == candidates
        expected = oracle.classify(classifier, frame, candidates)
        assert [(d.state, d.state_scores) for d in found] == expected  # exact, not approximate
        checked += len(found)
    assert checked > 300


def test_a_two_state_model_equals_the_oracle(real, tmp_path):
    two = [s for s in training_set() if s.annotations[0].state != "yellow"]
    model = tsrkit.classifier("lamp-state", iterations=15).fit(two)
    assert model.info["states"] == ["red", "green"]  # a binary estimator: one tree per iteration
    path = tmp_path / "two"
    save_model(path, model, plugin="lamp-state", plugin_version="0", params={}, training={})
    classifier = tsrkit.classifier("lamp-state", model=str(path))
    for frame, candidates in real[:3]:
        found = classifier.classify(frame, candidates)
        expected = oracle.classify(classifier, frame, candidates)
        assert [(d.state, d.state_scores) for d in found] == expected


def test_forest_sums_equal_scikit_learn_raw_predictions(real):
    estimator = tsrkit.classifier("lamp-state").estimator
    forest = Forest.of(estimator, "shipped", binary=False)
    features = np.concatenate([lamp_features(f.image, c) for f, c in real])
    assert np.array_equal(forest.raw(features), estimator._raw_predict(features))
    holes = features.copy()
    holes[np.random.default_rng(1).random(holes.shape) < 0.2] = np.nan
    assert np.array_equal(forest.raw(holes), estimator._raw_predict(holes))


def test_a_model_of_another_feature_count_is_one_clear_error(tmp_path):
    from sklearn.ensemble import HistGradientBoostingClassifier

    rng = np.random.default_rng(0)
    x = rng.normal(size=(60, 12))  # the trees would read past each row of the 43 features
    with threadpool_limits(1):
        estimator = HistGradientBoostingClassifier(max_iter=3).fit(x, np.arange(60) % 3)
    info = {"layout": VERSION, "states": ["red", "yellow", "green"]}
    path = tmp_path / "short"
    model = Model(arrays=estimator_arrays(estimator), info=info)
    save_model(path, model, plugin="lamp-state", plugin_version="0", params={}, training={})
    classifier = tsrkit.classifier("lamp-state", model=str(path))
    with pytest.raises(ModelError, match="12 features, this lamp-state reads 43"):
        classifier.classify(Frame(np.zeros((50, 50, 3), np.uint8), "x"), housed(rng, 50, 50, 2))
