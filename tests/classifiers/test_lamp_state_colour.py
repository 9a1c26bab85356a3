"""lamp-state's colour model: learned with the full model, mixed in by ``colour_weight``."""

from __future__ import annotations

import numpy as np
import pytest
from oracles.lamps import training_set
from threadpoolctl import threadpool_limits

import tsrkit
from tsrkit.core.types import Candidate, Frame
from tsrkit.plugin.models import Model, ModelError, load_model, save_model
from tsrkit_plugins.classifiers.lamp_state import labelled_features, prefer_red
from tsrkit_plugins.classifiers.lamp_state.colour import COLOUR, COLOUR_ARRAY, colour_columns
from tsrkit_plugins.classifiers.lamp_state.features import N_HUE, lamp_features
from tsrkit_plugins.shared.persistence import ARRAY, estimator_arrays


def save(path, model):
    save_model(path, model, plugin="lamp-state", plugin_version="0", params={}, training={})
    return str(path)


@pytest.fixture(scope="module")
def trained(tmp_path_factory):
    """A lamp-state model of the synthetic lamps (full and colour model) and its file."""
    with threadpool_limits(1):
        model = tsrkit.classifier("lamp-state", iterations=20).fit(training_set())
    return model, save(tmp_path_factory.mktemp("colour") / "model", model)


@pytest.fixture(scope="module")
def lights():
    """Every synthetic lamp as a frame with its lens candidates, and their features."""
    out = []
    for sample in training_set():
        frame = Frame(sample.load().image, sample.source)
        boxes = [Candidate.from_box(a.bbox, 1.0) for a in sample.annotations]
        out.append((frame, boxes, lamp_features(frame.image, boxes)))
    return out


def test_the_colour_columns_are_the_lab_means():
    rows = np.arange(2 * 43, dtype=np.float32).reshape(2, 43)
    assert (COLOUR.start, COLOUR.stop) == (2 * N_HUE, 2 * N_HUE + 4)
    taken = colour_columns(rows)
    assert taken.flags["C_CONTIGUOUS"] and taken.tolist() == rows[:, 22:26].tolist()


def test_fit_stores_a_colour_model_of_the_same_rows(trained):
    model, path = trained
    assert set(model.arrays) == {ARRAY, COLOUR_ARRAY}
    classifier = tsrkit.classifier("lamp-state", model=path)
    assert classifier.estimator.n_features_in_ == 43  # loads both
    estimator, _ = classifier._colour
    assert estimator.n_features_in_ == 4 and estimator.n_iter_ == 20  # the full model's
    x, y = labelled_features(training_set(), 3)
    assert np.mean(estimator.predict(colour_columns(x)) == y) > 0.9
    assert set(load_model(path, "lamp-state").arrays) == {ARRAY, COLOUR_ARRAY}


@pytest.mark.parametrize("weight", [0.0, 0.3, 1.0])
def test_scores_mix_the_two_models_by_colour_weight(trained, lights, weight):
    _, path = trained
    classifier = tsrkit.classifier("lamp-state", model=path, colour_weight=weight)
    full = classifier.estimator
    colour = classifier._colour[0]
    states = list(classifier._states)
    for frame, boxes, features in lights:
        expected = (1 - weight) * full.predict_proba(features) + weight * colour.predict_proba(
            features[:, COLOUR]
        )
        expected = prefer_red(expected, states, classifier.params["red_prior"])
        found = classifier.classify(frame, boxes)
        got = np.array([[d.state_scores[s] for s in states] for d in found])
        np.testing.assert_allclose(got, expected, rtol=0, atol=1e-12)


def test_a_model_without_a_colour_model_reads_the_full_model_alone(trained, lights, tmp_path):
    model, path = trained
    older = save(tmp_path / "older", Model({ARRAY: model.arrays[ARRAY]}, model.info))
    alone = tsrkit.classifier("lamp-state", model=older)
    off = tsrkit.classifier("lamp-state", model=path, colour_weight=0.0)
    mixed = tsrkit.classifier("lamp-state", model=path)
    differ = 0
    for frame, boxes, _ in lights:
        a, b, c = (k.classify(frame, boxes) for k in (alone, off, mixed))
        assert [d.state_scores for d in a] == [d.state_scores for d in b]
        differ += [d.state_scores for d in a] != [d.state_scores for d in c]
    assert alone._colour is None and differ > 0


def test_a_colour_model_of_other_columns_is_one_clear_error(trained, tmp_path):
    from sklearn.ensemble import HistGradientBoostingClassifier

    model, _ = trained
    x, y = labelled_features(training_set())
    with threadpool_limits(1):
        wrong = HistGradientBoostingClassifier(max_iter=3).fit(x[:, :6], y)
    arrays = {ARRAY: model.arrays[ARRAY], **estimator_arrays(wrong, COLOUR_ARRAY)}
    path = save(tmp_path / "wrong", Model(arrays, model.info))
    with pytest.raises(ModelError, match="colour model reads 6 features, not the 4 Lab means"):
        _ = tsrkit.classifier("lamp-state", model=path).estimator
