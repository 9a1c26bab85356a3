"""GRAY-TOPHAT baseline (Zheng 2016 5.2.2): white top-hat on grayscale + Zheng's localization."""

import json

import cv2
import numpy as np
import pytest

import tsrkit
from tsrkit.core.types import Frame
from tsrkit_plugins.detectors.gray_tophat import white_tophat


def spot_image():
    image = np.full((70, 90, 3), 60, np.uint8)
    image[:, 60:] = 200  # a wide bright area: no top-hat
    cv2.circle(image, (25, 30), 4, (255, 255, 255), -1)  # a small bright spot
    return image


def test_white_tophat_keeps_small_spots_and_drops_wide_areas():
    tophat = white_tophat(spot_image(), 21)
    assert tophat[30, 25] == 255 - 60
    assert tophat[10, 10] == 0 and tophat[35, 75] == 0
    assert tophat.dtype == np.float32


def test_white_tophat_is_opening_residue():
    rng = np.random.default_rng(1)
    image = rng.integers(0, 256, (40, 50, 3), dtype=np.uint8)
    gray = cv2.cvtColor(image, cv2.COLOR_BGR2GRAY)
    element = cv2.getStructuringElement(cv2.MORPH_ELLIPSE, (7, 7))
    opened = cv2.dilate(cv2.erode(gray, element), element)
    np.testing.assert_array_equal(white_tophat(image, 7), gray.astype(np.float32) - opened)


def test_white_tophat_rejects_empty_element():
    with pytest.raises(ValueError, match="se_size"):
        white_tophat(spot_image(), 0)


def test_detector_locates_the_spot_with_its_radius():
    found = tsrkit.detector("gray-tophat").detect(Frame(spot_image(), "spot.png"))
    assert len(found) == 1
    assert (found[0].x, found[0].y) == pytest.approx((25.5, 30.5), abs=0.01)
    assert found[0].radius == 4 and found[0].score == 195


def test_structuring_element_smaller_than_the_spot_finds_nothing_there():
    found = tsrkit.detector("gray-tophat", se_size=5).detect(Frame(spot_image(), "spot.png"))
    assert all(abs(c.x - 25.5) > 3 or abs(c.y - 30.5) > 3 for c in found)


def test_runs_on_a_real_frame(shared_datasets):
    root = shared_datasets / "roboflow_traffic_light_kr"
    entry = json.loads((root / "annotations.json").read_text())[0]
    image = cv2.imread(str(root / entry["file"]))
    found = tsrkit.detector("gray-tophat", n_top=5).detect(Frame(image, entry["file"]))
    assert 1 <= len(found) <= 5
    assert all(0 <= c.x < image.shape[1] and 0 <= c.y < image.shape[0] for c in found)
    assert [c.score for c in found] == sorted((c.score for c in found), reverse=True)
