"""Lens/annulus regions, the lit-lens search in a housing box, and the shared decisions."""

from __future__ import annotations

import cv2
import numpy as np
import pytest
from oracles.lamps import COLOURS, crop_sample, housing, lamp

from tsrkit.core.types import Annotation, Candidate, Frame, Sample
from tsrkit.plugin.registry import get_registry
from tsrkit_plugins.classifiers.decision import best_state, discriminative_ratio, fuse_lights
from tsrkit_plugins.shared.regions import (
    clip_box,
    disk_kernel,
    find_lens,
    is_housing,
    labelled_lenses,
    lens_of,
    ring_runs,
    rings,
)

PARAMS = {"region": "auto", "elongation": 1.5, "lens_fraction": 0.4}


def test_rings_match_distances_pixel_by_pixel():
    image = np.arange(30 * 40 * 3, dtype=np.uint32).reshape(30, 40, 3).astype(np.uint8)
    x, y, r = 12.3, 8.7, 4.0
    area = rings(image, x, y, r)
    disk, annulus = [], []
    for row in range(30):
        for col in range(40):
            d = np.hypot(col + 0.5 - x, row + 0.5 - y)
            if d <= r:
                disk.append(image[row, col])
            elif d <= 2 * r:
                annulus.append(image[row, col])
    assert np.array_equal(area.patch[area.disk], np.array(disk))
    assert np.array_equal(area.patch[area.annulus], np.array(annulus))


def test_rings_are_clipped_at_the_border():
    area = rings(np.zeros((10, 10, 3), np.uint8), 0.5, 0.5, 3)
    assert area.patch.shape[:2] == (7, 7)
    assert not (area.disk & area.annulus).any()


@pytest.mark.parametrize("radius", [0, -1])
def test_rings_reject_a_non_positive_radius(radius):
    with pytest.raises(ValueError, match="positive"):
        rings(np.zeros((5, 5, 3), np.uint8), 2, 2, radius)


def test_box_outside_the_image_is_an_error():
    with pytest.raises(ValueError, match="outside"):
        clip_box((50, 50, 60, 60), 20, 20)


def test_disk_kernel_sums_to_one():
    assert disk_kernel(3.5).sum() == pytest.approx(1.0)
    assert disk_kernel(0.2).shape == (1, 1)


@pytest.mark.parametrize("lit", [0, 1, 2])
@pytest.mark.parametrize("vertical", [True, False])
def test_find_lens_finds_the_lit_lamp_along_the_long_axis(lit, vertical):
    image = housing(COLOURS["green"], lit, vertical=vertical)
    lens = find_lens(image, (0, 0, image.shape[1], image.shape[0]))
    along = lens.y if vertical else lens.x
    assert abs(along - (20 * lit + 10)) <= 2
    assert lens.radius == pytest.approx(8.0)


def test_auto_region_reads_elongated_boxes_as_housings():
    square = Candidate.from_box((0, 0, 10, 10), 1.0)
    tall = Candidate.from_box((0, 0, 10, 30), 1.0)
    assert not is_housing(square, "auto", 1.5)
    assert is_housing(tall, "auto", 1.5)
    assert is_housing(square, "housing", 1.5)
    assert not is_housing(tall, "lens", 1.5)
    with pytest.raises(ValueError, match="region"):
        is_housing(tall, "bulb", 1.5)


def test_lens_of_keeps_a_lens_candidate_and_searches_a_housing():
    image = housing(COLOURS["red"], 0)
    box = Candidate.from_box((0, 0, 20, 60), 1.0)
    assert lens_of(image, box, {**PARAMS, "region": "lens"}) is box
    assert lens_of(image, box, PARAMS).y == pytest.approx(10, abs=2)


def test_labelled_lenses_passes_over_other_labels():
    image = lamp(COLOURS["red"])
    samples = [
        crop_sample(image, "red"),
        Sample("arrow", (Annotation((0, 0, 24, 24), "left-arrow"),), image=image),
    ]
    got = list(labelled_lenses(samples, ("red", "yellow", "green"), PARAMS))
    assert [state for state, _, _ in got] == ["red"]


def test_discriminative_ratio_and_best_state():
    scores = {"red": 0.2, "yellow": 0.9, "green": 0.45}
    assert best_state(scores) == "yellow"
    assert discriminative_ratio(scores) == pytest.approx(1 - 0.2 / 0.9)
    assert discriminative_ratio({"red": 0.0, "green": 0.0}) == 0.0
    with pytest.raises(ValueError):
        best_state({})


def test_fuse_lights_consensus_then_most_probable_then_unknown():
    assert fuse_lights([("red", 0.1), ("red", 0.2)], threshold=0.5) == "red"
    assert fuse_lights([("red", 0.3), ("green", 0.8)], threshold=0.5) == "green"
    assert fuse_lights([("red", 0.3), ("green", 0.4)], threshold=0.5) == "unknown"
    assert fuse_lights([], threshold=0.5) == "unknown"


@pytest.mark.parametrize("name", ["ab-hist", "hsi-backprojection"])
def test_shipped_models_classify_real_mit_housing_crops(shared_datasets, name):
    classifier = get_registry().create("classifier", name, {})
    root = shared_datasets / "udacity_mit_tl_crops" / "test"
    right = total = 0
    for state in ("red", "green"):
        for path in sorted((root / state).glob("*.jpg"))[:40]:
            image = cv2.imread(str(path))
            box = Candidate.from_box((0, 0, image.shape[1], image.shape[0]), 1.0)
            right += classifier.classify(Frame(image, str(path)), [box])[0].state == state
            total += 1
    assert total == 80 and right / total >= 0.85


def test_find_lens_passes_over_blue_sky():
    image = housing(COLOURS["green"], 2)
    image[:20] = (235, 190, 90)  # bright saturated sky blue where the top lens would be
    lens = find_lens(image, (0, 0, 20, 60))
    assert abs(lens.y - 50) <= 2


def test_ring_runs_hold_exactly_the_pixels_of_rings_for_any_lens():
    """The row runs of ring_runs (many lenses at once) give exactly the masks of the per-pixel
    test of rings(), for lenses of any size and sub-pixel place, clipped by the border or not."""
    rng = np.random.default_rng(0)
    image = np.zeros((60, 90, 3), np.uint8)
    lenses = []
    for _ in range(3000):
        r = float(rng.choice([rng.uniform(0.01, 1.5), rng.uniform(0.5, 30), rng.integers(1, 12)]))
        x = float(rng.choice([rng.uniform(-5, 95), rng.integers(0, 90) + 0.5]))
        y = float(rng.choice([rng.uniform(-5, 65), rng.integers(0, 60) + 0.5]))
        try:
            rings(image, x, y, r)
        except ValueError:
            continue
        lenses.append((x, y, r))
    runs = ring_runs(image, lenses)
    run, offset = runs.pixels()
    owner, rows = runs.owner.take(run), runs.row.take(run)
    cols, annulus = runs.col.take(run) + offset, runs.annulus.take(run)
    bounds = np.cumsum([0, *np.bincount(owner, minlength=len(lenses))])
    assert np.all(np.diff(owner) >= 0)  # lens by lens
    for i, (x, y, r) in enumerate(lenses):
        area = rings(image, x, y, r)
        x0, y0 = runs.boxes[i, :2]
        assert runs.boxes[i].tolist() == [x0, y0, x0 + area.disk.shape[1], y0 + area.disk.shape[0]]
        mine = slice(bounds[i], bounds[i + 1])
        disk, ring = np.zeros_like(area.disk), np.zeros_like(area.annulus)
        disk[rows[mine] - y0, cols[mine] - x0] = ~annulus[mine]
        ring[rows[mine] - y0, cols[mine] - x0] = annulus[mine]
        assert np.array_equal(disk, area.disk) and np.array_equal(ring, area.annulus)
        assert (disk | ring).sum() == bounds[i + 1] - bounds[i]  # no pixel twice


def test_ring_runs_refuse_what_rings_refuses():
    image = np.zeros((10, 10, 3), np.uint8)
    with pytest.raises(ValueError, match="outside"):
        ring_runs(image, [(5, 5, 2), (50, 50, 3)])
    with pytest.raises(ValueError, match="positive"):
        ring_runs(image, [(5, 5, 2), (5, 5, 0)])
