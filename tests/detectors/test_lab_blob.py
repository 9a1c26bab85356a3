"""LAB-BLOB on synthetic frames: lit discs of a few pixels, their state and radius."""

from __future__ import annotations

import cv2
import numpy as np
import pytest
from oracles.lamps import street

import tsrkit
from tsrkit_plugins.detectors.lab_blob import blob_peaks, gaussian_stack

RED = (40, 40, 235)
GREEN = (170, 230, 40)


@pytest.mark.parametrize("radius", [1, 2, 3])
def test_small_red_and_green_discs_are_found_with_their_state(radius):
    found = tsrkit.detector("lab-blob").detect(
        street([(40, 40, radius, RED), (110, 40, radius, GREEN)])
    )
    for x, state in ((40.5, "red"), (110.5, "green")):
        best = max((c for c in found if c.state == state), key=lambda c: c.score)
        assert np.hypot(best.x - x, best.y - 40.5) <= 1.0
    assert [c.score for c in found] == sorted((c.score for c in found), reverse=True)


def test_radius_follows_the_strongest_scale():
    small = tsrkit.detector("lab-blob").detect(street([(60, 40, 1, RED)]))[0]
    large = tsrkit.detector("lab-blob").detect(street([(60, 40, 4, RED)]))[0]
    assert small.radius < large.radius


def test_grey_frame_gives_no_candidates():
    assert tsrkit.detector("lab-blob").detect(street()) == []


def test_keeps_at_most_top_blobs_per_state():
    lamps = [(20 + 20 * i, 40, 2, RED) for i in range(7)]
    found = tsrkit.detector("lab-blob", top=3).detect(street(lamps))
    assert sum(c.state == "red" for c in found) == 3


def test_peaks_are_the_local_maxima_of_the_strongest_level():
    blurs = np.zeros((3, 9, 9), np.float32)
    blurs[0, 2, 2] = 1.0  # D_0 = 1 at (2, 2)
    blurs[1, 6, 6] = 0.5  # D_1 = 0.5 at (6, 6), where D_0 = -0.5
    blurs[1, 5, 6] = 0.25  # beside it, lower: not a maximum
    rows, cols, levels, values = blob_peaks(blurs, 0.1)
    found = sorted(zip(rows.tolist(), cols.tolist(), levels.tolist(), values.tolist()))
    assert found == [(2, 2, 0, 1.0), (6, 6, 1, 0.5)]
    assert blob_peaks(blurs, 0.6)[0].tolist() == [2]


def test_gaussian_stack_composes_to_the_direct_blur():
    image = np.zeros((61, 61), np.float32)
    image[30, 30] = 1.0
    stack = gaussian_stack(image, [1.0, 1.6, 2.56])
    direct = cv2.GaussianBlur(image, (0, 0), 2.56, borderType=cv2.BORDER_REFLECT_101)
    assert np.abs(stack[-1] - direct).max() <= 0.02 * direct.max()
