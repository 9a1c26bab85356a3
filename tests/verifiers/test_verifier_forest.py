"""The verifier's trees evaluated in one pass (plugins/shared/forest.py) give exactly
scikit-learn's ``predict_proba``: on the shipped model's features of real and synthetic
candidates, with missing values, and on a model trained with missing values."""

from __future__ import annotations

import numpy as np
import pytest
from threadpoolctl import threadpool_limits

from tsrkit.core.types import Candidate
from tsrkit.datasets import open_dataset
from tsrkit.plugin.models import ModelError
from tsrkit.plugin.registry import get_registry
from tsrkit.synth import SynthOptions, render_frame
from tsrkit_plugins.shared.forest import Forest
from tsrkit_plugins.verifiers.features import candidate_features


def circles(rng, width, height, n=50):
    return [
        Candidate.from_circle(rng.uniform(0, width), rng.uniform(0, height), r, rng.random())
        for r in rng.uniform(1, 20, n)
    ]


@pytest.fixture(scope="module")
def features(shared_datasets):
    """Features of random candidates on a real cinTA frame and a synthetic 1280x720 scene."""
    rng = np.random.default_rng(5)
    sample = next(iter(open_dataset(shared_datasets / "roboflow_cinta_v2_id", format="normalized")))
    images = [sample.load().image, render_frame(2, 7, 1280, 720, SynthOptions())[0]]
    return np.concatenate(
        [candidate_features(im, circles(rng, im.shape[1], im.shape[0])) for im in images]
    )


def test_shipped_model_probabilities_are_sklearns_to_the_bit(features):
    verifier = get_registry().create("verifier", "verifier")
    expected = verifier.estimator.predict_proba(features)[:, 1]
    assert np.array_equal(verifier.forest.probability(features), expected)
    holes = features.copy()
    holes[np.random.default_rng(1).random(holes.shape) < 0.2] = np.nan
    assert np.array_equal(
        verifier.forest.probability(holes), verifier.estimator.predict_proba(holes)[:, 1]
    )


def test_a_single_row_is_sklearns_to_the_bit(features):
    """A frame with one candidate: its leaves are added one after the other, as scikit-learn
    adds them (a NumPy reduction of a lone row's leaves would add them pairwise: the form before
    this one differed from scikit-learn in the last bits on most single rows)."""
    verifier = get_registry().create("verifier", "verifier")
    for row in features[:40]:
        expected = verifier.estimator.predict_proba(row[None])[:, 1]
        assert np.array_equal(verifier.forest.probability(row[None]), expected)


def test_missing_values_follow_the_learned_side():
    from sklearn.ensemble import HistGradientBoostingClassifier

    rng = np.random.default_rng(2)
    x = rng.normal(size=(400, 4))
    y = (x[:, 0] + x[:, 1] > 0).astype(int)
    x[rng.random(x.shape) < 0.15] = np.nan
    y[np.isnan(x[:, 0])] = 1  # a missing first feature means positive: learned as a side
    with threadpool_limits(1):  # two OpenMP threads on a loaded machine take seconds
        model = HistGradientBoostingClassifier(max_iter=30, random_state=0).fit(x, y)
    forest = Forest.of(model, "memory")
    assert forest.nan_right.any() and not forest.nan_right.all()
    test = rng.normal(size=(100, 4))
    test[rng.random(test.shape) < 0.3] = np.nan
    assert np.array_equal(forest.probability(test), model.predict_proba(test)[:, 1])


def test_categorical_splits_are_refused():
    from sklearn.ensemble import HistGradientBoostingClassifier

    rng = np.random.default_rng(3)
    x = np.column_stack([rng.integers(0, 4, 200), rng.normal(size=200)])
    with threadpool_limits(1):
        model = HistGradientBoostingClassifier(max_iter=5, categorical_features=[0]).fit(
            x, (x[:, 0] == 2).astype(int)
        )
    with pytest.raises(ModelError, match="categorical"):
        Forest.of(model, "memory")
