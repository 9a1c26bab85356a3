"""``tsrkit report RUN_DIR``: runs of registered datasets and of datasets given by path, compare
folders, and one clear line (exit 2, no traceback) for a run folder whose files are broken."""

from __future__ import annotations

import dataclasses
import json
import shutil
from pathlib import Path

import pytest
from click.testing import CliRunner

import tsrkit
from tsrkit.cli.main import cli
from tsrkit.synth import sample_path

REFERENCE = Path(__file__).resolve().parents[1] / "data" / "reference_reports"


def report_verb(folder: Path):
    return CliRunner().invoke(cli, ["report", str(folder)])


@pytest.fixture(scope="module")
def path_run(tmp_path_factory):
    """A run on the bundled sample's COCO file given by path (its first 12 frames)."""
    data = tsrkit.dataset(str(sample_path().parent / "coco.json"))
    data = dataclasses.replace(data, samples=data.samples[:12])
    out = tmp_path_factory.mktemp("path-run")
    tsrkit.benchmark(data, tsrkit.detector("gray-tophat"), out=out, cache=False)
    return out


def test_a_run_of_a_dataset_given_by_path_is_rendered_again_with_its_frames(path_run, tmp_path):
    run = tmp_path / "run"
    shutil.copytree(path_run, run)
    report = json.loads((run / "report.json").read_text())
    assert report["dataset"]["opened_as"]["ref"] == str(sample_path().parent / "coco.json")
    before = (run / "report.html").read_text()
    (run / "report.html").unlink()
    result = report_verb(run)
    assert result.exit_code == 0, result.output
    page = (run / "report.html").read_text()
    assert page == before and 'class="gallery"' in page and 'class="crop"' in page


@pytest.mark.parametrize(
    ("damage", "message"),
    [
        (lambda d: (d / "report.json").write_text(""), "report.json: empty file"),
        (
            lambda d: (d / "report.json").write_text("{oops"),
            "report.json: line 1 column 2: not valid JSON",
        ),
        (lambda d: (d / "report.json").write_text("[1, 2]"), "report.json: not a tsrkit report"),
        (
            lambda d: (d / "detections.jsonl").write_text('{"source": "a.png"}\n{oops\n'),
            "detections.jsonl: line 1: not a frame record (missing 'width')",
        ),
        (
            lambda d: (d / "detections.jsonl").write_text("\n[]\n"),
            "detections.jsonl: line 2: not a frame record",
        ),
        (lambda d: (d / "detections.jsonl").unlink(), "not a run folder (detections.jsonl"),
        (lambda d: (d / "compare.json").write_text(""), "compare.json: empty file"),
        (lambda d: (d / "compare.json").write_text('{"dataset": "x"}'), "no 'reports' list"),
    ],
)
def test_a_broken_run_folder_gives_one_clear_line(path_run, tmp_path, damage, message):
    run = tmp_path / "run"
    shutil.copytree(path_run, run)
    damage(run)
    result = report_verb(run)
    assert result.exit_code == 2, result.output
    assert message in result.output and "Traceback" not in result.output
    assert len(result.output.strip().splitlines()) == 1


def test_a_compare_folder_gets_readable_p_values(tmp_path):
    stored = json.loads((REFERENCE / "compare_sample.compare.json").read_text())
    stored["paired_tests"][0]["p_value"] = 7.430843875383497e-14
    (tmp_path / "compare.json").write_text(json.dumps(stored))
    result = report_verb(tmp_path)
    assert result.exit_code == 0, result.output
    page = (tmp_path / "compare.html").read_text()
    assert ">7.4e-14</td>" in page and "7.430843875383497e-14" not in page
    assert "<th>recall</th>" in page and "<th>AP50</th>" in page  # a report of an older run
