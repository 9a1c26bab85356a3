"""What users of detection tools expect from the command line: examples in
every verb's help, shell completion of plugin / dataset / preset names, progress indicators,
``--no-plots``, CSV beside JSON, clean COCO and JSON Lines, a warning when a conversion loses
states, flushed partial output of ``detect -o``, and no option a verb cannot use."""

from __future__ import annotations

import json
import math

import cv2
import numpy as np
import pytest
from click.testing import CliRunner

from tsrkit import Detector, hookimpl
from tsrkit.cli.main import cli
from tsrkit.core.types import Candidate, Dataset

VERBS_WITH_EXAMPLES = [
    ["benchmark"],
    ["compare"],
    ["detect"],
    ["train"],
    ["plugins"],
    ["presets"],
    ["datasets"],
    ["datasets", "list"],
    ["datasets", "info"],
    ["datasets", "verify"],
    ["datasets", "convert"],
    ["datasets", "synth"],
]


@pytest.mark.parametrize("verb", VERBS_WITH_EXAMPLES, ids=" ".join)
def test_every_verbs_help_shows_examples(verb):
    result = CliRunner().invoke(cli, [*verb, "--help"])
    assert result.exit_code == 0
    examples = result.output.split("Examples:")[1].split("Options:")[0]
    assert examples.count("tsrkit ") >= 1


def complete(words: str) -> list[str]:
    """What bash completion offers for the command line ``words`` (last word incomplete)."""
    args = words.split(" ")
    env = {
        "_TSRKIT_COMPLETE": "bash_complete",
        "COMP_WORDS": words,
        "COMP_CWORD": str(len(args) - 1),
    }
    result = CliRunner().invoke(cli, [], env=env, prog_name="tsrkit")
    return [line.split(",", 1)[1] for line in result.output.splitlines()]


def test_shell_completion_offers_plugin_dataset_and_preset_names():
    assert "gray-tophat" in complete("tsrkit detect -d gray")
    assert complete("tsrkit detect -c ab-") == ["ab-hist"]
    assert complete("tsrkit compare --detectors conspicuity,lab-f") == ["conspicuity,lab-frst"]
    assert "conspicuity,lab-blob" in complete("tsrkit compare --detectors conspicuity,lab-")
    assert "ab-hist" in complete("tsrkit train ")
    assert "gray-tophat" not in complete("tsrkit train ")
    assert complete("tsrkit benchmark --dataset roboflow_traffic") == ["roboflow_traffic_light_kr"]
    assert "sample" in complete("tsrkit datasets info ")
    assert complete("tsrkit detect --config recomm") == ["recommended", "recommended-forest"]
    assert complete("tsrkit presets --show recommended-f") == ["recommended-forest"]
    assert "yolo" in complete("tsrkit datasets convert x --to ")
    assert "plots" in complete("tsrkit benchmark --writer pl")


def test_options_a_verb_cannot_use_are_not_offered():
    help_text = CliRunner().invoke(cli, ["benchmark", "--help"]).output
    options = help_text.split("Options:")[1]
    assert "--tracker" not in options and "--no-plots" in options
    assert "--tracker" in CliRunner().invoke(cli, ["detect", "--help"]).output


def tiny_dataset(tmp_path):
    boxes = [{"label": "red", "x_min": 12, "y_min": 12, "x_max": 20, "y_max": 20}]
    records = []
    for k in range(2):
        image = np.full((32, 32, 3), 30, np.uint8)
        cv2.circle(image, (16, 16), 3, (40, 40, 230), -1)
        cv2.imwrite(str(tmp_path / f"f{k}.png"), image)
        records.append({"file": f"f{k}.png", "split": "test", "boxes": boxes})
    (tmp_path / "annotations.json").write_text(json.dumps(records))
    return tmp_path / "annotations.json"


def test_no_plots_writes_no_plot_files_and_csv_sits_beside_json(tmp_path):
    dataset = str(tiny_dataset(tmp_path))
    args = ["benchmark", "--dataset", dataset, "-d", "gray-tophat", "-q", "-w", "1", "--no-cache"]
    plain = CliRunner().invoke(cli, [*args, "-o", str(tmp_path / "a"), "--writer", "plots"])
    assert plain.exit_code == 0 and list((tmp_path / "a" / "plots").glob("*.png"))
    bare = CliRunner().invoke(cli, [*args, "-o", str(tmp_path / "b"), "--no-plots"])
    assert bare.exit_code == 0, bare.output
    written = {p.name for p in (tmp_path / "b").iterdir()}
    assert "plots" not in written
    assert {"report.json", "headline.csv", "frames.csv", "detections.jsonl"} <= written
    frames = (tmp_path / "b" / "frames.csv").read_text().splitlines()
    assert frames[0].startswith("frame,source") and len(frames) == 3


def test_coco_files_are_clean_with_file_names_relative_to_the_dataset_root(tmp_path):
    dataset = str(tiny_dataset(tmp_path))
    args = ["benchmark", "--dataset", dataset, "-d", "gray-tophat", "-q", "-w", "1"]
    result = CliRunner().invoke(
        cli, [*args, "--no-cache", "-o", str(tmp_path / "o"), "--writer", "coco"]
    )
    assert result.exit_code == 0, result.output
    truth = json.loads((tmp_path / "o" / "ground_truth.coco.json").read_text())
    assert [i["file_name"] for i in truth["images"]] == ["f0.png", "f1.png"]
    assert set(truth) == {"info", "images", "annotations", "categories"}
    standard = {"id", "image_id", "category_id", "bbox", "area", "iscrowd", "state"}
    assert all(set(a) == standard for a in truth["annotations"])
    results = json.loads((tmp_path / "o" / "detections.coco.json").read_text())
    assert all(set(r) == {"image_id", "category_id", "bbox", "score", "state"} for r in results)


class NanScore(Detector):
    name = "nan-score"

    def detect(self, frame):
        return [Candidate(10.0, 10.0, 2.0, (8.0, 8.0, 12.0, 12.0), float("nan"))]


class NanScorePlugin:
    @hookimpl
    def register_detectors(self, register):
        register(NanScore)


def test_json_lines_hold_no_nan_token(registry, tmp_path):
    registry.add(NanScorePlugin(), "nan-score")
    cv2.imwrite(str(tmp_path / "a.png"), np.zeros((20, 20, 3), np.uint8))
    out = tmp_path / "d.jsonl"
    result = CliRunner().invoke(
        cli, ["detect", str(tmp_path / "a.png"), "-d", "nan-score", "-o", str(out)]
    )
    assert result.exit_code == 0, result.output

    def refuse(token):
        raise AssertionError(f"{token} in JSON Lines")

    record = json.loads(out.read_text(), parse_constant=refuse)
    assert record["detections"][0]["score"] is None
    assert not (tmp_path / "d.jsonl.partial").exists()


class Crashes(Detector):
    name = "stops-the-run"

    def __init__(self, **params):
        super().__init__(**params)
        self.calls = 0

    def detect(self, frame):
        self.calls += 1
        if self.calls == 3:
            raise KeyboardInterrupt  # as Ctrl-C on the third frame
        return []


class CrashesPlugin:
    @hookimpl
    def register_detectors(self, register):
        register(Crashes)


def test_an_aborted_detect_keeps_every_frame_done_so_far(registry, tmp_path):
    registry.add(CrashesPlugin(), "stops-the-run")
    folder = tmp_path / "in"
    folder.mkdir()
    for k in range(4):
        cv2.imwrite(str(folder / f"{k}.png"), np.zeros((20, 20, 3), np.uint8))
    out = tmp_path / "d.jsonl"
    result = CliRunner().invoke(cli, ["detect", str(folder), "-d", "stops-the-run", "-o", str(out)])
    assert result.exit_code != 0 and not out.exists()
    partial = (tmp_path / "d.jsonl.partial").read_text().splitlines()
    assert [json.loads(line)["source"].rsplit("/", 1)[1] for line in partial] == ["0.png", "1.png"]
    assert "frames done so far are in" in result.output


def test_a_conversion_that_loses_states_warns_with_the_counts(tmp_path):
    from tsrkit.cli.datasets import state_changes
    from tsrkit.core.types import Annotation, Sample

    image = tmp_path / "a.png"
    cv2.imwrite(str(image), np.zeros((20, 20, 3), np.uint8))
    # a raw label whose state came from a states: mapping: YOLO keeps the label, not the state
    record = [
        {
            "file": "a.png",
            "width": 20,
            "height": 20,
            "boxes": [
                {"label": "left", "state": "green", "x_min": 1, "y_min": 1, "x_max": 9, "y_max": 9}
            ],
        }
    ]
    (tmp_path / "annotations.json").write_text(json.dumps(record))
    args = ["datasets", "convert", str(tmp_path / "annotations.json"), "-q", "--to"]
    kept = CliRunner().invoke(cli, [*args, "coco", "--out", str(tmp_path / "c.json")])
    assert kept.exit_code == 0 and "warning" not in kept.output
    lost = CliRunner().invoke(cli, [*args, "yolo", "--out", str(tmp_path / "yolo")])
    assert lost.exit_code == 0, lost.output
    assert "warning: yolo cannot hold every state" in lost.output
    assert "green 1 -> 0, unknown 0 -> 1" in lost.output
    same = Dataset("d", (Sample("a", (Annotation((0, 0, 1, 1), "red"),)),))
    assert state_changes(same, same) == []


def test_progress_is_shown_on_stderr_and_quiet_hides_it(tmp_path):
    cv2.imwrite(str(tmp_path / "a.png"), np.zeros((20, 20, 3), np.uint8))
    terminal = CliRunner(env={"FORCE_COLOR": "1"})  # stderr taken for a terminal
    shown = terminal.invoke(cli, ["detect", str(tmp_path), "-d", "gray-tophat"])
    quiet = terminal.invoke(cli, ["detect", str(tmp_path), "-d", "gray-tophat", "-q"])
    logged = CliRunner().invoke(cli, ["detect", str(tmp_path), "-d", "gray-tophat"])
    assert shown.exit_code == quiet.exit_code == logged.exit_code == 0
    assert "frames/s" in shown.stderr
    assert "frames/s" not in quiet.stderr and "frames/s" not in logged.stderr
    assert math.isfinite(json.loads(quiet.stdout)["ms"])
