"""adaboost-hsv: learning a colour on synthetic scenes, the lookup table, blobs, model I/O."""
from __future__ import annotations

import numpy as np
import pytest

from tsrkit.errors import TsrkitError
from tsrkit.models import load_model, save_model
from tsrkit.types import Annotation, Frame, Sample
from tsrkit_plugins.detectors import adaboost_hsv as ab

RED, GREEN = (20, 30, 230), (60, 200, 40)


def scene(rng, box, colour, size=(60, 80)):
    """Noisy grey-blue background, red specks, a green stripe and one filled coloured box."""
    image = rng.integers(60, 200, (*size, 3)).astype(np.uint8)
    image[..., 0] = np.clip(image[..., 0].astype(int) + 30, 0, 255)
    specks = rng.random(size) < 0.005
    image[specks] = RED
    image[-8:-2] = np.clip(np.array(GREEN) + rng.integers(-15, 16, (6, size[1], 3)), 0, 255)
    x0, y0, x1, y1 = box
    patch = np.array(colour) + rng.integers(-15, 16, (y1 - y0, x1 - x0, 3))
    image[y0:y1, x0:x1] = np.clip(patch, 0, 255)
    return image


def samples(seed, n=6, colour=RED):
    rng = np.random.default_rng(seed)
    out = []
    for _ in range(n):
        x0, y0 = rng.integers(5, 40), rng.integers(5, 30)
        box = (int(x0), int(y0), int(x0 + 15), int(y0 + 20))
        out.append(Sample(f"synthetic-{seed}", (Annotation(box, "red"),), image=scene(rng, box,
                                                                                    colour)))
    return out


def background_samples(seed, n=6):
    """Scenes without a target box (the negative images of Lee 3.2)."""
    rng = np.random.default_rng(seed)
    return [Sample(f"empty-{seed}", (), image=scene(rng, (0, 0, 0, 0), RED)) for _ in range(n)]


def make(**params):
    values = {p.name: p.default for p in ab.AdaBoostHSV.params}
    values.update(params)
    return ab.AdaBoostHSV(**values)


@pytest.fixture(scope="module")
def trained():
    det = make(n_estimators=20, min_size=5, max_boxes=3)
    model = det.fit(samples(1) + background_samples(11))
    det.use_model(model)
    return det, model


def test_learns_patch_to_near_perfect_pixel_accuracy(trained):
    det, model = trained
    counts = ab.pixel_histograms(samples(2), "red", 50)
    positive, negative = counts.positive, counts.negative
    assert counts.images == counts.target_images == 6 and model.info["prior"] == 0.5
    stumps = {k: model.arrays[k] for k in ab.STUMP_KEYS}
    f = ab.boosted_margin(ab.plane_features(), stumps)
    true_pos, true_neg = positive[f > 0].sum(), negative[f <= 0].sum()
    assert true_pos / positive.sum() > 0.99
    assert true_neg / negative.sum() > 0.99


def test_margin_matches_scikit_learn_decision():
    rng = np.random.default_rng(0)
    pos = rng.integers(0, 50, ab.LEVELS ** 2) * (rng.random(ab.LEVELS ** 2) < 0.01)
    neg = rng.integers(0, 50, ab.LEVELS ** 2) * (rng.random(ab.LEVELS ** 2) < 0.05)
    booster = ab.AdaBoostClassifier(ab.DecisionTreeClassifier(max_depth=1), n_estimators=7,
                                    random_state=0)
    x = ab.plane_features()
    cells = np.flatnonzero(pos + neg)
    booster.fit(x[cells], (pos[cells] > neg[cells]).astype(int))
    ours = ab.boosted_margin(x, ab.stump_arrays(booster))
    # scikit-learn's binary SAMME decision is 2 sum(w_i h_i) / sum(w_i); ours uses w_i / 2
    theirs = booster.decision_function(x) * booster.estimator_weights_.sum() / 4
    np.testing.assert_allclose(ours, theirs, atol=1e-9)


def test_probability_is_monotone_in_margin():
    margin = np.linspace(-8, 8, 401)
    for prior in (0.01, 0.5, 0.9):
        prob = ab.posterior(ab.margin_probability(margin), prior)
        assert np.all(np.diff(prob) > 0) or np.all(np.diff(prob[(prob > 1e-12)
                                                                 & (prob < 1 - 1e-12)]) > 0)
    assert ab.margin_probability(0.0) == pytest.approx(0.5)
    assert ab.margin_probability(1.0) == pytest.approx(np.e / (np.e + 1 / np.e))


def test_table_lookup_equals_direct_evaluation(trained):
    det, model = trained
    image = samples(3, n=1)[0].image
    stumps = {k: model.arrays[k] for k in ab.STUMP_KEYS}
    hue, sat, val = ab.hsv_planes(image)
    direct = ab.posterior(ab.margin_probability(
        ab.boosted_margin(ab.color_features(hue, sat), stumps)), model.info["prior"])
    direct[val.ravel() < 50] = 0
    fast = ab.probability_map(image, det.table(), 50)
    np.testing.assert_allclose(fast.ravel(), direct, rtol=1e-6, atol=1e-7)


def test_detects_box_and_ignores_other_colour(trained):
    det, _ = trained
    sample = samples(4, n=1)[0]
    found = det.detect(Frame(sample.image, "x"))
    assert len(found) == 1 and found[0].state == "red"
    np.testing.assert_allclose(found[0].bbox, sample.annotations[0].bbox, atol=1)
    green = samples(4, n=1, colour=GREEN)[0]
    assert det.detect(Frame(green.image, "x")) == []


def test_largest_first_nms_and_min_size():
    boxes = np.array([[0, 0, 10, 10], [1, 1, 9, 9], [20, 20, 24, 24]], float)
    assert ab.largest_first_nms(boxes, 0.3, 5).tolist() == [0, 2]
    assert ab.largest_first_nms(boxes, 0.3, 1).tolist() == [0]
    binary = np.zeros((20, 20), bool)
    binary[2:4, 2:12] = True
    binary[10:12, 10:12] = True
    found, _, _ = ab.blob_boxes(binary, 5)
    assert found.tolist() == [[2, 2, 12, 4]]


def test_two_colour_expansion():
    grown = ab.expand_two_colour(np.array([10, 5, 30, 10.0]), 1.25, 100)
    assert grown.tolist() == [10, 5, 30, 30]
    tall = np.array([0, 0, 5, 10.0])
    assert ab.expand_two_colour(tall, 1.25, 100).tolist() == tall.tolist()


def test_model_round_trip(tmp_path, trained):
    det, model = trained
    path = save_model(tmp_path / "m", model, plugin="adaboost-hsv", plugin_version="0",
                      params=det.params, training={})
    loaded = make(model=str(path), min_size=5, max_boxes=3)
    image = samples(5, n=1)[0].image
    np.testing.assert_array_equal(loaded.table(), det.table())
    assert loaded.detect(Frame(image, "x")) == det.detect(Frame(image, "x"))
    assert load_model(path, "adaboost-hsv").info["target"] == "red"


def test_errors():
    with pytest.raises(TsrkitError, match="needs a model"):
        make().detect(Frame(np.zeros((4, 4, 3), np.uint8), "x"))
    with pytest.raises(ValueError, match="target and background"):
        ab.fit_stumps(np.zeros(ab.LEVELS ** 2), np.ones(ab.LEVELS ** 2), 3, 0)
    det, model = make(target="green"), make().fit(samples(1, n=2))
    with pytest.raises(TsrkitError, match="detects 'red'"):
        det.use_model(model)
