"""The compiled housing fit (plugins/verifiers/housing/fit.py, lens.py) equals, to the bit, the
NumPy computation it replaced (tests/oracles/housing_oracle.py): on real frames of three cameras
with their annotated lenses and housings' centres, and on synthetic 1280x720 scenes with random
lenses of every size in and around the frame (some wholly outside, some without a radius)."""

from __future__ import annotations

import cv2
import numpy as np
import pytest
from oracles import housing_oracle as oracle
from oracles.frames import annotated_frames

from tsrkit_plugins.verifiers.housing.fit import fit_housings


def random_lenses(rng, width, height, n=60):
    """Lenses anywhere in and around the frame, radii from none (FRST-like) to a large blob."""
    radii = rng.choice([0.3, 1.0, 1.9, 2.0, 3.5, 6.0, 11.0, 20.0, 45.0, 70.0], n)
    return [(rng.uniform(-60, width + 60), rng.uniform(-60, height + 60), float(r)) for r in radii]


@pytest.fixture(scope="module")
def frames(shared_datasets):
    return annotated_frames(shared_datasets)


def test_fit_equals_the_oracle(frames):
    rng = np.random.default_rng(11)
    for image, candidates in frames:
        gray = cv2.cvtColor(image, cv2.COLOR_BGR2GRAY)
        lenses = [(c.x, c.y, c.radius) for c in candidates]
        lenses += random_lenses(rng, image.shape[1], image.shape[0])
        for subset in (lenses, lenses[:1], lenses[-2:]):
            for got, want in zip(fit_housings(gray, subset), oracle.fit_housings(gray, subset)):
                assert got.shape == want.shape and np.array_equal(got, want)


def test_flat_and_saturated_frames_equal_the_oracle():
    rng = np.random.default_rng(12)
    for level in (0, 128, 255):
        gray = np.full((120, 160), level, np.uint8)
        lenses = random_lenses(rng, 160, 120, 20)
        for got, want in zip(fit_housings(gray, lenses), oracle.fit_housings(gray, lenses)):
            assert np.array_equal(got, want)
