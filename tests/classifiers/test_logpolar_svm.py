"""logpolar-svm: the log-polar rotation property, training, our SVM decision, model I/O."""

from __future__ import annotations

import cv2
import numpy as np
import pytest
from sklearn.svm import SVC

from tsrkit.core.errors import TsrkitError
from tsrkit.core.types import Annotation, Candidate, Frame, Sample
from tsrkit.plugin.models import save_model
from tsrkit_plugins.classifiers import logpolar_svm as lp

SHAPES = ("disc", "square", "triangle", "cross")


def draw(shape, rng, size=40):
    """A noisy grey crop holding one bright shape, slightly shifted and scaled."""
    image = rng.integers(30, 70, (size, size, 3)).astype(np.uint8)
    c = size / 2 + rng.uniform(-1.5, 1.5, 2)
    r = size * rng.uniform(0.28, 0.34)
    white = (230, 230, 230)
    if shape == "disc":
        cv2.circle(image, (int(c[0]), int(c[1])), int(r), white, -1)
    elif shape == "square":
        cv2.rectangle(
            image, (int(c[0] - r), int(c[1] - r)), (int(c[0] + r), int(c[1] + r)), white, -1
        )
    elif shape == "triangle":
        pts = np.array([[c[0], c[1] - r], [c[0] - r, c[1] + r], [c[0] + r, c[1] + r]], np.int32)
        cv2.fillPoly(image, [pts], white)
    else:
        cv2.line(image, (int(c[0] - r), int(c[1])), (int(c[0] + r), int(c[1])), white, 5)
        cv2.line(image, (int(c[0]), int(c[1] - r)), (int(c[0]), int(c[1] + r)), white, 5)
    return image


def crops(seed, per_class=12, shapes=SHAPES):
    rng = np.random.default_rng(seed)
    return [
        Sample(f"{shape}-{i}", (Annotation((0, 0, 40, 40), shape),), image=draw(shape, rng))
        for shape in shapes
        for i in range(per_class)
    ]


def make(**params):
    values = {p.name: p.default for p in lp.LogPolarSVM.PARAMS}
    values.update(params)
    return lp.LogPolarSVM(**values)


def test_rotation_is_circular_shift_along_theta():
    rng = np.random.default_rng(0)
    gray = rng.random((33, 33)).astype(np.float32)
    base = lp.log_polar(gray, 32, 32)
    # np.rot90 turns the picture counter-clockwise on screen; theta rows run clockwise
    for turns in (1, 2, 3):
        rotated = lp.log_polar(np.ascontiguousarray(np.rot90(gray, turns)), 32, 32)
        np.testing.assert_allclose(rotated, np.roll(base, -8 * turns, axis=0), atol=1e-5)
    assert base.shape == (32, 32)


def test_intensity_normalisation():
    gray = np.array([[10.0, 20], [30, 40]], np.float32)
    out = lp.normalise_intensity(gray)
    assert out.mean() == pytest.approx(0, abs=1e-6) and out.std() == pytest.approx(1)
    np.testing.assert_array_equal(lp.normalise_intensity(gray * 3 + 5), out)
    assert not lp.normalise_intensity(np.full((3, 3), 7.0)).any()


@pytest.fixture(scope="module")
def fitted():
    clf = make()
    model = clf.fit(crops(1))
    clf.use_model(model)
    return clf, model


def test_training_is_deterministic(fitted):
    _, model = fitted
    again = make().fit(crops(1))
    for key, array in model.arrays.items():
        np.testing.assert_array_equal(array, again.arrays[key])
    assert model.info["classes"] == sorted(SHAPES)
    assert 0 < model.info["explained_variance"] <= 1


def test_classifies_held_out_shapes(fitted):
    clf, _ = fitted
    test = crops(2, per_class=5)
    right = sum(
        clf.classify(s.load(), [Candidate.from_box(s.annotations[0].bbox, 1)])[0].state
        == s.annotations[0].state
        for s in test
    )
    assert right / len(test) >= 0.9


@pytest.mark.parametrize(
    "shapes,kernel",
    [(SHAPES, "rbf"), (SHAPES, "poly"), (SHAPES[:2], "linear"), (SHAPES[:2], "sigmoid")],
)
def test_votes_match_scikit_learn(shapes, kernel):
    clf = make(kernel=kernel, C=1.0)
    samples = crops(3, shapes=shapes)
    clf.use_model(clf.fit(samples))
    info = clf.model().info
    x = clf._vectors(((s.image, s.annotations[0].bbox) for s in samples), info)
    test_x = clf._vectors(((s.image, s.annotations[0].bbox) for s in crops(4, shapes=shapes)), info)
    projected = clf.project(x)
    svm = SVC(kernel=kernel, C=1.0, gamma=info["gamma"], degree=3, coef0=0.0)
    svm.fit(projected, np.searchsorted(info["classes"], [s.annotations[0].state for s in samples]))
    ours = np.argmax(clf.votes(np.vstack([x, test_x])), axis=1)
    np.testing.assert_array_equal(ours, svm.predict(clf.project(np.vstack([x, test_x]))))


def test_model_round_trip(tmp_path, fitted):
    clf, model = fitted
    path = save_model(
        tmp_path / "lp",
        model,
        plugin="logpolar-svm",
        plugin_version="0",
        params=clf.params,
        training={},
    )
    loaded = make(model=str(path))
    frame = Frame(np.hstack([s.image for s in crops(5, per_class=1)]), "row")
    boxes = [Candidate.from_box((40 * i, 0, 40 * i + 40, 40), 1) for i in range(len(SHAPES))]
    assert loaded.classify(frame, boxes) == clf.classify(frame, boxes)
    assert loaded.states == tuple(sorted(SHAPES))


def test_errors():
    with pytest.raises(TsrkitError, match="needs a model"):
        make().classify(
            Frame(np.zeros((4, 4, 3), np.uint8), "x"), [Candidate.from_box((0, 0, 4, 4), 1)]
        )
    with pytest.raises(ValueError, match="two classes"):
        make().fit(crops(0, shapes=SHAPES[:1]))
    with pytest.raises(ValueError, match="outside"):
        lp.crop_gray(np.zeros((4, 4, 3), np.uint8), (10, 10, 12, 12), 8)
