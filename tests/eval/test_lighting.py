"""Tests for the light condition of Mascetti 3.2 (Table 4 thresholds on the mean V value)."""

from __future__ import annotations

import cv2
import numpy as np
import pytest

from tsrkit.eval.lighting import LIGHT_CONDITIONS, condition_of_m, light_condition, mean_v
from tsrkit.runner.inputs import read_image


def test_mean_v_matches_opencv_hsv():
    rng = np.random.default_rng(0)
    image = rng.integers(0, 256, (31, 17, 3), dtype=np.uint8)
    expected = cv2.cvtColor(image, cv2.COLOR_BGR2HSV)[..., 2].mean()
    assert mean_v(image) == pytest.approx(expected)


@pytest.mark.parametrize(
    "m, expected",
    [
        (0.0, "low"),
        (5.0, "low"),
        (5.01, "mid"),
        (60.0, "mid"),
        (60.5, "high"),
        (120.0, "high"),
        (120.01, "very_high"),
        (255.0, "very_high"),
    ],
)
def test_table4_boundaries(m, expected):
    assert condition_of_m(m) == expected


@pytest.mark.parametrize(
    "value, expected", [(0, "low"), (40, "mid"), (100, "high"), (200, "very_high")]
)
def test_light_condition_of_uniform_frames(value, expected):
    image = np.zeros((8, 8, 3), np.uint8)
    image[..., 1] = value  # V is the max channel, so a pure-green frame has V = value
    assert light_condition(image) == expected
    assert expected in LIGHT_CONDITIONS


@pytest.mark.parametrize(
    "bad",
    [np.zeros((4, 4), np.uint8), np.zeros((4, 4, 3), np.float32), np.zeros((0, 4, 3), np.uint8)],
)
def test_bad_input_is_a_value_error(bad):
    with pytest.raises(ValueError):
        mean_v(bad)


def test_non_finite_m_is_rejected():
    with pytest.raises(ValueError, match="finite"):
        condition_of_m(float("nan"))


def test_real_frames_get_a_condition(shared_datasets):
    images = sorted((shared_datasets / "roboflow_cinta_v2_id").rglob("*.jpg"))[:5]
    assert images
    for path in images:
        assert light_condition(read_image(path)) in LIGHT_CONDITIONS
