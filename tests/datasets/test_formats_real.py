"""Format readers on the real files of shared/datasets."""

from __future__ import annotations

from collections import Counter

import pytest

from tsrkit.datasets import open_dataset

DETECTION = {"roboflow_traffic_light_kr": (38, 82), "roboflow_cinta_v2_id": (300, 403)}


@pytest.mark.parametrize("name", sorted(DETECTION))
def test_yolo_and_normalized_agree_box_for_box(shared_datasets, name):
    normalized = open_dataset(shared_datasets / name, format="normalized")
    yolo = open_dataset(shared_datasets / name, format="yolo")
    assert (len(yolo), sum(len(s.annotations) for s in yolo)) == DETECTION[name]
    by_source = {s.source: s for s in normalized}
    for sample in yolo:
        expected = by_source[sample.source]
        assert (sample.width, sample.height, sample.split) == (
            expected.width,
            expected.height,
            expected.split,
        )
        got = sorted((a.attributes["label"], a.bbox) for a in sample.annotations)
        want = sorted((a.attributes["label"], a.bbox) for a in expected.annotations)
        assert [g[0] for g in got] == [w[0] for w in want]
        for (_, g), (_, w) in zip(got, want):
            assert g == pytest.approx(w, abs=0.01)


def test_kr_polygon_lines_are_boxed(shared_datasets):
    yolo = open_dataset(shared_datasets / "roboflow_traffic_light_kr", format="yolo")
    shapes = Counter(a.attributes["yolo_shape"] for s in yolo for a in s.annotations)
    assert shapes == {"polygon": 52, "box": 30}


def test_registry_maps_kr_left_arrow_to_green(shared_datasets):
    ds = open_dataset("roboflow_traffic_light_kr")
    left = [a for s in ds for a in s.annotations if a.attributes["label"] == "left"]
    assert len(left) == 21 and {a.state for a in left} == {"green"}
    assert ds.info["box"] == "lens" and ds.info["licence"] == "CC BY 4.0"
    assert Counter(s.split for s in ds) == {"valid": 25, "test": 13}


def test_mit_crops_one_whole_image_box(shared_datasets):
    ds = open_dataset("udacity_mit_tl_crops")
    assert len(ds) == 1484
    assert Counter(s.split for s in ds) == {"train": 1187, "test": 297}
    assert Counter(s.annotations[0].state for s in ds) == {"red": 904, "green": 536, "yellow": 44}
    sample = ds.samples[0]
    assert len(sample.annotations) == 1
    assert sample.annotations[0].bbox == (0, 0, sample.width, sample.height)
    assert sample.load().image.shape[:2] == (sample.height, sample.width)


def test_vgis_crops_carry_lighting(shared_datasets):
    ds = open_dataset("lisa_vgis_bulb_crops", format="crops")
    assert Counter(s.metadata["lighting"] for s in ds) == {"night": 433, "day": 165}
    assert Counter(s.annotations[0].state for s in ds) == {"green": 402, "red": 133, "yellow": 63}
    assert all(s.annotations[0].bbox == (0, 0, 20, 20) for s in ds)


def test_gtsrb_subset_and_original_csv_agree(shared_datasets):
    root = shared_datasets / "gtsrb_test_35px_subset"
    subset = open_dataset("gtsrb_test_35px_subset")
    original = open_dataset(root / "GT-final_test_full_7949rows.csv", images=root / "images")
    assert len(subset) == 2046 and len(original) == 7949
    by_source = {s.source: s.annotations[0] for s in original}
    for sample in subset:
        ann = sample.annotations[0]
        assert by_source[sample.source].attributes["class_id"] == ann.attributes["class_id"]
        assert by_source[sample.source].state == ann.state
        assert 0 <= ann.bbox[0] < ann.bbox[2] <= 35
    first = subset.samples[0].annotations[0]
    assert (first.state, first.attributes["class_id"]) == ("lkw_verboten", 16)
    assert len({s.annotations[0].attributes["class_id"] for s in subset}) == 43
