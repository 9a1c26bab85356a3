"""ab-hist batched over a frame's candidates gives exactly the scores, states and trained
histograms of the lens-by-lens computation it replaced (tests/oracles/ab_hist_oracle.py), on
real frames of three cameras and on synthetic ones."""

from __future__ import annotations

import cv2
import numpy as np
import pytest
from oracles.ab_hist_oracle import lens_areas, lens_scores
from oracles.frames import annotated_frames
from oracles.lamps import training_set

from tsrkit.core.types import Candidate, Frame
from tsrkit.plugin.registry import get_registry
from tsrkit.synth import SynthOptions, render_frame
from tsrkit_plugins.shared.regions import labelled_lenses, lens_of

PARAMS = [
    {},
    {"mode": "max"},
    {"smooth": 0, "min_chroma": 0},
    {"smooth": 1.3, "min_chroma": 25.5, "red_prior": False},
]


def circles(rng, width, height, n=40):
    """Circles of radius 0.6-20 px anywhere in the frame, some cut by its border."""
    return [
        Candidate.from_circle(rng.uniform(0, width), rng.uniform(0, height), r, 1.0)
        for r in rng.uniform(0.6, 20, n)
    ]


@pytest.mark.parametrize("params", PARAMS, ids=str)
def test_batched_scores_equal_the_lens_by_lens_oracle(shared_datasets, params):
    classifier = get_registry().create("classifier", "ab-hist", params)
    rng = np.random.default_rng(11)
    checked = 0
    for image, boxes in annotated_frames(shared_datasets):
        candidates = boxes + circles(rng, image.shape[1], image.shape[0])
        found = classifier.classify(Frame(image, "t"), candidates)
        assert [d.candidate for d in found] == candidates
        for candidate, detection in zip(candidates, found):
            lens = lens_of(image, candidate, classifier.params)
            expected = lens_scores(
                image,
                lens,
                classifier.trained,
                classifier.params["min_chroma"],
                classifier.params["smooth"],
                classifier.params["mode"],
            )
            assert list(detection.state_scores.values()) == expected  # exact, not approximate
            checked += 1
    assert checked > 300


def test_batched_training_equals_the_lens_by_lens_oracle():
    params = {"smooth": 2.0, "min_chroma": 5.0}
    classifier = get_registry().create("classifier", "ab-hist", params)
    sums = np.zeros((3, 32, 32))
    counts = np.zeros(3)
    for state, frame, lens in labelled_lenses(training_set(), classifier.states, classifier.params):
        a1, a3, a1_saturated = lens_areas(frame.image, lens, 32, 5.0, 2.0)
        i = classifier.states.index(state)
        sums[i] += a1 if a1_saturated else a3
        counts[i] += 1
    expected = (sums / counts[:, None, None]).astype(np.float32)
    assert np.array_equal(classifier.fit(training_set()).arrays["histograms"], expected)


def test_no_candidates_and_a_lens_outside_the_frame():
    classifier = get_registry().create("classifier", "ab-hist")
    image = np.zeros((40, 40, 3), np.uint8)
    assert classifier.classify(Frame(image, "t"), []) == []
    with pytest.raises(ValueError, match="outside"):
        classifier.classify(Frame(image, "t"), [Candidate.from_circle(200, 200, 3, 1.0)])


def test_grey_and_bgra_frames_read_as_their_bgr():
    classifier = get_registry().create("classifier", "ab-hist")
    bgr = render_frame(5, 7, 320, 240, SynthOptions())[0]
    candidates = circles(np.random.default_rng(2), 320, 240, n=10)
    expected = [d.state_scores for d in classifier.classify(Frame(bgr, "t"), candidates)]
    bgra = cv2.cvtColor(bgr, cv2.COLOR_BGR2BGRA)
    assert [d.state_scores for d in classifier.classify(Frame(bgra, "t"), candidates)] == expected
    grey = cv2.cvtColor(bgr, cv2.COLOR_BGR2GRAY)
    assert [d.state_scores for d in classifier.classify(Frame(grey, "t"), candidates)] == [
        d.state_scores
        for d in classifier.classify(Frame(cv2.cvtColor(grey, cv2.COLOR_GRAY2BGR), "t"), candidates)
    ]
