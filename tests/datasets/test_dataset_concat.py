"""Several datasets as one: NAME[:SPLIT] references, concatenation, train --dataset repeated."""

from __future__ import annotations

import json

import pytest
from click.testing import CliRunner

from tsrkit.cli.main import cli
from tsrkit.core.errors import TsrkitError
from tsrkit.core.types import Annotation, Dataset, Sample
from tsrkit.datasets import concat_datasets, open_datasets, parse_reference
from tsrkit.datasets.registry import load_registry


def test_parse_reference_takes_the_last_colon_unless_the_path_exists(tmp_path):
    assert parse_reference("kr:valid", "train") == ("kr", "valid")
    assert parse_reference("kr", "train") == ("kr", "train")
    assert parse_reference("kr") == ("kr", None)
    odd = tmp_path / "a:b"
    odd.mkdir()
    assert parse_reference(str(odd), "test") == (str(odd), "test")
    assert parse_reference("/data/x:y/z") == ("/data/x:y/z", None)
    with pytest.raises(TsrkitError, match="empty split"):
        parse_reference("kr:")


def small(name: str, info: dict) -> Dataset:
    samples = tuple(
        Sample(f"{name}{i}", (Annotation((0, 0, 2, 2), "red"),), split=("train", "test")[i % 2])
        for i in range(3)
    )
    return Dataset(name, samples, "normalized", "", info)


def test_concat_keeps_order_and_the_facts_the_parts_agree_on():
    a = small("a", {"box": "housing", "licence": "CC BY 4.0"})
    b = small("b", {"box": "housing", "licence": "research"})
    both = concat_datasets([a, b])
    assert both.name == "a+b"
    assert [s.source for s in both] == ["a0", "a1", "a2", "b0", "b1", "b2"]
    assert both.info == {"box": "housing", "parts": ["a", "b"]}
    assert concat_datasets([a]) is a
    with pytest.raises(TsrkitError):
        concat_datasets([])


def test_open_datasets_applies_each_split_and_the_default():
    both = open_datasets(["roboflow_traffic_light_kr:valid", "roboflow_cinta_v2_id"], split="test")
    assert both.name == "roboflow_traffic_light_kr:valid+roboflow_cinta_v2_id:test"
    assert len(both) == 25 + 100  # KR valid + cinTA test (datasets README)
    assert {s.split for s in both} == {"valid", "test"}
    assert "box" not in both.info  # KR boxes lenses, cinTA housings: no shared convention
    with pytest.raises(TsrkitError, match="its splits: test, valid"):
        open_datasets(["roboflow_cinta_v2_id:train"])


def test_train_reads_repeated_datasets(tmp_path):
    result = CliRunner().invoke(
        cli,
        [
            "train",
            "ab-hist",
            "--dataset",
            "udacity_mit_tl_crops:test",
            "--dataset",
            "udacity_mit_tl_crops",
            "--split",
            "train",
            "--out",
            str(tmp_path / "ab"),
        ],
    )
    assert result.exit_code == 0, result.output
    training = json.loads((tmp_path / "ab.json").read_text())["training"]
    assert training["dataset"] == "udacity_mit_tl_crops:test+udacity_mit_tl_crops:train"
    assert training["samples"] == 297 + 1187
    licence = load_registry()["udacity_mit_tl_crops"].licence
    assert "CC BY-SA 4.0" in licence
    assert training["licences"] == {
        "udacity_mit_tl_crops:test": licence,
        "udacity_mit_tl_crops:train": licence,
    }
