"""The verifier's features (one remap for both sample stacks, laid out in long rows; HOG
patches framed without ``np.pad``) equal, to the bit, the computation they replaced
(tests/oracles/verifier_features_oracle.py), on real frames of three cameras and synthetic
ones, with annotated boxes, housing-stage fits and random lenses and housings anywhere in and
around the frame."""

from __future__ import annotations

import dataclasses

import cv2
import numpy as np
import pytest
from oracles import verifier_features_oracle as oracle
from oracles.frames import annotated_frames

from tsrkit.core.types import Candidate, Frame
from tsrkit.plugin.registry import get_registry
from tsrkit_plugins.verifiers.features import candidate_features, remap_points, row_percentile


def scattered(rng, width, height, n):
    """Lenses of radius 0.6-25 px in and around the frame (some wholly outside), every other
    one with a tall or a wide housing box."""
    out = []
    for k, r in enumerate(rng.uniform(0.6, 25, n)):
        x, y = rng.uniform(-40, width + 40), rng.uniform(-40, height + 40)
        lens = Candidate.from_circle(x, y, r, rng.uniform(-1, 2))
        long, short = rng.uniform(3, 8) * r, 1.3 * r
        if k % 4 == 1:
            lens = dataclasses.replace(lens, housing=(x - short, y - short, x + short, y + long))
        elif k % 4 == 3:
            lens = dataclasses.replace(lens, housing=(x - long, y - short, x + short, y + short))
        out.append(lens)
    return out


@pytest.fixture(scope="module")
def scenes(shared_datasets):
    rng = np.random.default_rng(11)
    stage = get_registry().create("verifier", "housing")
    out = []
    for image, boxes in annotated_frames(shared_datasets):
        h, w = image.shape[:2]
        lenses = [Candidate.from_circle(c.x, c.y, max(c.radius / 3, 1.0), 1.0) for c in boxes]
        lenses += scattered(rng, w, h, 20)
        fitted = stage.verify(Frame(image, "t"), lenses)
        out.append((image, boxes + fitted + scattered(rng, w, h, 40)))
    return out


def test_features_equal_the_oracle(scenes):
    checked = 0
    for image, candidates in scenes:
        assert sum(c.housing is not None for c in candidates) > 20
        got = candidate_features(image, candidates)
        assert np.array_equal(got, oracle.candidate_features(image, candidates))
        for some in (candidates[:1], candidates[7:8], candidates[2:4], candidates[5:9]):
            assert np.array_equal(
                candidate_features(image, some), oracle.candidate_features(image, some)
            )
        grey = cv2.cvtColor(image, cv2.COLOR_BGR2GRAY)
        assert np.array_equal(
            candidate_features(grey, candidates), oracle.candidate_features(grey, candidates)
        )
        checked += len(candidates)
    assert checked > 450


def test_remap_points_do_not_depend_on_the_row_layout():
    rng = np.random.default_rng(3)
    image = rng.integers(0, 256, (90, 120, 3), np.uint8)
    x = rng.uniform(-20, 140, 70001).astype(np.float32)  # three rows, the last one filled up
    y = rng.uniform(-20, 110, 70001).astype(np.float32)
    x[::3] = np.round(x[::3])  # on pixel centres too

    def tall(x, y, width):
        return cv2.remap(
            image,
            x.reshape(-1, width),
            y.reshape(-1, width),
            cv2.INTER_LINEAR,
            borderMode=cv2.BORDER_REPLICATE,
        ).reshape(-1, 3)

    got = remap_points(image, x, y)
    assert got.shape == (70001, 3)
    assert np.array_equal(got[:70000], tall(x[:70000], y[:70000], 16))
    assert np.array_equal(got[70000:], tall(x[70000:], y[70000:], 1))
    assert np.array_equal(remap_points(image, x[:7], y[:7]), got[:7])


@pytest.mark.parametrize("n", [1, 2, 5, 264])
def test_row_percentile_is_numpys_to_the_bit(n):
    rng = np.random.default_rng(n)
    values = (rng.standard_normal((40, n)) * 100).astype(np.float32)
    values[:, : n // 2] = np.round(values[:, : n // 2])  # ties and whole numbers too
    for q in (0, 10, 25, 50, 75, 90, 100):
        assert np.array_equal(row_percentile(values, q), np.percentile(values, q, axis=1))
