"""Evaluation options and the extension points: evaluated box, non-exhaustive sets, writers,
parameter routing shared by the API and the CLI, and ``train --detector``."""

from __future__ import annotations

import dataclasses
import json
from typing import ClassVar

import benchmark_fakes
import pytest
from benchmark_fakes import OracleDetector, hand_dataset, make
from click.testing import CliRunner

import tsrkit
from tsrkit.cli.main import cli
from tsrkit.core.types import Annotation, Dataset
from tsrkit.plugin.models import Model
from tsrkit.plugin.params import ParamError
from tsrkit.plugin.selection import build_compare
from tsrkit.reporting.benchmarking import benchmark


class HousingVerifier(tsrkit.Verifier):
    """Fits a housing from one radius above the lens centre to five below (a test fake)."""

    name = "tall-housing"
    summary = "housing box from y - r to y + 5r"

    def verify(self, frame, candidates):
        return [
            dataclasses.replace(
                c,
                housing=(c.x - c.radius, c.y - c.radius, c.x + c.radius, c.y + 5 * c.radius),
                housing_score=1.0,
            )
            for c in candidates
        ]


class LearningVerifier(HousingVerifier):
    name = "learning-verifier"
    seen: ClassVar[list] = []

    def fit(self, samples, *, detector=None):
        LearningVerifier.seen.append(detector.name)
        return Model({"n": [len(list(samples))]})


@tsrkit.hookimpl
def register_verifiers(register):
    register(HousingVerifier)
    register(LearningVerifier)


def housing_dataset(box: str) -> Dataset:
    """The hand frames with their ground truth replaced by the fake verifier's housings."""
    data = hand_dataset(4)
    samples = []
    for s in data.samples:
        truth = tuple(
            Annotation((x - 3, y - 3, x + 3, y + 15), "red") for x, y, _ in s.metadata["dets"]
        )
        samples.append(dataclasses.replace(s, annotations=truth))
    return Dataset("housings", tuple(samples), info={"box": box})


def test_eval_box_chooses_lens_or_housing_and_auto_follows_the_registry():
    verifier = HousingVerifier()
    data = housing_dataset("housing")
    run = {
        box: benchmark(data, make(OracleDetector), verifier=verifier, box=box, cache=False)
        for box in ("lens", "housing", "auto")
    }
    assert run["housing"]["iou50"]["recall"] == 1.0  # the housing is the ground truth
    assert run["lens"]["iou50"]["recall"] == 0.0  # a 6x6 lens in a 6x18 box: IoU 1/3
    assert run["auto"]["evaluated_box"] == "housing" and run["lens"]["evaluated_box"] == "lens"
    assert run["auto"]["iou50"] == run["housing"]["iou50"]
    lens_set = benchmark(
        housing_dataset("lens"), make(OracleDetector), verifier=verifier, cache=False
    )
    assert lens_set["evaluated_box"] == "lens" and lens_set["iou50"]["recall"] == 0.0


def test_not_exhaustive_dataset_leaves_false_positive_figures_out(tmp_path):
    data = hand_dataset(6)
    full = benchmark(data, make(OracleDetector), cache=False)
    partial = benchmark(
        dataclasses.replace(data, info={"exhaustive": False}),
        make(OracleDetector),
        cache=False,
        out=tmp_path,
    )
    assert full["per_frame"]["precision_mean"] == pytest.approx(0.75)
    for section, key in (
        ("per_frame", "precision_mean"),
        ("intervals", "precision_mean"),
        ("iou50", "precision"),
        ("iou", "precision"),
        ("iou50", "ap"),
        ("iou50", "ap_50_95"),
    ):
        assert partial[section][key] is None, (section, key)
    assert partial["per_frame"]["recall_mean"] == full["per_frame"]["recall_mean"]
    assert "not exhaustively labelled" in partial["notes"][0]
    assert "not exhaustively labelled" in (tmp_path / "summary.md").read_text()


def test_writers_list_their_files_and_can_be_chosen(tmp_path):
    report = benchmark(hand_dataset(4), make(OracleDetector), cache=False, out=tmp_path / "all")
    assert report["files"] == [
        "detections.coco.json",
        "detections.jsonl",
        "frames.csv",
        "ground_truth.coco.json",
        "headline.csv",
        "report.html",
        "report.json",
        "summary.md",
    ]
    for name in report["files"] + report["plots"]:
        assert (tmp_path / "all" / name).is_file(), name
    frames = (tmp_path / "all" / "frames.csv").read_text().splitlines()
    assert frames[0].startswith("frame,source") and len(frames) == 5
    assert frames[2].endswith(",2,2,0.5,0.5")  # frame 1: one hit, one false positive
    only = benchmark(
        hand_dataset(4), make(OracleDetector), cache=False, out=tmp_path / "one", writers=["json"]
    )
    assert only["files"] == ["report.json"] and only["plots"] == []
    assert sorted(p.name for p in (tmp_path / "one").iterdir()) == ["report.json"]


@pytest.fixture
def fakes(registry, monkeypatch):
    registry.add(benchmark_fakes, "benchmark-fakes")
    import sys

    registry.add(sys.modules[__name__], "evaluation-option-fakes")
    monkeypatch.setattr(
        "tsrkit.datasets.open_dataset",
        lambda ref, format=None, images=None: hand_dataset(4, name=ref),
    )
    return registry


def test_compare_refuses_a_parameter_no_plugin_declares(fakes, tmp_path):
    result = CliRunner().invoke(
        cli,
        [
            "compare",
            "--detectors",
            "oracle,shifted",
            "-p",
            "bogus=1",
            "-o",
            str(tmp_path),
            "-w",
            "1",
            "-q",
        ],
    )
    assert result.exit_code == 2 and "unknown parameter 'bogus'" in result.output
    runs = build_compare(["oracle", "shifted"], params=["oracle.delay=0.01", "crash_on=x"])
    assert runs[0].detector.params["delay"] == 0.01 and runs[1].detector.params["delay"] == 0
    assert [r.detector.params["crash_on"] for r in runs] == ["x", "x"]
    with pytest.raises(ParamError, match="unknown parameter"):
        build_compare(["oracle", "shifted"], params={"classifier.model": "m"})


def test_api_config_and_cli_share_one_selection(fakes, tmp_path):
    chosen = tsrkit.select(
        config={"detector": {"name": "oracle", "params": {"delay": 0.5}}},
        params=["crash_on=f"],
        verifier="tall-housing",
    )
    assert chosen.detector.params == {"delay": 0.5, "crash_on": "f"}
    assert chosen.verifier.name == "tall-housing"
    assert tsrkit.select(classifier="always-red", classifier_alone=True).detector is None
    with pytest.raises(ParamError, match="unknown parameter 'bogus'"):
        tsrkit.select("oracle", params={"bogus": 1})


def test_train_passes_the_detector_to_a_trainable_verifier(fakes, tmp_path):
    LearningVerifier.seen.clear()
    result = CliRunner().invoke(
        cli,
        [
            "train",
            "learning-verifier",
            "--dataset",
            "hand",
            "--detector",
            "oracle",
            "-p",
            "detector.delay=0",
            "--out",
            str(tmp_path / "m"),
        ],
    )
    assert result.exit_code == 0, result.output
    assert LearningVerifier.seen == ["oracle"]
    meta = json.loads((tmp_path / "m.json").read_text())
    assert meta["training"]["detector"]["name"] == "oracle"
    missing = CliRunner().invoke(
        cli, ["train", "learning-verifier", "--dataset", "hand", "--out", str(tmp_path / "n")]
    )
    assert missing.exit_code == 2 and "--detector" in missing.output
    assert isinstance(LearningVerifier(), tsrkit.Trainable)
