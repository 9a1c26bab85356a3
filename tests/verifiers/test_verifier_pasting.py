"""Real head crops pasted into scenes as the verifier's extra positives (``crop_frames``)."""

from __future__ import annotations

import numpy as np
import pytest
from test_verifier import FAST, make, tiny_dataset

from tsrkit.core.errors import TsrkitError
from tsrkit.core.types import Annotation, Candidate, Sample
from tsrkit.plugin.models import load_model
from tsrkit.plugin.registry import get_registry
from tsrkit.runner.training import train
from tsrkit_plugins.verifiers.mining import centre_labels
from tsrkit_plugins.verifiers.pasting import (
    CROP_SET,
    ENLARGE,
    FEATHER,
    CropPool,
    crop_frames,
    crop_pool,
    crop_samples,
    feathered_alpha,
    framed_scenes,
    housing_crops,
    paste,
    paste_crops,
    pasted_scenes,
)


def head_crop(colour=(40, 40, 230)) -> np.ndarray:
    """A 20x40 grey head whose top lamp is lit."""
    crop = np.full((40, 20, 3), 60, np.uint8)
    crop[4:16, 4:16] = colour
    return crop


def crops(n: int = 3) -> list[np.ndarray]:
    return [head_crop((40, 40 + 60 * k, 230)) for k in range(n)]


def pool(n: int = 3, rotate: float = 0.0) -> CropPool:
    return CropPool(crops(n), rotate, "+test")


def test_feathered_alpha_ramps_every_side_and_is_opaque_inside():
    alpha = feathered_alpha(10, 8)
    assert alpha.shape == (10, 8)
    assert np.all(alpha[FEATHER:-FEATHER, FEATHER:-FEATHER] == 1.0)
    for edge in (alpha[0], alpha[-1], alpha[:, 0], alpha[:, -1]):
        assert np.allclose(edge, 1 / (FEATHER + 1))
    assert alpha[1, 1] == pytest.approx(2 / (FEATHER + 1))


def test_paste_puts_the_resized_crop_at_the_box_and_leaves_the_rest():
    image = np.zeros((100, 100, 3), np.uint8)
    paste(image, np.full((40, 20, 3), 200, np.uint8), (30, 10, 40, 30))  # halved
    assert np.all(image[10 + FEATHER : 30 - FEATHER, 30 + FEATHER : 40 - FEATHER] == 200)
    assert image[10, 30, 0] == round(200 / (FEATHER + 1))  # the feathered corner
    outside = np.ones(image.shape[:2], bool)
    outside[10:30, 30:40] = False
    assert not image[outside].any()


def test_pasted_crops_lie_at_their_boxes_in_the_upper_frame_without_overlap():
    image = np.zeros((720, 1280, 3), np.uint8)
    boxes = paste_crops(image, crops(), np.random.default_rng(1), count=5)
    assert len(boxes) == 5
    for x0, y0, x1, y1 in boxes:
        height, width = y1 - y0, x1 - x0
        assert 10 <= height <= min(110, ENLARGE * 40) and y1 <= 0.55 * 720
        assert width == pytest.approx(height / 2, abs=1)  # the crops' aspect
        inner = image[int(y0) + FEATHER : int(y1) - FEATHER, int(x0) + FEATHER : int(x1) - FEATHER]
        assert inner.any(axis=2).all()  # every inner pixel is the crop's (none is black)
    painted = image.any(axis=2)
    for k, a in enumerate(boxes):
        for b in boxes[k + 1 :]:
            assert a[2] <= b[0] or b[2] <= a[0] or a[3] <= b[1] or b[3] <= a[1]
        painted[int(a[1]) : int(a[3]), int(a[0]) : int(a[2])] = False
    assert not painted.any()  # nothing drawn outside the boxes
    # a candidate on a pasted lamp is a positive by Zheng's rule
    x0, y0, x1, y1 = boxes[0]
    lamp = Candidate.from_circle((x0 + x1) / 2, y0 + 0.25 * (y1 - y0), 2, 1.0)
    assert centre_labels([lamp], boxes).tolist() == [1]


def test_scenes_are_a_function_of_the_seed():
    first = list(pasted_scenes(2, pool(), seed=5))
    again = list(pasted_scenes(2, pool(), seed=5))
    other = list(pasted_scenes(2, pool(), seed=6))
    assert [f.source for f, _ in first] == [f.source for f, _ in again]
    for (a, boxes_a), (b, boxes_b) in zip(first, again):
        assert a.image.shape == (720, 1280, 3)
        assert np.array_equal(a.image, b.image) and boxes_a == boxes_b and boxes_a
    assert [b for _, b in first] != [b for _, b in other]


def test_the_crop_set_is_read_through_the_registry(shared_datasets):
    samples = crop_samples()
    assert len(samples) == 1187 and all(s.split == "train" for s in samples)
    frame, boxes = next(crop_frames(1))
    assert frame.source.startswith("pasted-crops+up") and len(boxes) == 5


def test_a_missing_crop_set_fails_training_at_once_with_one_clear_error(tmp_path, monkeypatch):
    monkeypatch.setenv("TSRKIT_DATA_DIR", str(tmp_path))
    assert list(crop_frames(0)) == []  # never read when no scene is asked for
    detector = get_registry().create("detector", "gray-tophat")
    with pytest.raises(TsrkitError, match=f"crop_frames > 0 pastes the train crops of {CROP_SET}"):
        make(**dict(FAST, crop_frames=1)).fit(tiny_dataset(1), detector=detector)


@pytest.mark.parametrize("backgrounds", ["synthetic", "real"])
def test_training_reads_the_pasted_scenes(shared_datasets, tmp_path, backgrounds):
    detector = get_registry().create("detector", "gray-tophat")
    infos = [
        load_model(
            train(
                "verifier",
                tiny_dataset(),
                tmp_path / f"m{n}",
                dict(FAST, crop_frames=n, crop_backgrounds=backgrounds),
                detector,
            ),
            "verifier",
        ).info
        for n in (0, 2)
    ]
    assert infos[1]["frames"] == infos[0]["frames"] + 2
    assert infos[1]["positives"] > infos[0]["positives"]


def test_the_defaults_are_the_measured_ones():
    params = make().params
    assert params["crop_frames"] == 80 and params["crop_backgrounds"] == "real"
    assert params["crop_own"] and params["crop_rotate"] == 0.3


def test_real_backgrounds_keep_their_boxes_and_take_crops_clear_of_them():
    own = (100.0, 100.0, 130.0, 180.0)
    backgrounds = [
        Sample(
            f"frame{k}",
            (Annotation(own, "red"),),
            416,
            416,
            "train",
            image=np.zeros((416, 416, 3), np.uint8),
        )
        for k in range(2)
    ]
    scenes = list(framed_scenes(4, pool(), backgrounds, seed=5))
    again = list(framed_scenes(4, pool(), backgrounds, seed=5))
    assert [f.source.rsplit(":", 1)[1] for f, _ in scenes] == ["frame0"] * 2 + ["frame1"] * 2
    for (frame, boxes), (same, boxes_again) in zip(scenes, again):
        assert np.array_equal(frame.image, same.image) and boxes == boxes_again
        assert boxes[0] == own and len(boxes) == 6
        assert not frame.image[100:180, 100:130].any()  # the frame's own light is untouched
        for x0, y0, x1, y1 in boxes[1:]:
            assert 6 <= y1 - y0 <= 64  # heights scaled to the 416 px frame
            assert x1 <= own[0] or own[2] <= x0 or y1 <= own[1] or own[3] <= y0
    assert not backgrounds[0].image.any()  # pasted into a copy


def test_turned_crops_lie_across_and_are_named_apart():
    image = np.zeros((720, 1280, 3), np.uint8)
    boxes = paste_crops(image, crops(), np.random.default_rng(1), count=5, rotate=1.0)
    assert boxes
    for x0, y0, x1, y1 in boxes:  # the 20x40 crops, turned: twice as wide as tall
        assert x1 - x0 == pytest.approx(2 * (y1 - y0), abs=1)
    upright = next(pasted_scenes(1, pool(), seed=5))[0].source
    turned = next(pasted_scenes(1, CropPool(crops(), 0.5, "+turn0.5"), seed=5))[0].source
    assert upright != turned


def test_training_housings_are_cut_out_and_lens_boxes_are_not():
    image = np.zeros((100, 200, 3), np.uint8)
    image[10:70, 20:40] = 90  # a 20x60 housing
    housing, lens = (20.0, 10.0, 40.0, 70.0), (100.0, 10.0, 112.0, 22.0)
    sample = Sample(
        "f", (Annotation(housing, "red"), Annotation(lens, "red")), 200, 100, "train", image=image
    )
    ((name, crop),) = housing_crops([sample])
    assert crop.shape == (60, 20, 3) and np.all(crop == 90) and name.startswith("f")


def test_the_pool_names_its_training_housings(shared_datasets):
    image = np.zeros((100, 200, 3), np.uint8)

    def frame(box):
        return Sample("f", (Annotation(box, "red"),), 200, 100, "train", image=image)

    mit = crop_pool()
    one = crop_pool([frame((20.0, 10.0, 40.0, 70.0))], rotate=0.3)
    other = crop_pool([frame((22.0, 10.0, 42.0, 70.0))], rotate=0.3)
    assert len(one.images) == len(mit.images) + 1 and one.rotate == 0.3
    assert len({mit.tag, one.tag, other.tag}) == 3
