"""Training-time augmentation of the verifier: boxes follow the resize, looks are seeded."""

from __future__ import annotations

import numpy as np
import pytest
from test_verifier import FAST, tiny_dataset

from tsrkit.core.types import Candidate, Frame
from tsrkit.plugin.base import Detector
from tsrkit.plugin.models import load_model
from tsrkit.plugin.params import ParamError
from tsrkit.plugin.registry import get_registry
from tsrkit.runner.training import train
from tsrkit_plugins.verifiers.augment import Augmentation, camera_look, resized
from tsrkit_plugins.verifiers.mining import labelled_candidates


def square_frame(width: int = 100, height: int = 80) -> Frame:
    """A black frame with a white square on rows 30-49, columns 20-39: its box in pixel-centre
    coordinates is (19.5, 29.5, 39.5, 49.5)."""
    image = np.zeros((height, width, 3), np.uint8)
    image[30:50, 20:40] = 255
    return Frame(image, "square")


def test_halving_maps_the_box_onto_the_averaged_square():
    view, boxes = resized(square_frame(), [(19.5, 29.5, 39.5, 49.5)], 0.5)
    assert view.image.shape == (40, 50, 3) and view.source == "square@x0.5"
    # (v + 0.5) x 0.5 - 0.5 on each edge; area averaging of aligned 2x2 blocks: rows 15-24,
    # columns 10-19 exactly white, all else black
    assert boxes == [(9.5, 14.5, 19.5, 24.5)]
    expected = np.zeros((40, 50, 3), np.uint8)
    expected[15:25, 10:20] = 255
    assert np.array_equal(view.image, expected)


def test_enlarging_keeps_the_square_centred_in_its_mapped_box():
    view, [box] = resized(square_frame(), [(19.5, 29.5, 39.5, 49.5)], 1.5)
    assert view.image.shape == (120, 150, 3)
    assert box == pytest.approx((29.5, 44.5, 59.5, 74.5))  # centre (29.5, 39.5) -> (44.5, 59.5)
    weight = view.image[..., 0].astype(float)
    yy, xx = np.mgrid[: weight.shape[0], : weight.shape[1]]
    centre = ((xx * weight).sum() / weight.sum(), (yy * weight).sum() / weight.sum())
    assert centre == pytest.approx(((box[0] + box[2]) / 2, (box[1] + box[3]) / 2), abs=1e-6)


def test_a_rounded_size_scales_boxes_by_the_exact_factor():
    view, [box] = resized(square_frame(101, 80), [(0.0, 0.0, 10.0, 4.0)], 0.5)
    assert view.image.shape == (40, 50, 3)  # round(50.5) = 50: x factor 50 / 101, not 0.5
    assert box == pytest.approx((0.5 * 50 / 101 - 0.5, -0.25, 10.5 * 50 / 101 - 0.5, 1.75))


def test_camera_looks_are_seeded_by_seed_and_source_and_keep_the_frame_shape():
    frame = tiny_dataset(1).samples[0].load()
    looks = [v.image for v, _ in Augmentation((1.0,), 3, seed=5).views(frame, [])]
    again = [v.image for v, _ in Augmentation((1.0,), 3, seed=5).views(frame, [])]
    other = [v.image for v, _ in Augmentation((1.0,), 3, seed=6).views(frame, [])]
    assert len(looks) == 4 and looks[0] is frame.image  # scale 1: the frame as it is
    assert all(a.shape == frame.image.shape and a.dtype == np.uint8 for a in looks)
    assert all(np.array_equal(a, b) for a, b in zip(looks, again))
    assert not any(np.array_equal(a, b) for a, b in zip(looks[1:], other[1:]))
    assert not np.array_equal(looks[1], looks[2])
    # a mid grey stays grey-ish: the look changes colour and exposure, not the content
    grey = np.full((8, 8, 3), 128, np.uint8)
    out = camera_look(grey, np.random.default_rng(0)).astype(int)
    assert np.ptp(out) <= 40 and 30 <= out.mean() <= 230


def test_views_keep_their_sources_apart_and_their_boxes_with_them():
    frame = square_frame()
    views = list(Augmentation((1.0, 0.5, 1.5), 1).views(frame, [(19.5, 29.5, 39.5, 49.5)]))
    assert [v.source for v, _ in views] == [
        "square",
        "square@x0.5",
        "square@x1.5",
        "square@look0.0",
    ]
    assert [b for _, b in views] == [
        [(19.5, 29.5, 39.5, 49.5)],
        [(9.5, 14.5, 19.5, 24.5)],
        [pytest.approx((29.5, 44.5, 59.5, 74.5))],
        [(19.5, 29.5, 39.5, 49.5)],
    ]


class Brightest(Detector):
    """One candidate on the centroid of the brightest pixels (test stand-in)."""

    name = "brightest"

    def detect(self, frame):
        grey = frame.image.max(axis=2)
        yy, xx = np.nonzero(grey >= grey.max() - 1)
        return [Candidate.from_circle(xx.mean(), yy.mean(), 2, 1.0)]


def test_mining_labels_each_resized_view_by_its_own_boxes():
    from tsrkit.core.types import Annotation, Sample

    image = square_frame().image
    sample = Sample(
        "sq", (Annotation((19.5, 29.5, 39.5, 49.5), "red"),), 100, 80, "train", image=image
    )
    data = labelled_candidates(
        [sample],
        Brightest(),
        lambda frame, candidates: candidates,
        lambda image, candidates: np.full((len(candidates), 1), image.shape[1], np.float32),
        1,
        0,
        augmentation=Augmentation((1.0, 0.25, 2.0)),
    )
    assert data.labels.tolist() == [1, 1, 1]  # the candidate on the square is in its box
    assert data.features[:, 0].tolist() == [100, 25, 200]  # the detector ran on each view


def test_augment_params_are_checked_with_clear_errors():
    reg = get_registry()
    with pytest.raises(ParamError, match=r"0\.5 twice"):
        reg.create("verifier", "verifier", {"augment_scales": "1,0.5,0.5"})
    with pytest.raises(ParamError, match="augment_scales"):
        reg.create("verifier", "verifier", {"augment_scales": "1,8"})
    with pytest.raises(ParamError, match="augment_colour"):
        reg.create("verifier", "verifier", {"augment_colour": "-1"})


def test_augmented_training_is_deterministic_and_learns_from_more_candidates(tmp_path):
    detector = get_registry().create("detector", "gray-tophat")
    params = dict(FAST, augment_scales="1,0.5,1.5", augment_colour=1)
    paths = [
        train("verifier", tiny_dataset(3), tmp_path / f"m{k}", params, detector) for k in (1, 2)
    ]
    a, b = (load_model(p, "verifier") for p in paths)
    for key in a.arrays:
        assert np.array_equal(a.arrays[key], b.arrays[key])
    unaugmented = dict(FAST, augment_colour=0)
    plain = load_model(
        train("verifier", tiny_dataset(3), tmp_path / "p", unaugmented, detector), "verifier"
    )
    assert a.info["positives"] > plain.info["positives"]
    # three more views of each of 3 frames, and one look of the one no-light scene
    assert a.info["frames"] == plain.info["frames"] + 3 * 3 + 1
