"""``tsrkit benchmark`` / ``compare`` on the command line, with in-process fake plugins."""

import json

import benchmark_fakes
import pytest
from benchmark_fakes import hand_dataset
from click.testing import CliRunner

from tsrkit.cli.main import cli


@pytest.fixture
def fakes(registry, monkeypatch):
    """The fake plugins registered, and ``open_dataset`` serving the hand-built frames."""
    registry.add(benchmark_fakes, "benchmark-fakes")
    monkeypatch.setattr(
        "tsrkit.datasets.open_dataset",
        lambda ref, format=None, images=None: hand_dataset(6, name=ref),
    )
    return registry


def test_benchmark_prints_table_and_writes_report(fakes, tmp_path):
    result = CliRunner().invoke(
        cli,
        [
            "benchmark",
            "--dataset",
            "hand",
            "--detector",
            "oracle",
            "--classifier",
            "always-red",
            "--out",
            str(tmp_path),
            "--workers",
            "1",
            "--quiet",
        ],
    )
    assert result.exit_code == 0, result.output
    assert "always-red" in result.stdout and "0.750" in result.stdout
    report = json.loads((tmp_path / "report.json").read_text())
    assert report["dataset"]["name"] == "hand" and report["classifier"]["name"] == "always-red"
    assert report["per_frame"]["recall_mean"] == pytest.approx(0.75)


def test_benchmark_param_reaches_the_plugin(fakes, tmp_path):
    result = CliRunner().invoke(
        cli,
        [
            "benchmark",
            "-d",
            "oracle",
            "-p",
            "crash_on=frame001",
            "-o",
            str(tmp_path),
            "-w",
            "1",
            "-q",
        ],
    )
    assert result.exit_code == 0, result.output
    report = json.loads((tmp_path / "report.json").read_text())
    assert [s["source"] for s in report["skipped"]] == ["frame001"]
    assert report["params"]["detector"]["crash_on"] == "frame001"


def test_compare_runs_each_detector(fakes, tmp_path):
    result = CliRunner().invoke(
        cli, ["compare", "--detectors", "oracle,shifted", "-o", str(tmp_path), "-w", "1", "-q"]
    )
    assert result.exit_code == 0, result.output
    assert "oracle vs shifted" in result.stdout
    comparison = json.loads((tmp_path / "compare.json").read_text())
    assert comparison["detectors"] == ["oracle", "shifted"]
    assert (tmp_path / "shifted" / "summary.md").is_file()


def test_unknown_detector_is_one_line_error(fakes, tmp_path):
    result = CliRunner().invoke(cli, ["benchmark", "-d", "nope", "-o", str(tmp_path)])
    assert result.exit_code == 2
    assert "no detector called 'nope'" in result.output
    assert "Traceback" not in result.output


def test_bare_tsrkit_compares_the_defaults_into_tsrkit_out(fakes, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    monkeypatch.setattr("tsrkit.cli.benchmark.DEFAULT_COMPARE", ("oracle", "shifted"))
    result = CliRunner().invoke(cli, [])
    assert result.exit_code == 0, result.output
    comparison = json.loads((tmp_path / "tsrkit-out" / "compare.json").read_text())
    assert comparison["dataset"] == "sample"
    assert [t["verdict"] for t in comparison["paired_tests"]] == ["oracle better"]


@pytest.mark.parametrize("workers", ["1", "2"])
def test_setup_error_from_a_plugin_stops_the_run(fakes, tmp_path, workers):
    """A TsrkitError from a plugin (e.g. no model) ends the run with one line, in workers too."""
    result = CliRunner().invoke(
        cli,
        ["benchmark", "-d", "untrained", "--workers", workers, "--quiet", "--out", str(tmp_path)],
    )
    assert result.exit_code == 2
    assert result.stderr.strip() == "Error: untrained needs a model: pass --param model=M"
    assert not (tmp_path / "report.json").exists()


def test_a_rerun_with_fewer_files_leaves_none_of_the_old_report(fakes, tmp_path):
    args = ["benchmark", "--dataset", "hand", "--detector", "oracle", "--classifier", "always-red",
            "--out", str(tmp_path), "--workers", "1", "--quiet"]  # fmt: skip
    assert CliRunner().invoke(cli, args).exit_code == 0
    first = json.loads((tmp_path / "report.json").read_text())
    assert first["plots"] and all((tmp_path / name).is_file() for name in first["plots"])
    (tmp_path / "notes.txt").write_text("the user's own file")
    (tmp_path / "report.json").write_text(
        json.dumps({**first, "files": [*first["files"], "../outside.txt", "notes.txt"]})
    )
    (tmp_path.parent / "outside.txt").write_text("not the run's")
    result = CliRunner().invoke(cli, [*args, "--writer", "json", "--writer", "csv"])
    assert result.exit_code == 0, result.output
    second = json.loads((tmp_path / "report.json").read_text())
    left = {p.relative_to(tmp_path).as_posix() for p in tmp_path.rglob("*") if p.is_file()}
    assert not second["plots"] and not any(name in left for name in first["plots"])
    assert set(second["files"]) <= left and "summary.md" not in left
    assert (tmp_path.parent / "outside.txt").exists()  # never outside the run's folder
    assert "notes.txt" not in left  # listed by the old report, so it was the run's
