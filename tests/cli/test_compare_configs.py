"""``compare --configs``: whole pipelines (presets or run files) side by side, paired tests."""

from __future__ import annotations

import json

from click.testing import CliRunner

from tsrkit.cli.main import cli


def test_two_presets_run_side_by_side_with_a_paired_test(tmp_path):
    frames = tmp_path / "frames"
    made = CliRunner().invoke(
        cli, ["datasets", "synth", "--out", str(frames), "--frames", "3", "-q"]
    )
    assert made.exit_code == 0, made.output
    out = tmp_path / "cmp"
    result = CliRunner().invoke(
        cli,
        [
            "compare",
            "--dataset",
            str(frames / "annotations.json"),
            "--configs",
            "recommended,recommended-forest",
            "-w",
            "1",
            "-q",
            "--no-plots",
            "-o",
            str(out),
        ],
    )
    assert result.exit_code == 0, result.output
    comparison = json.loads((out / "compare.json").read_text())
    assert comparison["runs"] == ["recommended", "recommended-forest"]
    verifiers = [r["verifier"]["name"] for r in comparison["reports"]]
    assert verifiers == ["cnn-verifier", "verifier"]
    assert "recommended vs recommended-forest, per-frame recall" in result.output
    assert (out / "recommended" / "report.json").is_file()


def test_configs_exclude_the_single_pipeline_options():
    result = CliRunner().invoke(
        cli, ["compare", "--configs", "recommended,recommended-forest", "-V", "verifier"]
    )
    assert result.exit_code == 2
    assert "--configs names whole pipelines; --verifier goes with it" in result.output
    alone = CliRunner().invoke(cli, ["compare", "--configs", "recommended"])
    assert alone.exit_code == 2 and "at least two" in alone.output
