"""compare with and without the verifier (paired tests) and AP50 on lens vs housing boxes."""

from __future__ import annotations

import dataclasses
import json
import sys

import numpy as np
import pytest
from click.testing import CliRunner

import tsrkit
from tsrkit.cli.main import cli
from tsrkit.core.types import Annotation, Candidate, Dataset, Sample
from tsrkit.reporting.comparison import compare

HOUSING = (10.0, 5.0, 20.0, 35.0)  # a vertical head; its top lamp is lit


class TwoLamps(tsrkit.Detector):
    """The lit lamp (10 x 10 lens box: IoU 1/3 with its housing) and one false light."""

    name = "two-lamps"

    def detect(self, frame):
        return [Candidate.from_circle(15, 10, 5, 1.0), Candidate.from_circle(50, 50, 5, 0.5)]


class KeepStrong(tsrkit.Verifier):
    """Keeps candidates scoring at least 0.8 and gives them the true housing."""

    name = "keep-strong"

    def verify(self, frame, candidates):
        return [dataclasses.replace(c, housing=HOUSING) for c in candidates if c.score >= 0.8]


@tsrkit.hookimpl
def register_detectors(register):
    register(TwoLamps)


@tsrkit.hookimpl
def register_verifiers(register):
    register(KeepStrong)


@pytest.fixture
def fakes(registry):
    registry.add(sys.modules[__name__], "compare-verifier-fakes")
    return registry


def heads(frames: int = 8) -> Dataset:
    samples = tuple(
        Sample(
            f"head{i}",
            (Annotation(HOUSING, "red"),),
            80,
            80,
            "test",
            image=np.full((80, 80, 3), i, np.uint8),
        )
        for i in range(frames)
    )
    return Dataset("heads", samples, info={"box": "housing"})


def test_each_detector_runs_with_and_without_the_verifier(fakes, tmp_path):
    result = compare(
        heads(),
        [TwoLamps()],
        verifier=KeepStrong(),
        without_verifier=True,
        cache=False,
        out=tmp_path,
    )
    assert result["runs"] == ["two-lamps", "two-lamps+keep-strong"]
    assert result["reports"][1]["verifier"]["name"] == "keep-strong"
    tests = {t["metric"].split(" (")[0]: t for t in result["verifier_tests"]}
    assert tests["per-frame recall"]["verdict"] == "no significant difference"
    assert tests["per-frame precision"]["mean_difference"] == pytest.approx(0.5)
    assert tests["per-frame precision"]["verdict"] == "two-lamps+keep-strong better"
    fp = tests["false positives per frame"]
    assert fp["mean_difference"] == pytest.approx(1.0) and fp["p_value"] < 0.05
    # the lens box overlaps the housing by 1/3: AP50 0 on lenses, 1 once housings are fitted
    assert result["box_ap50"] == [
        {"run": "two-lamps", "lens": 0.0, "housing": 0.0},
        {"run": "two-lamps+keep-strong", "lens": 0.0, "housing": pytest.approx(1.0)},
    ]
    text = (tmp_path / "compare.md").read_text()
    assert "With vs without the verifier" in text and "housing AP50" in text
    assert (tmp_path / "two-lamps+keep-strong" / "report.json").is_file()


def test_cli_without_verifier_takes_the_verifier_from_a_config(fakes, tmp_path, monkeypatch):
    monkeypatch.setattr("tsrkit.cli.benchmark.load_dataset", lambda *a: heads())
    config = tmp_path / "run.yaml"
    config.write_text("verifier: {name: keep-strong}\n")
    args = ["compare", "--detectors", "two-lamps", "--without-verifier", "-w", "1", "-q"]
    result = CliRunner().invoke(cli, [*args, "--config", str(config), "-o", str(tmp_path / "o")])
    assert result.exit_code == 0, result.output
    stored = json.loads((tmp_path / "o" / "compare.json").read_text())
    assert stored["runs"] == ["two-lamps", "two-lamps+keep-strong"]
    missing = CliRunner().invoke(cli, [*args, "-o", str(tmp_path / "n")])
    assert missing.exit_code == 2 and "needs a verifier" in missing.output
