"""The helpers of ``benchmarks/state_separability.py`` (the colour-separability evidence)."""

from __future__ import annotations

import importlib
from pathlib import Path

import numpy as np
import pytest

from tsrkit.core.types import Annotation, Dataset, Sample
from tsrkit_plugins.classifiers.lamp_state import STATES, labelled_features
from tsrkit_plugins.classifiers.lamp_state.features import N_FEATURES, N_HUE

BENCHMARKS = Path(__file__).resolve().parents[2] / "benchmarks"


@pytest.fixture
def sep(monkeypatch):
    monkeypatch.syspath_prepend(str(BENCHMARKS))
    return importlib.import_module("state_separability")


def rows_with_lab(lab: np.ndarray) -> np.ndarray:
    """Feature rows whose four Lab columns (core a, b, rim a, b) are ``lab``."""
    rows = np.zeros((len(lab), N_FEATURES), np.float32)
    rows[:, 2 * N_HUE : 2 * N_HUE + 4] = lab
    return rows


def test_hue_angles_are_unbroken_per_state(sep):
    # red (+a), amber (+b), green (-a, slightly -b or +b) and a blue sky (-b)
    lab = np.array([[1, 0.2, 1, -0.1], [0.1, 1, 0, 1], [-1, -0.2, -1, 0.2], [0, -1, 0.1, -1]])
    core, rim = sep.hue_angles(rows_with_lab(lab))
    assert np.all((core >= -90) & (core < 270)) and np.all((rim >= -90) & (rim < 270))
    assert core[0] == pytest.approx(11.3, abs=0.1) and rim[0] == pytest.approx(-5.7, abs=0.1)
    assert core[1] == pytest.approx(84.3, abs=0.1) and rim[1] == pytest.approx(90.0)
    # greens either side of the -a axis stay together, around 180
    assert core[2] == pytest.approx(191.3, abs=0.1) and rim[2] == pytest.approx(168.7, abs=0.1)
    assert core[3] == pytest.approx(-90.0) and rim[3] == pytest.approx(-84.3, abs=0.1)


def test_neighbour_states_take_the_majority_of_the_nearest(sep):
    others = rows_with_lab(np.array([[1, 0, 1, 0]] * 3 + [[0, 1, 0, 1]] * 2 + [[0.9, 0.4] * 2]))
    labels = np.array([0, 0, 0, 1, 1, 1])
    x = rows_with_lab(np.array([[1, 0.1, 1, 0.1], [0.1, 1, 0.1, 1], [0.8, 0.5, 0.8, 0.5]]))
    assert sep.neighbour_states(x, others, labels, 1).tolist() == [0, 1, 1]
    # three nearest of the orange lamp: the amber beside it and two pure reds
    assert sep.neighbour_states(x, others, labels, 3).tolist() == [0, 1, 0]
    assert sep.share_cell(np.array([0, 0, 1, 2])) == "0.50 / 0.25 / 0.25 / 0.00"


def test_folds_keep_images_whole_and_spread_each_state(sep):
    images = np.repeat(np.arange(20), 2)
    labels = np.repeat(np.arange(20) % 2, 2)
    fold = sep.folds(images, labels, 5, seed=3)
    assert np.all(fold[::2] == fold[1::2])  # both lights of an image in one fold
    for state in (0, 1):
        assert np.bincount(fold[labels == state], minlength=5).tolist() == [4] * 5
    assert np.array_equal(fold, sep.folds(images, labels, 5, seed=3))


def test_light_ids_follow_labelled_features_rows(sep):
    samples = []
    for i, n in enumerate((2, 0, 1)):
        boxes = [Annotation((5 + 10 * k, 5, 12 + 10 * k, 25), "red") for k in range(n)]
        image = np.full((40, 40, 3), 60 * i, np.uint8)
        image[10:20, 6:11] = (40, 40, 230)
        samples.append(Sample(f"frame {i}", tuple(boxes), image=image))
    dataset = Dataset("three", tuple(samples))
    light, image = sep.light_ids(dataset, copies=2)
    x, y = labelled_features(dataset, 2)
    assert len(light) == len(x) == 9 and y.tolist() == [STATES.index("red")] * 9
    # per image its lights' views one after another: image 0 twice 2 lights x 3 views
    assert light.tolist() == [0, 1, 0, 1, 0, 1, 2, 2, 2]
    assert image.tolist() == [0] * 6 + [2] * 3
    plain, _ = labelled_features(dataset)
    assert np.array_equal(x[light == 2][0], plain[2])
