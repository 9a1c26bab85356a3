"""ab-hist (Zheng 3.3): histograms, Eq. 3.20 similarity, training, decisions, model files."""

from __future__ import annotations

import numpy as np
import pytest
from oracles.lamps import COLOURS, lamp, training_set

from tsrkit.core.types import Candidate, Frame
from tsrkit.plugin.models import ModelError, load_model, save_model
from tsrkit.plugin.registry import get_registry
from tsrkit_plugins.classifiers.ab_hist import ab_cells, ab_histograms, similarities
from tsrkit_plugins.classifiers.decision import discriminative_ratio


def make(**params):
    return get_registry().create("classifier", "ab-hist", params)


@pytest.fixture(scope="module")
def model_path(tmp_path_factory):
    classifier = make(smooth=0, min_chroma=0)
    path = tmp_path_factory.mktemp("ab") / "model"
    save_model(
        path,
        classifier.fit(training_set()),
        plugin="ab-hist",
        plugin_version="t",
        params=classifier.params,
        training={},
    )
    return path


def test_histograms_match_numpy_histogram2d_region_by_region():
    rng = np.random.default_rng(3)
    lab = rng.integers(0, 256, (180, 3), dtype=np.uint8)
    region = rng.integers(0, 3, 180)
    mask = (rng.random(180) < 0.6) & (region != 2)
    cells = ab_cells(8, 0.0).take(lab[:, 1].astype(int) * 256 + lab[:, 2])
    got = ab_histograms(np.where(mask, cells, 64), region, 3, 8)
    for i in range(2):
        chosen = mask & (region == i)
        expected, _, _ = np.histogram2d(
            lab[chosen, 1], lab[chosen, 2], bins=8, range=[[0, 256], [0, 256]]
        )
        assert np.allclose(got[i], expected / chosen.sum())
        assert got[i].sum() == pytest.approx(1.0)
    assert got.shape == (3, 8, 8) and not got[2].any()


def test_cells_leave_out_colours_below_the_chroma_floor():
    cells = ab_cells(8, 10.0)
    assert cells[128 * 256 + 128] == 64  # grey (a = b = 128): chroma 0, the spare cell
    assert cells[200 * 256 + 128] == 6 * 8 + 4  # chroma 72: a in bin 6, b in bin 4
    assert cells[133 * 256 + 134] == 64 and ab_cells(8, 0.0)[133 * 256 + 134] == 4 * 8 + 4


def test_similarity_is_one_for_equal_and_zero_for_disjoint_histograms():
    h = np.array([[1.0, 2.0], [0.0, 0.0]], np.float32)
    other = np.array([[0.0, 0.0], [0.0, 5.0]], np.float32)
    half = np.array([[1.0, 0.0], [0.0, 1.0]], np.float32)
    got = similarities(np.stack([h, np.zeros_like(h)]), np.stack([3 * h, other, half]))
    assert got[0, :2] == pytest.approx([1.0, 0.0])
    assert got[1].tolist() == [0.0, 0.0, 0.0]
    single = np.array([[[1.0, 0.0], [0.0, 0.0]]], np.float32)
    assert similarities(single, half[None])[0, 0] == pytest.approx(0.5)


@pytest.mark.parametrize("state", ["red", "yellow", "green"])
@pytest.mark.parametrize("mode", ["max", "saturation"])
def test_pure_disks_get_their_state_with_a_ratio_near_one(model_path, state, mode):
    classifier = make(model=str(model_path), smooth=0, min_chroma=0, mode=mode)
    image = lamp(COLOURS[state], size=40, radius=8, seed=11)
    det = classifier.classify(Frame(image, "t"), [Candidate.from_circle(20, 20, 8, 1.0)])[0]
    assert det.state == state
    assert discriminative_ratio(det.state_scores) > 0.8


def test_night_halo_is_classified_by_its_annulus(model_path):
    white = (250, 250, 250)
    image = lamp(COLOURS["red"], size=48, radius=12, core=white, seed=5)
    classifier = make(model=str(model_path), smooth=0, min_chroma=0, mode="saturation")
    det = classifier.classify(Frame(image, "t"), [Candidate.from_circle(24, 24, 6, 1.0)])[0]
    assert det.state == "red"
    plain = lamp(white, size=48, radius=6, seed=5)
    assert (
        classifier.classify(Frame(plain, "t"), [Candidate.from_circle(24, 24, 6, 1.0)])[
            0
        ].state_scores["red"]
        < det.state_scores["red"]
    )


def test_low_discriminative_ratio_gives_unknown(model_path):
    grey = lamp((128, 128, 128), size=24, radius=8)
    classifier = make(model=str(model_path), smooth=0, min_chroma=0, min_ratio=0.99)
    assert (
        classifier.classify(Frame(grey, "t"), [Candidate.from_box((4, 4, 20, 20), 1)])[0].state
        == "unknown"
    )


def test_training_is_deterministic_and_averages_histograms():
    first = make(smooth=0).fit(training_set())
    second = make(smooth=0).fit(training_set())
    assert np.array_equal(first.arrays["histograms"], second.arrays["histograms"])
    assert first.arrays["counts"].tolist() == [4, 4, 4]
    assert first.arrays["histograms"].sum(axis=(1, 2)) == pytest.approx([1, 1, 1], rel=1e-3)


def test_training_needs_every_colour():
    with pytest.raises(ValueError, match="yellow"):
        make().fit([s for s in training_set() if s.annotations[0].state != "yellow"])


def test_model_round_trip_and_wrong_models(tmp_path, model_path):
    model = load_model(model_path, plugin="ab-hist")
    image = lamp(COLOURS["green"], size=30, radius=9)
    frame, cands = Frame(image, "t"), [Candidate.from_box((6, 6, 24, 24), 1.0)]
    assert (
        make(model=str(model_path), smooth=0, min_chroma=0).classify(frame, cands)[0].state_scores
        == make(model=str(model_path), smooth=0, min_chroma=0)
        .classify(frame, cands)[0]
        .state_scores
    )
    assert model.arrays["histograms"].shape == (3, 32, 32)
    other = tmp_path / "other"
    save_model(
        other, model, plugin="hsi-backprojection", plugin_version="t", params={}, training={}
    )
    with pytest.raises(ModelError, match="hsi-backprojection"):
        make(model=str(other)).classify(frame, cands)
    (tmp_path / "bad.npz").write_bytes(b"not a zip")
    (tmp_path / "bad.json").write_text(model_path.with_suffix(".json").read_text())
    with pytest.raises(ModelError, match="corrupt"):
        make(model=str(tmp_path / "bad")).classify(frame, cands)


def test_warm_red_prior_reads_orange_red_as_red(tmp_path):
    classifier = make(smooth=4)
    path = tmp_path / "smooth"
    save_model(
        path,
        classifier.fit(training_set()),
        plugin="ab-hist",
        plugin_version="t",
        params=classifier.params,
        training={},
    )
    orange_red = lamp((10, 150, 240), size=40, radius=8, seed=4)  # a-b angle 70, red 34, yellow 90
    cand = [Candidate.from_circle(20, 20, 8, 1.0)]
    states = {
        prior: make(model=str(path), smooth=4, red_prior=prior)
        .classify(Frame(orange_red, "t"), cand)[0]
        .state
        for prior in (True, False)
    }
    assert states == {True: "red", False: "yellow"}
