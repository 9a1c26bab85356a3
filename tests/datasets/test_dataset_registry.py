"""datasets.yaml, open_dataset by name / path / "sample", and format auto-detection."""

from __future__ import annotations

import json

import pytest

from tsrkit.core.errors import TsrkitError
from tsrkit.datasets import DatasetError, load_registry, open_dataset

REAL = [
    "roboflow_traffic_light_kr",
    "roboflow_cinta_v2_id",
    "udacity_mit_tl_crops",
    "lisa_vgis_bulb_crops",
    "gtsrb_test_35px_subset",
    "dtld_fridtjofs",
    "iwai_japan_tl",
    "traffic_pi_us",
]


def _write_registry(tmp_path, monkeypatch, text):
    file = tmp_path / "datasets.yaml"
    file.write_text(text)
    monkeypatch.setenv("TSRKIT_DATASETS_YAML", str(file))
    return file


def test_repository_registry_lists_the_real_sets_and_sample(shared_datasets):
    registry = load_registry()
    assert set(REAL) | {"sample"} == set(registry)
    for name in REAL:
        entry = registry[name]
        assert entry.licence and entry.citation and entry.manifest == "MANIFEST.sha256"
        assert entry.annotation_path().exists()
        assert (entry.root_path() / entry.manifest).is_file()
    assert registry["roboflow_traffic_light_kr"].states == {"left": "green"}


def test_the_japanese_set_is_one_fold_of_horizontal_housings_not_exhaustive(shared_datasets):
    dataset = open_dataset("iwai_japan_tl")
    assert dataset.info["exhaustive"] is False and dataset.info["box"] == "housing"
    boxes = [a.bbox for s in dataset.samples for a in s.annotations]
    assert (len(dataset.samples), len(boxes)) == (453, 658)
    wide = [b[2] - b[0] > b[3] - b[1] for b in boxes]
    assert sum(wide) >= 0.95 * len(boxes)  # horizontal heads
    states = {a.state for s in dataset.samples for a in s.annotations}
    assert states == {"red", "yellow", "green", "unknown"}


def test_relative_root_resolves_against_data_dir(tmp_path, monkeypatch):
    data = tmp_path / "data" / "mine"
    data.mkdir(parents=True)
    (data / "annotations.json").write_text(
        json.dumps(
            [
                {
                    "file": "a.jpg",
                    "split": "test",
                    "width": 8,
                    "height": 6,
                    "boxes": [{"label": "Stop", "x_min": 1, "y_min": 1, "x_max": 3, "y_max": 4}],
                }
            ]
        )
    )
    _write_registry(
        tmp_path,
        monkeypatch,
        """
datasets:
  mine:
    format: normalized
    root: mine
    path: annotations.json
    task: detection
    box: lens
    licence: CC0
    citation: me
    states: {Stop: off}
""",
    )
    monkeypatch.setenv("TSRKIT_DATA_DIR", str(tmp_path / "data"))
    ds = open_dataset("mine")
    assert ds.name == "mine" and ds.info["licence"] == "CC0" and ds.info["box"] == "lens"
    assert ds.samples[0].source == str(data / "a.jpg")
    assert ds.samples[0].annotations[0].state == "off"
    assert open_dataset("mine", states={"Stop": "red"}).samples[0].annotations[0].state == "red"
    monkeypatch.setenv("TSRKIT_DATA_DIR", str(tmp_path / "nowhere"))
    with pytest.raises(DatasetError, match="TSRKIT_DATA_DIR"):
        open_dataset("mine")


def test_malformed_registry_entry_is_named(tmp_path, monkeypatch):
    file = _write_registry(
        tmp_path,
        monkeypatch,
        """
datasets:
  broken:
    format: coco
    root: x
    task: detection
    box: lens
""",
    )
    with pytest.raises(DatasetError, match=rf"{file}: datasets.broken: missing licence, citation"):
        load_registry()
    file.write_text("datasets:\n  a: [1,\n")
    with pytest.raises(DatasetError, match=r"datasets.yaml: line \d+: not valid YAML"):
        load_registry()


def test_ambiguous_and_unknown_formats_ask_for_format(shared_datasets, tmp_path):
    with pytest.raises(TsrkitError, match=r"several formats match \(normalized, yolo\).*--format"):
        open_dataset(shared_datasets / "roboflow_traffic_light_kr")
    (tmp_path / "notes.txt").write_text("hello\n")
    with pytest.raises(TsrkitError, match=r"no format recognises it.*--format"):
        open_dataset(tmp_path / "notes.txt")
    with pytest.raises(TsrkitError, match="neither a registered dataset"):
        open_dataset("no_such_dataset")


def test_sample_resolves_through_synth(tmp_path, monkeypatch):
    file = tmp_path / "annotations.json"
    file.write_text(
        json.dumps([{"file": "f.jpg", "split": "train", "width": 4, "height": 4, "boxes": []}])
    )
    monkeypatch.setattr("tsrkit.datasets.scenes.sample_path", lambda: file)
    ds = open_dataset("sample")
    assert ds.name == "sample" and ds.format == "normalized" and len(ds) == 1
    assert ds.info["box"] == "lens"
