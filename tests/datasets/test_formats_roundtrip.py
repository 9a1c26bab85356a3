"""Writers: write a dataset, read it back, get the same images, boxes, labels and splits."""

from __future__ import annotations

import cv2
import numpy as np
import pytest

from tsrkit.core.types import Annotation, Dataset, Sample
from tsrkit.datasets import open_dataset, write_dataset


@pytest.fixture
def small_dataset(tmp_path):
    images = tmp_path / "src" / "images"
    images.mkdir(parents=True)
    specs = [
        (
            "a.png",
            "train",
            [((1.5, 2.25, 10.0, 12.0), "red", "red"), ((20.0, 5.0, 27.5, 19.0), "left", "green")],
        ),
        ("b.png", "test", [((0.0, 0.0, 39.0, 29.0), "yellow", "yellow")]),
        ("c.png", "valid", []),
    ]
    samples = []
    for name, split, boxes in specs:
        cv2.imwrite(str(images / name), np.full((30, 40, 3), 90, np.uint8))
        anns = tuple(
            Annotation(b, state, {"label": label, "radius": 2.5}) for b, label, state in boxes
        )
        samples.append(Sample(str(images / name), anns, 40, 30, split, {"lighting": "night"}))
    return Dataset("small", tuple(samples))


def _content(dataset, with_state=True):
    out = {}
    for s in dataset:
        out[s.source] = (
            s.split,
            sorted(
                (
                    a.attributes["label"],
                    a.state if with_state else None,
                    tuple(round(v, 3) for v in a.bbox),
                )
                for a in s.annotations
            ),
        )
    return out


@pytest.mark.parametrize(
    "fmt,target",
    [("normalized", "out/annotations.json"), ("coco", "out/coco.json"), ("voc", "voc")],
)
def test_round_trip_keeps_boxes_labels_states_splits(small_dataset, tmp_path, fmt, target):
    out = tmp_path / target
    write_dataset(small_dataset, fmt, out)
    back = open_dataset(out)
    assert back.format == fmt
    assert _content(back) == _content(small_dataset)


@pytest.mark.parametrize("fmt", ["normalized", "coco"])
def test_json_writers_keep_metadata_and_attributes(small_dataset, tmp_path, fmt):
    out = tmp_path / "o" / f"{fmt}.json"
    write_dataset(small_dataset, fmt, out)
    back = open_dataset(out, format=fmt)
    assert all(s.metadata["lighting"] == "night" for s in back)
    assert all(a.attributes["radius"] == 2.5 for s in back for a in s.annotations)
    assert "../src/images/a.png" in out.read_text()


def test_yolo_round_trip_keeps_labels_and_links_images(small_dataset, tmp_path):
    out = tmp_path / "yolo"
    write_dataset(small_dataset, "yolo", out)
    back = open_dataset(out)
    assert back.format == "yolo" and len(back) == 3
    expected = {
        k.replace("/src/images/", f"/yolo/{v[0]}/images/"): (
            v[0],
            [(label, None, box) for label, _, box in v[1]],
        )
        for k, v in _content(small_dataset).items()
    }
    got = _content(back, with_state=False)
    assert got.keys() == expected.keys()
    for key, (split, anns) in got.items():
        assert split == expected[key][0]
        for (label, _, box), (want_label, _, want) in zip(anns, expected[key][1]):
            assert label == want_label and box == pytest.approx(want, abs=1e-3)
    assert {a.state for s in back for a in s.annotations} == {"red", "yellow", "unknown"}
    assert back.samples[0].load().image.shape == (30, 40, 3)
