"""A frame's shared colour views: computed once, sliced for its upper band, fresh after replace."""

from __future__ import annotations

import pickle
from dataclasses import replace

import cv2
import numpy as np

from tsrkit.api import Frame


def frame() -> Frame:
    rng = np.random.default_rng(4)
    return Frame(rng.integers(0, 256, (40, 30, 3), dtype=np.uint8), "random")


def test_a_conversion_is_computed_once_and_equals_opencv():
    f = frame()
    lab = f.views.colour(cv2.COLOR_BGR2Lab)
    assert f.views.colour(cv2.COLOR_BGR2Lab) is lab
    assert np.array_equal(lab, cv2.cvtColor(f.image, cv2.COLOR_BGR2Lab))
    calls = []
    f.views.map("grey sum", lambda image: calls.append(1) or image.sum(axis=2))
    f.views.map("grey sum", lambda image: calls.append(1) or image.sum(axis=2))
    assert calls == [1]


def test_a_band_slices_what_its_frame_holds_and_computes_what_it_does_not():
    f = frame()
    hsv = f.views.colour(cv2.COLOR_BGR2HSV)
    band = f.band(25)
    assert band.image.shape == (25, 30, 3) and band.source == f.source
    sliced = band.views.colour(cv2.COLOR_BGR2HSV)
    assert np.shares_memory(sliced, hsv) and np.array_equal(sliced, hsv[:25])
    own = band.views.colour(cv2.COLOR_BGR2Lab)
    assert own.shape[:2] == (25, 30)
    assert np.array_equal(own, cv2.cvtColor(f.image, cv2.COLOR_BGR2Lab)[:25])
    assert cv2.COLOR_BGR2Lab not in [k[1] for k in f.views._cache]


def test_a_replaced_frame_starts_its_own_views_and_pickles_without_them():
    f = frame()
    f.views.colour(cv2.COLOR_BGR2GRAY)
    flipped = replace(f, image=np.ascontiguousarray(f.image[::-1]))
    assert flipped.views is not f.views
    assert np.array_equal(
        flipped.views.colour(cv2.COLOR_BGR2GRAY), cv2.cvtColor(flipped.image, cv2.COLOR_BGR2GRAY)
    )
    copy = pickle.loads(pickle.dumps(f))
    assert copy.views._cache == {} and np.array_equal(copy.image, f.image)
