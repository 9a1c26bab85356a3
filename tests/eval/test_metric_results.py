"""Metrics render themselves: a metric written as one file reaches ``report.json``,
``summary.md``, ``report.html``, ``headline.csv`` and ``plots/`` with no writer edited; a metric
or writer that fails is reported and left out while the rest of the report is written; a result
that breaks the contract is refused with the reason."""

from __future__ import annotations

import csv
import dataclasses
import json
from dataclasses import dataclass
from pathlib import Path

import detection_count_metric
import pytest
from click.testing import CliRunner

import tsrkit
from tsrkit.api import Metric, MetricResult, Plot, ReportWriter, Table, hookimpl
from tsrkit.cli.main import cli
from tsrkit.eval.guard import GuardedMetrics
from tsrkit.eval.settings import EvalSettings
from tsrkit.reporting.report import REPORT_KEYS, headline, run_results

PNG = b"\x89PNG\r\n\x1a\n"
REFERENCE = Path(__file__).resolve().parents[1] / "data" / "reference_reports"


def small_sample(frames: int = 8):
    data = tsrkit.dataset("sample")
    return dataclasses.replace(data, samples=data.samples[:frames])


def test_a_metric_in_one_file_reaches_every_report_file(registry, tmp_path):
    registry.add(detection_count_metric, "detection-count")
    report = tsrkit.benchmark(
        small_sample(), tsrkit.detector("gray-tophat"), out=tmp_path, cache=False
    )
    lines = (tmp_path / "detections.jsonl").read_text().splitlines()
    counts = [len(json.loads(line)["detections"]) for line in lines]
    mean = sum(counts) / len(counts)
    assert report["detection_count"]["mean"] == mean and len(counts) == 8
    assert report["metrics"]["detection-count"] == ["detection_count"]
    summary = (tmp_path / "summary.md").read_text()
    assert f"| det/frame | {mean:.2f} |" in summary
    assert "## Frames by number of detections" in summary
    assert f"{counts.count(0)} frames had no detection at all." in summary
    page = (tmp_path / "report.html").read_text()
    assert 'id="detection-count"' in page and "<td>det/frame</td>" in page
    assert "How many frames reported each number of detections." in page
    with (tmp_path / "headline.csv").open() as fh:
        (row,) = list(csv.DictReader(fh))
    assert float(row["detection_count.mean"]) == mean
    assert float(row["per_frame.recall_mean"]) == report["per_frame"]["recall_mean"]
    assert "plots/detection_count.png" in report["plots"]
    assert (tmp_path / "plots" / "detection_count.png").read_bytes().startswith(PNG)
    # The report verb rebuilds the same results from the run's files alone.
    (tmp_path / "report.html").unlink()
    result = CliRunner().invoke(cli, ["report", str(tmp_path)])
    assert result.exit_code == 0, result.output
    assert (tmp_path / "report.html").read_text() == page


class Boom(Metric):
    """Raises on the third frame."""

    name = "boom"

    def reset(self, settings):
        self.frames = 0

    def update(self, sample, record):
        self.frames += 1
        if self.frames == 3:
            raise ZeroDivisionError("the third frame")

    def compute(self):
        return {"boom": {"frames": self.frames}}


class Broken(ReportWriter):
    name = "broken"

    def files(self, run):
        return ["broken.txt"]

    def write(self, run, folder):
        raise RuntimeError("disk on fire")


class Failing:
    @hookimpl
    def register_metrics(register):
        register(Boom)

    @hookimpl
    def register_report_writers(register):
        register(Broken)


def test_a_failing_metric_and_writer_are_reported_and_the_rest_written(registry, tmp_path):
    registry.add(Failing, "failing")
    args = ["benchmark", "--dataset", "sample", "-d", "gray-tophat", "-w", "1", "-q"]
    result = CliRunner().invoke(cli, [*args, "--no-cache", "-o", str(tmp_path)])
    assert result.exit_code == 0, result.output
    assert "Traceback" not in result.output
    assert "note: metric 'boom' failed and was left out" in result.output
    report = json.loads((tmp_path / "report.json").read_text())
    assert report["failures"] == [
        {"plugin": "metric 'boom'", "error": "ZeroDivisionError: the third frame"},
        {"plugin": "writer 'broken'", "error": "RuntimeError: disk on fire"},
    ]
    assert "boom" not in report and "boom" not in report["metrics"]
    assert "broken.txt" not in report["files"] and not (tmp_path / "broken.txt").exists()
    assert report["per_frame"]["recall_mean"] > 0 and report["iou50"]["ap"] is not None
    for name in ("summary.md", "report.html"):
        text = (tmp_path / name).read_text()
        assert "metric &#x27;boom&#x27; failed" in text or "metric 'boom' failed" in text
        assert "disk on fire" in text


@dataclass(frozen=True)
class Shown(MetricResult):
    def tables(self):
        return [Table("t", "T", ("a", "b"), (("1",),))]  # a row one cell short


def metric(name, result, result_type=MetricResult):
    """A metric class called ``name`` whose ``compute`` returns ``result``."""
    return type(
        name,
        (Metric,),
        {
            "name": name,
            "result_type": result_type,
            "reset": lambda self, settings: None,
            "update": lambda self, sample, record: None,
            "compute": lambda self: result,
        },
    )


@pytest.mark.parametrize(
    ("second", "why"),
    [
        (metric("b", {"per_frame": {"recall_mean": 0.5}}), "report key 'per_frame.recall_mean'"),
        (metric("b", {"timing": {}}), "report section 'timing' is the report's own"),
        (metric("b", Shown({"x": 1})), "returned Shown, not its result_type MetricResult"),
        (metric("b", {"x": object()}), "sections are not JSON"),
        (metric("b", Shown({"x": 1}), Shown), "table 't' has rows of the wrong width"),
        (
            metric("b", MetricResult({"x": 1}), type("P", (MetricResult,), {})),
            "not its result_type P",
        ),
    ],
)
def test_a_result_that_breaks_the_contract_is_refused_with_the_reason(second, why):
    first = metric("a", {"per_frame": {"recall_mean": 0.25}})
    guarded = GuardedMetrics({"a": first, "b": second}, EvalSettings())
    sections, results, written = guarded.compute(REPORT_KEYS)
    assert sections == {"per_frame": {"recall_mean": 0.25}} and written == {"a": ["per_frame"]}
    ((failure),) = guarded.failures
    assert failure.plugin == "metric 'b'" and why in failure.error
    assert [r.metric for r in results] == ["a"]


def test_a_plot_named_like_a_path_is_refused():
    @dataclass(frozen=True)
    class Escaping(MetricResult):
        def plots(self):
            return [Plot("../outside.png", "", lambda figure: None)]

    guarded = GuardedMetrics({"e": metric("e", Escaping({}), Escaping)}, EvalSettings())
    guarded.compute()
    assert "not a plain file name" in guarded.failures[0].error


def test_a_shared_section_lists_each_metrics_keys():
    one = metric("one", {"iou50": {"precision": 0.5}, "own": [1]})
    two = metric("two", {"iou50": {"ap": 0.25}})
    sections, _, written = GuardedMetrics({"one": one, "two": two}, EvalSettings()).compute()
    assert sections == {"iou50": {"precision": 0.5, "ap": 0.25}, "own": [1]}
    assert written == {"one": ["iou50.precision", "own"], "two": ["iou50.ap"]}


def test_a_report_written_before_results_rendered_themselves_still_renders():
    from tsrkit.core.results import fmt

    stored = json.loads(
        (REFERENCE / "sample_conspicuity_ab-hist.report.json").read_text(encoding="utf-8")
    )
    assert "metrics" not in stored
    figures = headline(stored)
    assert figures["recall"] == fmt(stored["per_frame"]["recall_mean"])
    assert figures["AP50"] == fmt(stored["iou50"]["ap"])
    assert figures["state"] == fmt(stored["state"]["accuracy"])
    titles = [t.title for r in run_results(stored) for t in r.tables()]
    assert "Overlap matching (Lee 2017, 3.6.2)" in titles
    assert "States of matched detections: confusion" in titles


class NotFinite(Metric):
    """A third-party metric whose figures are not finite (a ratio of zero frames, a bound)."""

    name = "not-finite"

    def reset(self, settings):
        self.frames = 0

    def update(self, sample, record):
        self.frames += 1

    def compute(self):
        return {"odd": {"ratio": float("nan"), "bound": float("inf"), "frames": self.frames}}


class NotFinitePlugin:
    @hookimpl
    def register_metrics(register):
        register(NotFinite)


def test_non_finite_metric_values_are_written_as_null(registry, tmp_path):
    registry.add(NotFinitePlugin, "not-finite")
    args = ["benchmark", "--dataset", "sample", "-d", "gray-tophat", "-w", "1", "-q"]
    result = CliRunner().invoke(cli, [*args, "--no-cache", "-o", str(tmp_path)])
    assert result.exit_code == 0, result.output

    def refuse(token):
        raise AssertionError(f"{token} written into JSON")

    report = json.loads((tmp_path / "report.json").read_text(), parse_constant=refuse)
    lines = (tmp_path / "detections.jsonl").read_text().splitlines()
    assert report["odd"] == {"ratio": None, "bound": None, "frames": len(lines)}
    for line in lines:
        json.loads(line, parse_constant=refuse)
    again = CliRunner().invoke(cli, ["report", str(tmp_path), "--writer", "markdown"])
    assert again.exit_code == 0, again.output
