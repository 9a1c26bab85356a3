"""Reports reproduce to the last digit: stored reports of the sample, re-run and compared.

``tests/data/reference_reports/`` holds ``report.json`` files written by tsrkit before the
issue-14 refactor (commands in its README), without the machine-dependent fields (timing,
versions, the dataset root, source hashes, file lists). Every stored key must come back equal.
"""
from __future__ import annotations

import json
from pathlib import Path

import pytest

import tsrkit

REFERENCE = Path(__file__).resolve().parent / "data" / "reference_reports"


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
    report = tsrkit.benchmark(tsrkit.dataset("sample"), tsrkit.detector("gray-tophat"),
                              out=tmp_path, cache=False)
    assert_reproduces(comparable(report), reference("sample_gray-tophat"))
