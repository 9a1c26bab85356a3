"""adaboost-hsv: learning a colour on synthetic scenes, the lookup table, blobs, model I/O."""

from __future__ import annotations

import cv2
import numpy as np
import pytest
from sklearn.ensemble import AdaBoostClassifier
from sklearn.tree import DecisionTreeClassifier

from tsrkit.core.errors import TsrkitError
from tsrkit.core.types import Annotation, Frame, Sample
from tsrkit.plugin.models import load_model, save_model
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
        out.append(
            Sample(f"synthetic-{seed}", (Annotation(box, "red"),), image=scene(rng, box, colour))
        )
    return out


def background_samples(seed, n=6):
    """Scenes without a target box (the negative images of Lee 3.2)."""
    rng = np.random.default_rng(seed)
    return [Sample(f"empty-{seed}", (), image=scene(rng, (0, 0, 0, 0), RED)) for _ in range(n)]


def make(**params):
    values = {p.name: p.default for p in ab.AdaBoostHSV.PARAMS}
    values.update(params)
    return ab.AdaBoostHSV(**values)


@pytest.fixture(scope="module")
def trained():
    det = make(target="red", labels="box", n_estimators=20, min_size=5, max_boxes=3)
    model = det.fit(samples(1) + background_samples(11))
    det.use_model(model)
    return det, model


def test_learns_patch_to_near_perfect_pixel_accuracy(trained):
    _det, model = trained
    counts = ab.pixel_histograms(samples(2), ("red",), 50, "box")
    positive, negative = counts.positive[0], counts.negative[0]
    assert counts.images == counts.target_images[0] == 6 and model.info["priors"]["red"] == 0.5
    stumps = {k: model.arrays[f"red_{k}"] for k in ab.STUMP_KEYS}
    f = ab.boosted_margin(ab.plane_features(), stumps)
    true_pos, true_neg = positive[f > 0].sum(), negative[f <= 0].sum()
    assert true_pos / positive.sum() > 0.99
    assert true_neg / negative.sum() > 0.99


def test_margin_matches_scikit_learn_decision():
    rng = np.random.default_rng(0)
    pos = rng.integers(0, 50, ab.LEVELS**2) * (rng.random(ab.LEVELS**2) < 0.01)
    neg = rng.integers(0, 50, ab.LEVELS**2) * (rng.random(ab.LEVELS**2) < 0.05)
    booster = AdaBoostClassifier(
        DecisionTreeClassifier(max_depth=1), n_estimators=7, random_state=0
    )
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
        assert np.all(np.diff(prob) > 0) or np.all(
            np.diff(prob[(prob > 1e-12) & (prob < 1 - 1e-12)]) > 0
        )
    assert ab.margin_probability(0.0) == pytest.approx(0.5)
    assert ab.margin_probability(1.0) == pytest.approx(np.e / (np.e + 1 / np.e))


def test_table_lookup_equals_direct_evaluation(trained):
    det, model = trained
    image = samples(3, n=1)[0].image
    stumps = {k: model.arrays[f"red_{k}"] for k in ab.STUMP_KEYS}
    hue, sat, val = ab.hsv_planes(image)
    direct = ab.posterior(
        ab.margin_probability(ab.boosted_margin(ab.color_features(hue, sat), stumps)),
        model.info["priors"]["red"],
    )
    direct[val.ravel() < 50] = 0
    fast, colour = ab.probability_map(image, det.table(), det._colour, 50)
    assert not colour.any()
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
    path = save_model(
        tmp_path / "m",
        model,
        plugin="adaboost-hsv",
        plugin_version="0",
        params=det.params,
        training={},
    )
    loaded = make(model=str(path), target="red", min_size=5, max_boxes=3)
    image = samples(5, n=1)[0].image
    np.testing.assert_array_equal(loaded.table(), det.table())
    assert loaded.detect(Frame(image, "x")) == det.detect(Frame(image, "x"))
    assert load_model(path, "adaboost-hsv").info["targets"] == ["red"]


def test_errors():
    with pytest.raises(ValueError, match="target and background"):
        ab.fit_stumps(np.zeros(ab.LEVELS**2), np.ones(ab.LEVELS**2), 3, 0)
    det, model = make(target="green"), make(target="red", labels="box").fit(samples(1, n=2))
    with pytest.raises(TsrkitError, match="needs \\['green'\\]"):
        det.use_model(model)
    with pytest.raises(ValueError, match="'box' or 'lens'"):
        ab.box_target_mask(np.zeros((2, 2)), np.zeros((2, 2)), "ring", 50)


def lit_housing(rng, lit, size=(30, 12)):
    """A dark housing with three lenses: the ``lit`` one (0 top .. 2 bottom) bright and vivid."""
    image = np.full((*size, 3), 40, np.uint8) + rng.integers(0, 10, (*size, 3)).astype(np.uint8)
    colours = (RED, (20, 200, 240), GREEN)
    for i, colour in enumerate(colours):
        centre = (6, 5 + 10 * i)
        shade = colour if i == lit else tuple(c // 8 for c in colour)
        cv2.circle(image, centre, 3, shade, -1)
    return image


def test_lens_mask_finds_the_lit_lens_only():
    rng = np.random.default_rng(0)
    image = lit_housing(rng, lit=2)
    _, sat, val = ab.hsv_planes(image)
    mask = ab.lens_mask(sat, val, 50)
    lens = np.zeros(mask.shape, bool)
    cv2.circle(lens.view(np.uint8), (6, 25), 3, 1, -1)
    assert (mask == lens).mean() > 0.97 and mask[lens].mean() > 0.9
    assert not ab.lens_mask(sat, np.zeros_like(val), 50).any()


def test_pixel_labels_lens_other_colours_and_hard_negatives():
    rng = np.random.default_rng(1)
    image = np.full((40, 40, 3), 120, np.uint8)
    image[2:32, 2:14] = lit_housing(rng, lit=0)
    image[2:32, 20:32] = lit_housing(rng, lit=2)
    anns = (Annotation((2, 2, 14, 32), "red"), Annotation((20, 2, 32, 32), "green"))
    _, sat, val = ab.hsv_planes(image)
    (red_pos, red_neg), (green_pos, green_neg) = ab.pixel_labels(
        sat, val, anns, ("red", "green"), "lens", False, 10
    )
    assert red_pos[2:12, 2:14].sum() > 20 and not red_pos[12:].any() and not red_pos[:, 14:].any()
    assert red_neg[green_pos].all() and green_neg[red_pos].all()
    assert not red_neg[12:32, 2:14].any()
    _, (_, hard) = ab.pixel_labels(sat, val, anns, ("red", "green"), "lens", True, 10)
    assert hard[12:32, 2:14].sum() > 100 and not (hard & green_pos).any()
    ((box_pos, box_neg),) = ab.pixel_labels(sat, val, anns, ("red",), "box", False, 10)
    assert box_pos[2:32, 2:14].all() and not box_neg[2:32, 20:32].any()


def test_lights_mode_gives_each_blob_its_colour():
    rng = np.random.default_rng(2)
    train = []
    for i in range(6):
        lit = i % 3
        image = np.full((60, 60, 3), 110, np.uint8) + rng.integers(0, 20, (60, 60, 3)).astype(
            np.uint8
        )
        x, y = int(rng.integers(2, 44)), int(rng.integers(2, 26))
        image[y : y + 30, x : x + 12] = lit_housing(rng, lit)
        train.append(
            Sample(
                f"l{i}",
                (Annotation((x, y, x + 12, y + 30), ("red", "yellow", "green")[lit]),),
                image=image,
            )
        )
    det = make(n_estimators=30, min_size=3, max_boxes=5, threshold=0.5)
    det.use_model(det.fit(train))
    scene_image = np.full((60, 90, 3), 110, np.uint8)
    for k, lit in enumerate((2, 0, 1)):
        scene_image[10:40, 5 + 30 * k : 17 + 30 * k] = lit_housing(rng, lit)
    found = sorted(det.detect(Frame(scene_image, "x")), key=lambda c: c.x)
    assert [c.state for c in found] == ["green", "red", "yellow"]
    assert [c.y for c in found] == [35.5, 15.5, 25.5]


def test_shipped_default_model_detects_lights():
    det = make()
    assert det.params["model"] is None and det.colours == ("red", "yellow", "green")
    image = np.full((80, 80, 3), 90, np.uint8)
    cv2.circle(image, (20, 40), 6, (80, 60, 255), -1)  # lit red lenses lean to magenta
    cv2.circle(image, (60, 40), 6, (120, 255, 60), -1)
    found = sorted(det.detect(Frame(image, "x")), key=lambda c: c.x)
    assert [c.state for c in found] == ["red", "green"]
    info = load_model(ab.DEFAULT_MODEL, "adaboost-hsv").info
    assert info["data_licence"] == "CC BY 4.0" and info["targets"] == ["red", "yellow", "green"]
