"""Reports reproduce to the last digit: stored reports of the sample, re-run and compared.

``tests/data/reference_reports/`` holds ``report.json`` files written by tsrkit before the
plugin entry points were introduced (commands in its README), without the machine-dependent fields
(timing, versions, the dataset root, source hashes, file lists). Every stored key must come back
equal.
"""

from __future__ import annotations

import gzip
import json
from pathlib import Path

import pytest

import tsrkit
from tsrkit.core.records import FrameRecord
from tsrkit.reporting.benchmarking import eval_settings, evaluate
from tsrkit.reporting.comparison import paired_tests

REFERENCE = Path(__file__).resolve().parents[1] / "data" / "reference_reports"


def comparable(report: dict) -> dict:
    """A report without the fields that depend on the machine, the checkout or the outputs."""
    out = {k: v for k, v in report.items() if k not in ("timing", "versions", "plots", "files")}
    out["dataset"] = {k: v for k, v in report["dataset"].items() if k != "root"}
    for kind in ("detector", "classifier", "verifier"):
        if out.get(kind):
            out[kind] = {k: v for k, v in out[kind].items() if k != "source_sha256"}
    return json.loads(json.dumps(out))


def assert_reproduces(report: dict, reference: dict, where: str = "") -> None:
    """Every key of ``reference`` (recursively) is in ``report`` with an identical value."""
    if isinstance(reference, dict):
        assert isinstance(report, dict), where
        for key, value in reference.items():
            assert key in report, f"{where}/{key} missing"
            assert_reproduces(report[key], value, f"{where}/{key}")
    else:
        assert report == reference, f"{where}: {report!r} != {reference!r}"


def reference(name: str) -> dict:
    return json.loads((REFERENCE / f"{name}.report.json").read_text())


def test_gray_tophat_on_the_sample_reproduces(tmp_path):
    report = tsrkit.benchmark(
        tsrkit.dataset("sample"), tsrkit.detector("gray-tophat"), out=tmp_path, cache=False
    )
    assert_reproduces(comparable(report), reference("sample_gray-tophat"))


def stored_records(name: str) -> list[FrameRecord]:
    with gzip.open(REFERENCE / f"{name}.detections.jsonl.gz", "rt", encoding="utf-8") as fh:
        return [FrameRecord.from_json(json.loads(line)) for line in fh]


def replay(name: str, dataset, plugins: dict):
    """The run of the stored records, evaluated by today's metrics and report builder."""
    settings = eval_settings(dataset, detection=plugins["detector"] is not None)
    return evaluate(dataset, stored_records(name), settings, plugins)


@pytest.mark.parametrize(
    "name, dataset, split",
    [
        ("sample_conspicuity_ab-hist", "sample", None),
        ("sample_gray-tophat", "sample", None),
        ("sample_lab-frst", "sample", None),
        ("udacity_mit_tl_crops_test_ab-hist", "udacity_mit_tl_crops", "test"),
    ],
)
def test_stored_records_evaluate_to_the_stored_report(name, dataset, split, shared_datasets):
    data = tsrkit.dataset(dataset)
    data = data.split(split) if split else data
    expected = reference(name)
    run = replay(name, data, {k: expected[k] for k in ("detector", "classifier")})
    assert_reproduces(comparable(run.report), expected)


def test_compare_replay_reproduces_reports_and_paired_tests():
    stored = json.loads((REFERENCE / "compare_sample.compare.json").read_text())
    data = tsrkit.dataset("sample")
    runs = [
        replay(
            f"compare_sample_{name}",
            data,
            {"detector": report["detector"], "classifier": report["classifier"]},
        )
        for name, report in zip(stored["detectors"], stored["reports"])
    ]
    for run, report in zip(runs, stored["reports"]):
        assert_reproduces(comparable(run.report), report)
    assert paired_tests(stored["detectors"], runs) == stored["paired_tests"]
