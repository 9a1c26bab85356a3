"""Zheng's localization (3.2.2, Figure 3-10, Eq. 3.13-3.15, Algorithm 3-1)."""

import cv2
import numpy as np
import pytest
from oracles.conspicuity_oracle import drmshift_reference

from tsrkit_plugins.detectors import localization as loc

PARAMS = {
    "h_peak": 0.9,
    "n_top": 10,
    "n_pi": 20,
    "asp_min": 0.6,
    "pd_min": 0.0,
    "shift_tol": 0.5,
    "shift_iter": 10,
    "max_iter": 50,
}


def blob(shape, centre, sigma, height=1.0):
    yy, xx = np.mgrid[: shape[0], : shape[1]]
    return height * np.exp(-((yy - centre[0]) ** 2 + (xx - centre[1]) ** 2) / (2 * sigma**2))


def test_drmshift_converges_to_the_mass_centre_of_a_blob():
    cm = blob((60, 70), (30.0, 41.0), 3.0).astype(np.float32)
    rm = np.full(cm.shape, 6, np.int32)
    centres, radius = loc.drmshift(
        cm, np.array([[26.0, 45.0], [33.0, 38.0]]), rm, tol=0.01, n_max=50
    )
    np.testing.assert_allclose(centres, [[30.0, 41.0], [30.0, 41.0]], atol=0.05)
    assert list(radius) == [6, 6]


def test_drmshift_follows_the_radius_map_like_the_reference():
    rng = np.random.default_rng(0)
    cm = sum(
        blob((50, 60), c, s, h)
        for c, s, h in [((12, 15), 3, 1.0), ((30, 40), 5, 0.7), ((40, 10), 2, 0.5)]
    )
    cm = (cm + 0.05 * rng.random(cm.shape)).astype(np.float32)
    rm = rng.integers(1, 8, cm.shape).astype(np.int32)
    starts = rng.uniform(0, 49, (12, 2))
    centres, radius = loc.drmshift(cm, starts, rm, tol=0.5, n_max=10)
    for start, centre, r in zip(starts, centres, radius):
        ref_centre, ref_r = drmshift_reference(cm, rm, start, 0.5, 10)
        np.testing.assert_allclose(centre, ref_centre, atol=1e-6)
        assert r == ref_r


def test_drmshift_needs_radii():
    with pytest.raises(ValueError, match="radius"):
        loc.drmshift(np.ones((5, 5)), np.array([[2.0, 2.0]]))


def test_peak_mask_after_normalisation_and_opening():
    wcm = np.zeros((20, 20), np.float32)
    wcm[3, 3] = 4.0  # a lone peak pixel: noise for the opening
    wcm[10:14, 10:14] = 3.8  # a 4x4 peak region survives
    norm = loc.normalise(wcm)
    assert norm.max() == 1.0
    mask = loc.peak_mask(norm, 0.9)
    assert mask[3, 3] == 1 and mask[10:14, 10:14].all()
    opened = loc.denoise(mask)
    assert opened[3, 3] == 0 and opened[11:13, 11:13].all()
    assert loc.normalise(np.zeros((3, 3), np.float32)).max() == 0


def test_components_and_shape_filter():
    mask = np.zeros((30, 30), np.uint8)
    mask[2:6, 2:6] = 1  # square: kept
    mask[10:12, 5:20] = 1  # elongated: aspect 2/15 < 0.6
    mask[20, 20] = mask[21, 21] = 1  # diagonal pair: one 8-connected component, density 0.5
    found = loc.components(mask)
    assert len(found.areas) == 3
    keep = loc.shape_filter(found, 0.6, 0.0)
    assert sorted(found.areas[keep]) == [2, 16]
    keep = loc.shape_filter(found, 0.6, 0.6)
    assert list(found.areas[keep]) == [16]
    np.testing.assert_allclose(found.centroids[0], [3.5, 3.5])
    assert len(loc.components(np.zeros((5, 5), np.uint8)).areas) == 0


def test_non_overlapping_keeps_the_larger_and_respects_earlier():
    centres = np.array([[10.0, 10.0], [10.0, 14.0], [40.0, 40.0], [70.0, 70.0]])
    radius = np.array([2, 3, 2, 2])
    kept = loc.non_overlapping(centres, radius, np.array([[70.0, 73.0]]), np.array([1]))
    assert list(kept) == [1, 2]  # 0 touches the larger 1; 3 touches an earlier candidate
    touching = loc.non_overlapping(
        np.array([[0.0, 0.0], [0.0, 5.0]]), np.array([2, 3]), np.zeros((0, 2)), np.zeros(0, int)
    )
    assert list(touching) == [1]


def test_stop_checks():
    assert loc.too_many(21, 0, 20)
    assert not loc.too_many(20, 0, 20)
    assert loc.too_many(4, 3, 20)
    assert not loc.too_many(3, 3, 20)


def test_localize_finds_peaks_in_descending_order_with_their_radius():
    shape = (80, 100)
    cm = (
        blob(shape, (20, 20), 2.5, 1.0)
        + blob(shape, (50, 70), 2.5, 0.6)
        + blob(shape, (60, 20), 2.5, 0.3)
    )
    rm = np.full(shape, 3, np.int32)
    rm[40:60, 60:80] = 5
    found = loc.localize(cm.astype(np.float32), PARAMS, radius_map=rm)
    got = [(round(c.y - 0.5), round(c.x - 0.5), c.radius) for c in found]
    assert got[:3] == [(20, 20, 3), (50, 70, 5), (60, 20, 3)]
    assert found[0].score == pytest.approx(1.0, abs=1e-3)
    assert found[0].bbox == pytest.approx(
        (found[0].x - 3, found[0].y - 3, found[0].x + 3, found[0].y + 3)
    )


def test_localize_without_radius_map_uses_component_size():
    cm = np.zeros((40, 40), np.float32)
    yy, xx = np.mgrid[:40, :40]
    cm[(yy - 20) ** 2 + (xx - 15) ** 2 <= 16] = 1.0
    found = loc.localize(cm, PARAMS)
    assert len(found) == 1
    assert (found[0].x, found[0].y) == pytest.approx((15.5, 20.5), abs=0.01)
    assert found[0].radius == 4


def test_localize_stops_when_too_many_equal_peaks():
    cm = np.zeros((100, 100), np.float32)
    for i in range(5):
        for j in range(6):
            cm[5 + 18 * i : 9 + 18 * i, 5 + 15 * j : 9 + 15 * j] = 1.0
    assert loc.localize(cm, PARAMS) == []
    assert len(loc.localize(cm, dict(PARAMS, n_pi=40, n_top=7))) == 7


def test_region_of_interest():
    image = np.zeros((100, 10, 3), np.uint8)
    assert loc.region_of_interest(image, 0.6).shape[0] == 60
    with pytest.raises(ValueError):
        loc.region_of_interest(image, 0.0)


def test_clear_found_zeroes_the_raw_peaks_and_the_digital_disks():
    rng = np.random.default_rng(3)
    wcm = rng.uniform(0.1, 1.0, (30, 40)).astype(np.float32)
    raw = np.zeros((30, 40), np.uint8)
    raw[5, 7] = raw[20, 30] = 1
    centres = np.array([[10.4, 12.6], [28.0, 39.0], [-1.0, 3.0]])  # the last two cut by edges
    radius = np.array([3, 2, 1])
    loc.clear_found(wcm, raw, centres, radius)
    dy, dx = np.mgrid[:30, :40]
    expected = raw > 0
    for (row, col), r in zip(np.rint(centres), radius):
        expected |= (dy - row) ** 2 + (dx - col) ** 2 <= r * r
    assert np.array_equal(wcm == 0, expected)


def test_normalise_divides_in_place_and_drmshift_takes_a_known_reach():
    wcm = np.array([[1.0, 4.0], [2.0, 0.0]], np.float32)
    assert loc.normalise(wcm) is wcm and wcm.tolist() == [[0.25, 1.0], [0.5, 0.0]]
    # With copy, the quotients go to a new array and the map is left as it was.
    cm = np.array([[3.0, 0.7], [0.0, 1.9]], np.float32)
    copied = loc.normalise(cm, 1.9, copy=True)
    assert (
        copied is not cm and cm.tolist() == np.array([[3.0, 0.7], [0.0, 1.9]], np.float32).tolist()
    )
    assert np.array_equal(copied, loc.normalise(cm.copy(), 1.9))
    zeros = np.zeros((2, 2), np.float32)
    assert loc.normalise(zeros, copy=True) is zeros
    cm = blob((40, 40), (20.0, 18.0), 3.0).astype(np.float32)
    rm = np.full((40, 40), 4, np.int32)
    rm[0, 0] = 9  # the map's maximum, out of every window's way
    starts = np.array([[15.0, 15.0], [24.0, 22.0]])
    found = loc.drmshift(cm, starts, rm)
    for got, want in zip(loc.drmshift(cm, starts, rm, reach=9), found):
        assert np.array_equal(got, want)


def test_sparse_components_are_opencvs_components_in_opencvs_order():
    # Masks of odd and even sizes, sparse to dense, opened like the peak masks; statistics,
    # centroids and label order as cv2.connectedComponentsWithStats gives them.
    rng = np.random.default_rng(3)
    for trial in range(400):
        h, w = rng.integers(1, 50, 2) if trial < 300 else rng.integers(100, 300, 2)
        mask = (rng.random((h, w)) < rng.uniform(0.01, 0.6)).astype(np.uint8)
        if trial >= 300:
            mask = loc.denoise(cv2.dilate(mask, np.ones((3, 3), np.uint8)))
        _, _, stats, centroids = cv2.connectedComponentsWithStats(mask, connectivity=8)
        mine, middles = loc.sparse_components(np.flatnonzero(mask), w)
        assert np.array_equal(mine, stats[1:]) and np.array_equal(middles, centroids[1:])
