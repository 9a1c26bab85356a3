"""The verifier's box model (``box_rank``): labels, training, model file, and the order it gives."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from scipy.special import logit
from test_verifier import FAST, lamp_scene, make, tiny_dataset

from tsrkit.core.types import Candidate, Frame
from tsrkit.plugin.models import ModelError, load_model
from tsrkit.plugin.registry import get_registry
from tsrkit.runner.training import train
from tsrkit_plugins.shared.forest import Forest
from tsrkit_plugins.shared.persistence import BOX_ARRAY, load_estimator
from tsrkit_plugins.verifiers import features as F
from tsrkit_plugins.verifiers.mining import box_labels

#: Two scenes of rendered heads (mostly vertical, no rims): candidates on them whose housing fits
#: and one whose misses.
BOXED = dict(FAST, head_frames=2, head_horizontal=0.2, head_rims=0.0, box_rank=0.5)


@pytest.fixture(scope="module")
def trained(tmp_path_factory):
    folder = tmp_path_factory.mktemp("boxrank")
    detector = get_registry().create("detector", "gray-tophat")
    boxed = [train("verifier", tiny_dataset(), folder / f"box{k}", BOXED, detector) for k in (1, 2)]
    plain = train("verifier", tiny_dataset(), folder / "plain", dict(BOXED, box_rank=0.0), detector)
    return boxed, plain


def test_box_labels_need_a_centre_hit_on_a_housing_box_and_read_the_fitted_housing():
    housed = dataclasses.replace(Candidate.from_circle(10, 5, 2, 1), housing=(6, 0, 14, 21))
    across = dataclasses.replace(Candidate.from_circle(10, 15, 2, 1), housing=(0, 13, 30, 21))
    bare = Candidate.from_circle(10, 10, 2, 1)  # no housing: its lens box, IoU 16 / 160
    # housing box 8 x 20 (aspect 2.5): IoU 160 / 168, 56 / 344, 16 / 160
    assert box_labels([housed, across, bare], [(6, 0, 14, 20)]).tolist() == [1, 0, 0]
    # a second, wide housing box across the head: one fitting box is enough
    assert box_labels([across], [(6, 0, 14, 20), (0, 13, 30, 20)]).tolist() == [1]
    # a lens box (aspect 1) gives no box label, nor does a miss
    assert box_labels([housed, bare], [(8, 8, 12, 12)]).tolist() == [-1, -1]
    assert box_labels([housed], [(50, 0, 58, 20)]).tolist() == [-1]
    assert box_labels([], [(6, 0, 14, 20)]).tolist() == []


def test_box_model_training_is_deterministic_and_separate(trained):
    (a, b), plain = trained
    first, second = (load_model(p, "verifier") for p in (a, b))
    assert set(first.arrays) == {"estimator_skops", BOX_ARRAY}
    for key in first.arrays:
        assert np.array_equal(first.arrays[key], second.arrays[key])
    assert first.info["box_fits"] > 0 and first.info["box_misfits"] > 0
    # the light model is the one trained without box_rank: the keep decision is unchanged
    alone = load_model(plain, "verifier")
    assert set(alone.arrays) == {"estimator_skops"} and "box_fits" not in alone.info
    assert np.array_equal(alone.arrays["estimator_skops"], first.arrays["estimator_skops"])


def test_box_model_round_trip_and_the_reported_score(trained):
    (path, _), _ = trained
    frame = tiny_dataset(1).samples[0].load()
    candidates = get_registry().create("detector", "gray-tophat").detect(frame)
    verifier = make(model=str(path), threshold=0.0, box_rank=0.5)
    staged, decision, score = verifier.scores(frame, candidates)
    assert staged
    box = load_estimator(load_model(path, "verifier"), "x", name=BOX_ARRAY)
    fits = box.predict_proba(F.candidate_features(frame.image, staged))[:, 1]
    assert np.allclose(decision, verifier.probabilities(frame, staged))
    assert np.allclose(score, decision * (0.5 + 0.5 * fits))
    kept = verifier.verify(frame, candidates)
    assert [c.score for c in kept] == sorted(score.tolist(), reverse=True)


def test_box_rank_on_a_model_without_a_box_model_is_one_clear_error(trained):
    _, plain = trained
    frame = Frame(lamp_scene(), "lamp")
    with pytest.raises(ModelError, match="no box model"):
        make(model=str(plain), box_rank=0.5).verify(frame, [Candidate.from_circle(80, 30, 6, 1)])


def split(feature: int, at: float, low: float, high: float) -> Forest:
    """One tree, one split: probability ``low`` where ``feature <= at``, else ``high``."""
    return Forest(
        baseline=np.zeros(1),
        roots=np.array([0]),
        depths=np.array([1]),
        feature=np.array([feature, 0, 0]),
        threshold=np.array([at, 0.0, 0.0]),
        nan_right=np.zeros(3, bool),
        children=np.array([[1, 2], [1, 1], [2, 2]]),  # node 0 -> nodes 1, 2; leaves
        value=np.array([0.0, logit(low), logit(high)]),
    )


def hand_verifier(box_rank: float, **params):
    """A verifier whose light model gives 0.8 to a candidate of detector score > 0.5 and 0.6
    to the others, and whose box model gives those 0.02 and 0.98."""
    verifier = make(after="", box_rank=box_rank, **params)
    column = F.feature_names().index("score")
    verifier._estimator = "set by hand"  # nothing to load
    verifier._forest = split(column, 0.5, 0.6, 0.8)
    verifier._box_forest = split(column, 0.5, 0.98, 0.02)
    return verifier


def test_box_rank_reorders_the_kept_candidates_and_keeps_the_same_ones():
    frame = Frame(lamp_scene(), "lamp")
    light = Candidate.from_circle(80, 30, 6, 0.9)  # light model 0.8, its housing misses
    other = Candidate.from_circle(40, 90, 6, 0.2)  # light model 0.6, its housing fits

    def kept(box_rank, **params):
        found = hand_verifier(box_rank, **params).verify(frame, [light, other])
        return [(c.x, round(c.score, 6)) for c in found]

    assert kept(0.0, threshold=0.5) == [(80, 0.8), (40, 0.6)]
    # 0.8 x (0.5 + 0.5 x 0.02) = 0.408 and 0.6 x (0.5 + 0.5 x 0.98) = 0.594: the order turns;
    # both are still kept at threshold 0.5 (read on 0.8 and 0.6), though 0.408 is below it
    assert kept(0.5, threshold=0.5) == [(40, 0.594), (80, 0.408)]
    assert kept(1.0, threshold=0.5) == [(40, 0.588), (80, 0.016)]
    # relative 0.8 of the frame's best decision (0.64) drops the other whatever its box
    assert kept(0.5, threshold=0.0, relative=0.8) == [(80, 0.408)]
    assert kept(0.5, threshold=0.7) == [(80, 0.408)]
