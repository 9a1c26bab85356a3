"""The verifier's frame-relative context features (plugins/verifiers/context.py)."""

from __future__ import annotations

import numpy as np
import pytest

from tsrkit.types import Candidate
from tsrkit_plugins.verifiers import context as C
from tsrkit_plugins.verifiers import features as F


def planes(values: list[float], pixels: int = 4) -> np.ndarray:
    """One candidate's planes: ``pixels`` pixels, each with the 8 ``COLOUR_NAMES`` values."""
    return np.tile(np.asarray(values, np.float32), (1, pixels, 1))


def test_frame_statistics_of_a_frame_of_known_pixels():
    image = np.zeros((80, 160, 3), np.uint8)
    image[:, :96] = 100  # 60 % of the frame grey 100 ...
    image[:, 96:] = (0, 0, 200)  # ... 40 % pure red of V 200, S 255
    stats = C.frame_statistics(image)
    assert (stats.v_low, stats.v_high, stats.s_high) == (100.0, 200.0, 255.0)
    # grey-world neutral: the mean of grey (a = 128) and red (OpenCV 8-bit Lab a of pure red)
    import cv2

    red_a = float(cv2.cvtColor(np.array([[[0, 0, 200]]], np.uint8), cv2.COLOR_BGR2LAB)[0, 0, 1])
    assert stats.a_mean == pytest.approx(0.6 * 128.0 + 0.4 * red_a)


def test_photometric_features_place_the_lens_in_the_frames_range():
    stats = C.FrameStatistics(v_low=50.0, v_high=250.0, s_high=200.0, a_mean=130.0, b_mean=120.0)
    # lens pixels: L 200, a 170, b 150, S 100, V 150, one pixel of V 200
    lens = planes([200, 170, 150, 100, 150, 0, 0, 0])
    lens[0, 0, 4] = 210.0
    got = C.photometric_features(lens, stats)[0]
    expected = [
        ((150 * 3 + 210) / 4 - 50) / 200,  # lens mean V between the frame's median and 99th
        210 / 250,  # lens peak V over the frame's 99th percentile
        100 / 200,  # lens saturation over the frame's 99th percentile
        170 - 130,  # lens a after grey-world balance
        150 - 120,  # lens b after grey-world balance
    ]
    assert got == pytest.approx(expected)


def test_photometric_features_do_not_move_when_the_camera_brightens_the_frame():
    """A camera that scales every V by the same gain leaves the V columns alone."""
    stats = C.FrameStatistics(50.0, 150.0, 200.0, 128.0, 128.0)
    lens = planes([0, 128, 128, 100, 120, 0, 0, 0])
    brighter = C.FrameStatistics(60.0, 180.0, 200.0, 128.0, 128.0)  # V' = 1.2 V
    lens2 = lens.copy()
    lens2[..., 4] *= 1.2
    one = C.photometric_features(lens, stats)[0]
    two = C.photometric_features(lens2, brighter)[0]
    assert two[:2] == pytest.approx(one[:2])


def test_relations_count_duplicates_the_best_of_them_and_others_in_the_housing():
    a = Candidate.from_circle(100, 100, 4, 0.9)
    b = Candidate.from_circle(106, 100, 3, 0.8)  # 6 px from a: within 2 x 4 px
    c = Candidate.from_circle(100, 120, 4, 0.5)  # 20 px below: another lamp of a's head
    d = Candidate.from_circle(300, 50, 2, 0.95)  # alone
    a = Candidate(**{**a.__dict__, "housing": (90.0, 90.0, 110.0, 130.0)})
    got = C.relation_features([a, b, c, d])
    assert got.tolist() == [
        [1.0, 1.0, 2.0],  # b is a's duplicate, a scores better; b and c lie in a's housing
        [1.0, 0.0, 0.0],  # b: a duplicate beaten by a; no housing fitted
        [0.0, 1.0, 0.0],
        [0.0, 1.0, 0.0],
    ]


def test_the_feature_matrix_ends_with_the_context_columns():
    image = np.full((120, 160, 3), 150, np.uint8)
    image[20:80, 70:90] = 25
    cands = [Candidate.from_circle(80, 30, 6, 1.0), Candidate.from_circle(81, 31, 6, 0.5)]
    names = F.feature_names()
    assert names[-len(C.CONTEXT_NAMES) :] == list(C.CONTEXT_NAMES)
    assert F.layout()["version"] == F.FEATURE_VERSION == 3
    rows = F.candidate_features(image, cands)
    assert rows.shape == (2, len(names))
    tail = dict(zip(names[-len(C.CONTEXT_NAMES) :], rows[:, -len(C.CONTEXT_NAMES) :].T))
    assert tail["duplicates"].tolist() == [1.0, 1.0]
    assert tail["best_of_duplicates"].tolist() == [1.0, 0.0]
