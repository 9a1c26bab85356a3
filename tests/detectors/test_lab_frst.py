"""The LAB-FRST detector on synthetic frames with lit discs, and its feature map."""

from __future__ import annotations

import cv2
import numpy as np
import pytest
from oracles.frst_arrays import frst_arrays
from oracles.lamps import street

import tsrkit
from tsrkit.core.types import Frame
from tsrkit.datasets import open_dataset
from tsrkit.synth import SynthOptions, render_frame
from tsrkit_plugins.detectors.frst.lab_frst import lab_feature_map, spot_candidates

RED = (40, 40, 235)
GREEN = (170, 230, 40)


def nearest(candidates, x, y):
    return min(candidates, key=lambda c: np.hypot(c.x - x, c.y - y))


def test_finds_a_red_lit_disc_and_labels_it_red():
    found = tsrkit.detector("lab-frst").detect(street([(40, 40, 5, RED)]))
    red = [c for c in found if c.state == "red"]
    assert red
    best = max(red, key=lambda c: c.score)
    assert np.hypot(best.x - 40.5, best.y - 40.5) <= 1.5
    assert best.radius >= 0.5


def test_red_and_green_discs_get_their_own_state():
    frame = street([(40, 40, 5, RED), (110, 40, 5, GREEN)])
    found = tsrkit.detector("lab-frst").detect(frame)
    assert nearest(found, 40.5, 40.5).state == "red"
    assert nearest(found, 110.5, 40.5).state == "green"
    assert (
        np.hypot(nearest(found, 110.5, 40.5).x - 110.5, nearest(found, 110.5, 40.5).y - 40.5) <= 1.5
    )
    assert [c.score for c in found] == sorted((c.score for c in found), reverse=True)


def test_keeps_at_most_top_spots_per_state():
    lamps = [(20 + 20 * i, 40, 4, RED) for i in range(7)]
    found = tsrkit.detector("lab-frst", top=3).detect(street(lamps))
    assert sum(c.state == "red" for c in found) == 3


def test_grey_frame_gives_no_candidates():
    assert tsrkit.detector("lab-frst").detect(street()) == []


def test_feature_map_sign_and_scale():
    patches = np.array([[RED, GREEN, (128, 128, 128), (255, 255, 255)]], np.uint8)
    red, green, grey, white = lab_feature_map(patches)[0]
    lab = cv2.cvtColor(patches, cv2.COLOR_BGR2Lab).astype(float)[0, 0]
    assert red == pytest.approx(lab[0] / 255 * (lab[1] + lab[2] - 256) / 128, abs=1e-6)
    assert red > 0.4 and green < -0.2
    assert abs(grey) < 0.02 and abs(white) < 0.02


def test_spot_candidates_rank_by_peak_and_binarise_at_the_fraction():
    symmetry = np.zeros((30, 30), np.float32)
    symmetry[5, 5], symmetry[20, 8:11] = 1.0, 0.6
    symmetry[25, 25] = 0.4
    spots = spot_candidates(symmetry, 0.5, 5, "red")
    assert [(c.x, c.y, c.score) for c in spots] == [
        (5.5, 5.5, 1.0),
        (9.5, 20.5, pytest.approx(0.6)),
    ]
    assert spots[1].radius == 1.5


def test_rejects_non_bgr_images():
    with pytest.raises(ValueError, match="BGR uint8"):
        lab_feature_map(np.zeros((10, 10), np.uint8))


@pytest.fixture(scope="module")
def oracle_frames(shared_datasets):
    """Real frames of four cameras (a 1280x720 cut of a 1280x960 Japanese dash-cam frame
    among them) and a rendered 1280x720 scene."""
    frames = []
    for name, size in (
        ("roboflow_traffic_light_kr", None),
        ("dtld_fridtjofs", None),
        ("roboflow_cinta_v2_id", None),
        ("iwai_japan_tl", (1280, 960)),
    ):
        samples = open_dataset(shared_datasets / name, format="normalized")
        sample = next(s for s in samples if size is None or (s.width, s.height) == size)
        image = sample.load().image
        frames.append(image[120:840] if size else image)
    frames += [render_frame(seed, 11, 1280, 720, SynthOptions())[0] for seed in (1,)]
    return frames


def test_candidates_equal_those_of_the_array_transform(oracle_frames):
    """The detector's candidates (positions, radii, scores, states) at the defaults and at the
    union's setting are those of the whole-image array transform, bit for bit."""
    settings = ({}, {"top": 15, "fraction": 0.1})
    for image in oracle_frames:
        feature = lab_feature_map(image)
        args = dict(radii=tuple(range(1, 11)), alpha=3.0, beta=0.0)
        bright = frst_arrays(np.maximum(feature, 0), mode="bright", **args)
        dark = -frst_arrays(np.minimum(feature, 0), mode="dark", **args)
        for params in settings:
            detector = tsrkit.detector("lab-frst", **params)
            p = detector.params
            expected = spot_candidates(bright, p["fraction"], p["top"], "red")
            expected += spot_candidates(dark, p["fraction"], p["top"], "green")
            found = detector.detect(Frame(image, "oracle"))
            assert found == sorted(expected, key=lambda c: -c.score)
            assert len(found) >= 2
