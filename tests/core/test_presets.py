"""Presets: named run configurations shipped in the package (--config NAME, tsrkit presets)."""

from __future__ import annotations

import json

import pytest
from click.testing import CliRunner

import tsrkit
from tsrkit.cli.main import cli
from tsrkit.core.errors import TsrkitError
from tsrkit.plugin.params import load_config
from tsrkit.plugin.presets import describe, preset_names, preset_path, resolve_config
from tsrkit.plugin.registry import get_registry


def test_every_preset_loads_and_names_installed_plugins():
    assert "recommended" in preset_names()
    for name in preset_names():
        chosen = tsrkit.select(config=name)
        assert chosen.detector is not None
        assert describe(name)


def test_recommended_runs_the_cnn_after_the_forest_and_a_state_classifier():
    chosen = tsrkit.select(config="recommended")
    assert chosen.verifier is not None and chosen.verifier.name == "cnn-verifier"
    assert chosen.verifier.params["after"].plugin.name == "verifier"
    assert tsrkit.select(config="recommended-forest").verifier.name == "verifier"
    assert chosen.classifier is not None
    # the command line overrides the preset, as with any config file
    assert tsrkit.select(detector="gray-tophat", config="recommended").detector.name == (
        "gray-tophat"
    )


def test_preset_names_win_over_files_named_alike_and_unknown_names_are_one_error(
    tmp_path, monkeypatch
):
    """A value is a file when it holds a separator or ends in .yaml/.yml, else a preset: a
    file ``recommended`` in the working folder does not hide the shipped preset."""
    mine = tmp_path / "recommended"
    mine.write_text("detector: gray-tophat\n")
    assert resolve_config(mine) == mine
    monkeypatch.chdir(tmp_path)
    assert load_config("recommended")["detector"]["name"] == "union"
    assert load_config("./recommended")["detector"]["name"] == "gray-tophat"
    assert resolve_config("missing.yaml").name == "missing.yaml"  # a file name stays a file
    with pytest.raises(TsrkitError, match=r"presets: .*recommended"):
        preset_path("nope")
    (tmp_path / "nope").write_text("detector: gray-tophat\n")
    result = CliRunner().invoke(cli, ["benchmark", "--config", "nope", "-q"])
    assert result.exit_code == 2 and "no preset called 'nope'" in result.output
    assert "for the file, write ./nope" in result.output


def test_presets_command_lists_and_shows():
    listed = CliRunner().invoke(cli, ["presets"])
    assert listed.exit_code == 0 and "recommended" in listed.output
    shown = CliRunner().invoke(cli, ["presets", "--show", "recommended"])
    assert shown.exit_code == 0
    assert shown.output == preset_path("recommended").read_text(encoding="utf-8")


def test_the_presets_models_were_trained_for_them():
    """The forest's model records the detector whose candidates it learned (the presets'
    union), and the CNN's card names the preset it was trained for."""
    from tsrkit.plugin.models import load_model
    from tsrkit_plugins.verifiers.cnn.plugin import DEFAULT_MODEL as CNN_MODEL
    from tsrkit_plugins.verifiers.learned import DEFAULT_MODEL

    preset = load_config("recommended")
    assert preset["detector"] == load_config("recommended-forest")["detector"]
    training = load_model(DEFAULT_MODEL, "verifier").meta["training"]["detector"]
    assert training["name"] == preset["detector"]["name"]
    # the model records the detector's validated parameters (members: their specs)
    name, params = preset["detector"]["name"], preset["detector"]["params"]
    detector = get_registry().create("detector", name, params)
    for key in params:
        assert json.loads(json.dumps(detector.params[key], default=str)) == training["params"][key]
    card = load_model(CNN_MODEL, "cnn-verifier")
    assert card.info["preset"] == "recommended"
    assert set(card.meta["training"]["licences"].values()) <= {
        "CC BY 4.0",
        "CC BY-SA 4.0",
        "MIT (tsrkit)",
    }


def test_detect_runs_the_recommended_preset_on_a_video(tmp_path):
    import json

    video = tmp_path / "drive.mp4"
    synth = ["datasets", "synth", "--out", str(tmp_path / "s"), "--frames", "2"]
    made = CliRunner().invoke(cli, [*synth, "--video", str(video)])
    assert made.exit_code == 0, made.output
    out = tmp_path / "drive.jsonl"
    result = CliRunner().invoke(
        cli, ["detect", str(video), "--config", "recommended", "--out", str(out)]
    )
    assert result.exit_code == 0, result.output
    records = [json.loads(line) for line in out.read_text().splitlines()]
    assert [r["frame"] for r in records] == [0, 1]
    threshold = load_config("recommended")["verifier"]["params"]["threshold"]
    for record in records:
        for d in record["detections"]:
            # kept at the network's threshold (its probability blended with the forest's
            # score, itself ordered by the box model)
            assert threshold <= d["score"] <= 1.0
            assert d["state"] in ("red", "yellow", "green", "unknown")
