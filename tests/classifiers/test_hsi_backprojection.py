"""hsi-backprojection (Lee 5.3.3-5.3.4): back-projection, training, filter size, video, files."""

from __future__ import annotations

import cv2
import numpy as np
import pytest
from oracles.lamps import COLOURS, crop_sample, housing, lamp, training_set

from tsrkit.core.types import Candidate, Frame
from tsrkit.plugin.models import Model, ModelError, load_model, save_model
from tsrkit.plugin.registry import get_registry
from tsrkit_plugins.classifiers.hsi_backprojection import (
    back_project,
    expected_diameter,
    low_pass,
    scaled_histogram,
    smooth_hue,
    unclipped,
)


def make(**params):
    return get_registry().create("classifier", "hsi-backprojection", params)


@pytest.fixture(scope="module")
def model_path(tmp_path_factory):
    classifier = make()
    path = tmp_path_factory.mktemp("hsi") / "model"
    save_model(
        path,
        classifier.fit(training_set()),
        plugin="hsi-backprojection",
        plugin_version="t",
        params=classifier.params,
        training={},
    )
    return path


def classify_one(classifier, image, candidate, **frame_args):
    return classifier.classify(Frame(image, "t", **frame_args), [candidate])[0]


def test_scaled_histogram_peaks_at_one():
    hist = scaled_histogram(np.array([3, 3, 3, 5, 179]), 180)
    assert hist.shape == (180,) and hist[3] == 1.0 and hist[5] == pytest.approx(1 / 3)


def test_hue_smoothing_wraps_around_red():
    hist = scaled_histogram(np.array([179]), 180)
    smoothed = smooth_hue(hist, 3.0)
    assert smoothed.max() == pytest.approx(1.0)
    assert smoothed[1] == pytest.approx(smoothed[177], rel=1e-4) and smoothed[1] > 0.5


def test_back_projection_matches_a_pixel_loop():
    rng = np.random.default_rng(2)
    hsv = np.stack(
        [rng.integers(0, 180, (6, 7)), rng.integers(0, 256, (6, 7)), rng.integers(0, 256, (6, 7))],
        axis=-1,
    ).astype(np.uint8)
    hue, sat, val = rng.random((3, 180)), rng.random(256), rng.random(256)
    got = back_project(hsv, hue, sat, val)
    for state in range(3):
        for y in range(6):
            for x in range(7):
                h, s, v = hsv[y, x]
                assert got[state, y, x] == pytest.approx(hue[state, h] * sat[s] * val[v])


def test_expected_diameter_is_eq_5_8():
    assert expected_diameter(0.15, 1000.0, 50.0) == pytest.approx(6.0)
    with pytest.raises(ValueError, match="positive"):
        expected_diameter(0.15, 1000.0, 0.0)


def test_low_pass_weights_the_previous_frame():
    assert low_pass(np.array([1.0, 0.0]), np.array([0.0, 1.0]), 0.75).tolist() == [0.75, 0.25]


@pytest.mark.parametrize("state", ["red", "yellow", "green"])
def test_pure_disks_get_their_state(model_path, state):
    image = lamp(COLOURS[state], size=40, radius=8, seed=4)
    cand = Candidate.from_circle(20, 20, 8, 1.0)
    assert classify_one(make(model=str(model_path)), image, cand).state == state
    det = classify_one(make(model=str(model_path), red_prior=False), image, cand)
    assert det.state == state
    others = [v for k, v in det.state_scores.items() if k != state]
    assert max(others) < 0.5 * det.state_scores[state]


def test_warm_red_prior_reads_orange_red_as_red(model_path):
    orange_red = lamp((10, 120, 240), size=40, radius=8, seed=4)  # OpenCV hue 14
    cand = Candidate.from_circle(20, 20, 8, 1.0)
    assert classify_one(make(model=str(model_path)), orange_red, cand).state == "red"
    assert (
        classify_one(make(model=str(model_path), red_prior=False), orange_red, cand).state
        == "yellow"
    )


@pytest.mark.parametrize("lit,state", [(0, "red"), (1, "yellow"), (2, "green")])
def test_housing_box_is_searched_for_the_lit_lens(model_path, lit, state):
    image = housing(COLOURS[state], lit)
    det = classify_one(make(model=str(model_path)), image, Candidate.from_box((0, 0, 20, 60), 1))
    assert det.state == state


def test_metadata_sets_the_filter_size(model_path):
    classifier = make(model=str(model_path))
    image = lamp(COLOURS["green"], size=40, radius=3)
    cand = Candidate.from_box((0, 0, 40, 40), 1.0)
    wide = classify_one(classifier, image, cand).state_scores["green"]
    sized = classify_one(
        classifier, image, cand, metadata={"focal_px": 1000.0, "distance_m": 50.0}
    ).state_scores["green"]
    assert sized > 2 * wide


def test_threshold_gives_unknown(model_path):
    dark = lamp((30, 30, 30), size=24, radius=8)
    det = classify_one(
        make(model=str(model_path), threshold=0.05), dark, Candidate.from_box((4, 4, 20, 20), 1.0)
    )
    assert det.state == "unknown"


def test_fusion_gives_every_light_the_approach_state(model_path):
    image = np.hstack(
        [lamp(COLOURS["green"], size=24, radius=8), lamp((30, 30, 30), size=24, radius=8)]
    )
    cands = [Candidate.from_circle(12, 12, 8, 1.0), Candidate.from_circle(36, 12, 8, 1.0)]
    plain = make(model=str(model_path), threshold=0.05).classify(Frame(image, "t"), cands)
    fused = make(model=str(model_path), threshold=0.05, fuse=True).classify(
        Frame(image, "t"), cands
    )
    assert [d.state for d in plain] == ["green", "unknown"]
    assert [d.state for d in fused] == ["green", "green"]


def test_low_pass_carries_probabilities_over_consecutive_frames(model_path):
    classifier = make(model=str(model_path), lowpass=0.8)
    cand = Candidate.from_circle(20, 20, 8, 1.0)
    red = lamp(COLOURS["red"], size=40, radius=8)
    green = lamp(COLOURS["green"], size=40, radius=8)
    classifier.classify(Frame(red, "v", index=0), [cand])
    assert classifier.classify(Frame(green, "v", index=1), [cand])[0].state == "red"
    assert classifier.classify(Frame(green, "w", index=2), [cand])[0].state == "green"


def test_training_takes_equal_pixels_per_sample_and_is_deterministic():
    first = make().fit(training_set())
    second = make().fit(training_set())
    smallest = int((np.hypot(*np.mgrid[-5:5, -5:5] + 0.5) <= 5).sum())
    assert first.info["pixels_per_sample"] == smallest
    for key in ("hue", "saturation", "intensity"):
        assert np.array_equal(first.arrays[key], second.arrays[key])
        assert first.arrays[key].max() == pytest.approx(1.0)
    assert make(pixels_per_sample=10).fit(training_set()).info["pixels_per_sample"] == 10


def test_model_round_trip_and_wrong_models(tmp_path, model_path):
    model = load_model(model_path, plugin="hsi-backprojection")
    assert model.arrays["hue"].shape == (3, 180)
    save_model(tmp_path / "ab", model, plugin="ab-hist", plugin_version="t", params={}, training={})
    cand = Candidate.from_circle(12, 12, 8, 1.0)
    with pytest.raises(ModelError, match="ab-hist"):
        classify_one(make(model=str(tmp_path / "ab")), lamp(COLOURS["red"]), cand)
    bad = {"hue": np.ones((3, 10), np.float32)}
    save_model(
        tmp_path / "short",
        type(model)(arrays=bad),
        plugin="hsi-backprojection",
        plugin_version="t",
        params={},
        training={},
    )
    with pytest.raises(ModelError, match="expected hue"):
        classify_one(make(model=str(tmp_path / "short")), lamp(COLOURS["red"]), cand)


def test_unclipped_keeps_order_and_falls_back_when_all_are_clipped():
    pixels = np.array([[0, 200, 255], [5, 180, 240], [3, 100, 250], [2, 90, 120]], np.uint8)
    assert unclipped(pixels, 250).tolist() == [[5, 180, 240], [2, 90, 120]]
    assert unclipped(pixels, 256).tolist() == pixels.tolist()
    assert unclipped(pixels[[0, 2]], 250).tolist() == pixels[[0, 2]].tolist()


#: An over-exposed red lamp's core (BGR): red clipped at 255 and green risen, OpenCV hue 23.
CLIPPED_CORE = (20, 200, 255)


def overexposed_red(size: int = 40, radius: int = 10) -> np.ndarray:
    """A red lamp whose core (80% of the radius) is clipped to :data:`CLIPPED_CORE`."""
    image = np.full((size, size, 3), 35, np.uint8)
    cv2.circle(image, (size // 2, size // 2), radius, (40, 30, 230), -1)
    cv2.circle(image, (size // 2, size // 2), radius * 8 // 10, CLIPPED_CORE, -1)
    return image


@pytest.fixture
def hand_model(tmp_path):
    """Hue windows red 0-10 and 170-179, yellow 18-32, green 60-90; S and I rising with
    saturation and value, so that grey pixels weigh nothing and the brightest (clipped) ones
    most, as trained S and I histograms do."""
    hue = np.zeros((3, 180), np.float32)
    hue[0, :11] = hue[0, 170:] = hue[1, 18:33] = hue[2, 60:91] = 1
    rising = np.arange(256, dtype=np.float32) / 255
    model = Model(arrays={"hue": hue, "saturation": rising, "intensity": rising})
    return save_model(
        tmp_path / "hand",
        model,
        plugin="hsi-backprojection",
        plugin_version="t",
        params={},
        training={},
    )


def test_clipped_core_is_left_out_so_an_overexposed_red_stays_red(hand_model):
    image, cand = overexposed_red(), Candidate.from_circle(20, 20, 10, 1.0)
    common = dict(model=str(hand_model), red_prior=False)
    assert classify_one(make(**common, clip=256), image, cand).state == "yellow"  # Lee as printed
    det = classify_one(make(**common, clip=250), image, cand)
    assert det.state == "red" and det.state_scores["yellow"] == 0.0


def test_a_fully_clipped_lamp_falls_back_to_its_clipped_pixels(hand_model):
    image = np.full((40, 40, 3), 35, np.uint8)
    cv2.circle(image, (20, 20), 10, CLIPPED_CORE, -1)
    det = classify_one(
        make(model=str(hand_model), red_prior=False, clip=250),
        image,
        Candidate.from_circle(20, 20, 10, 1.0),
    )
    assert det.state == "yellow" and det.state_scores["yellow"] > 0.5
    assert det.state_scores["red"] == det.state_scores["green"] == 0.0


def test_training_leaves_clipped_pixels_out():
    samples = [crop_sample(overexposed_red(size=20), "red")] + [
        crop_sample(lamp(COLOURS[state], size=20, radius=10), state)
        for state in ("yellow", "green")
    ]
    kept = make(clip=250, hue_smooth=0).fit(samples).arrays["hue"][0]
    every = make(clip=256, hue_smooth=0).fit(samples).arrays["hue"][0]
    assert every.argmax() == 23  # Lee as printed: the clipped core's hue dominates red
    assert kept.argmax() == 179 and kept[23] == 0  # the rim's red, OpenCV hue 179
