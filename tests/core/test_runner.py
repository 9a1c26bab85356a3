"""The benchmark runner: parallel engines agree, failures are skipped, a killed run resumes."""

import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import cv2
import numpy as np
import pytest
from benchmark_fakes import OracleDetector, RedClassifier, ShiftedDetector, hand_dataset, make

from tsrkit.core.types import Annotation, Dataset, Sample
from tsrkit.reporting.benchmarking import benchmark
from tsrkit.reporting.comparison import compare
from tsrkit.runner.engine import BenchmarkError

TESTS = Path(__file__).resolve().parents[1]


def without_timing(report):
    return {k: v for k, v in report.items() if k != "timing"}


def test_hand_built_report_numbers(tmp_path):
    report = benchmark(hand_dataset(6), make(OracleDetector), make(RedClassifier), out=tmp_path)
    # Odd frames: recall 1/2, precision 1/2; even frames: 1 and 1 (see hand_dataset).
    assert report["per_frame"]["recall_mean"] == pytest.approx(0.75)
    assert report["per_frame"]["precision_mean"] == pytest.approx(0.75)
    assert report["per_frame"]["hit_frame_fraction"] == 1.0
    assert report["iou50"]["precision"] == pytest.approx(9 / 12)
    # Matched pairs: 6 red boxes (right) and 3 green boxes (called red).
    assert report["state"]["accuracy"] == pytest.approx(6 / 9)
    assert report["frames"] == 6 and report["skipped"] == []
    for name in (
        "report.json",
        "summary.md",
        "detections.jsonl",
        "detections.coco.json",
        "ground_truth.coco.json",
        "plots/recall_fpr_bubbles.png",
        "plots/categories.png",
        "plots/pr_curve.png",
        "plots/confusion.png",
    ):
        assert (tmp_path / name).is_file(), name
    lines = (tmp_path / "detections.jsonl").read_text().splitlines()
    assert len(lines) == 6 and json.loads(lines[1])["detections"][1]["x"] == 35
    summary = (tmp_path / "summary.md").read_text()
    assert "| lighting - max radius |" in summary
    assert "| green | 3 | 0 | 0 | 0 | 0 |" in summary  # 3 green boxes called red
    assert json.loads((tmp_path / "report.json").read_text())["frames"] == 6


def test_process_pool_matches_serial_run(tmp_path):
    data = hand_dataset(10)
    serial = benchmark(data, make(OracleDetector), cache=False)
    pooled = benchmark(data, make(OracleDetector), workers=2, cache=False)
    assert without_timing(serial) == without_timing(pooled)


def test_dask_local_cluster_matches_serial_run():
    from distributed import LocalCluster

    data = hand_dataset(6)
    serial = benchmark(data, make(OracleDetector), cache=False)
    with LocalCluster(
        n_workers=1, threads_per_worker=2, processes=False, dashboard_address=None
    ) as cluster:
        distributed = benchmark(
            data, make(OracleDetector), engine="dask", scheduler=cluster, cache=False
        )
    assert without_timing(serial) == without_timing(distributed)
    assert distributed["timing"]["engine"] == "dask"


def test_unreadable_image_and_crashing_plugin_are_skipped(tmp_path):
    good = tmp_path / "good.png"
    cv2.imwrite(str(good), np.zeros((20, 20, 3), np.uint8))
    broken = tmp_path / "broken.png"
    broken.write_bytes(b"not an image")
    box = (Annotation((2, 2, 8, 8), "red"),)
    samples = (
        Sample(str(good), box, metadata={"dets": [(5, 5, 1.0)]}),
        Sample(str(broken), box, metadata={"dets": []}),
        Sample(str(tmp_path / "missing.png"), box, metadata={"dets": []}),
        Sample("crash", box, metadata={"dets": []}, image=np.zeros((9, 9, 3), np.uint8)),
    )
    report = benchmark(
        Dataset("mixed", samples), make(OracleDetector, crash_on="crash"), cache=False
    )
    reasons = {Path(s["source"]).name: s["reason"] for s in report["skipped"]}
    assert set(reasons) == {"broken.png", "missing.png", "crash"}
    assert "plugin error: RuntimeError: deliberate crash" in reasons["crash"]
    assert "no such file" in reasons["missing.png"]
    assert report["frames"] == 1 and report["per_frame"]["recall_mean"] == 1.0


def test_classifier_alone_on_crops():
    crops = tuple(
        Sample(
            f"crop{i}",
            (Annotation((0, 0, 10, 10), state),),
            10,
            10,
            image=np.full((10, 10, 3), 9 * i, np.uint8),
        )
        for i, state in enumerate(["red", "red", "yellow", "green"])
    )
    report = benchmark(Dataset("crops", crops), None, make(RedClassifier), cache=False)
    assert report["state"]["accuracy"] == 0.5
    assert report["state"]["red_yellow_errors"]["yellow_as_red"] == 1
    assert report["detector"] is None and report["classifier"]["name"] == "always-red"
    assert report["per_frame"]["note"].startswith("classifier alone")


def test_cache_is_keyed_by_plugin_parameters(tmp_path):
    data = hand_dataset(4)
    first = benchmark(data, make(OracleDetector), cache_dir=tmp_path)
    again = benchmark(data, make(OracleDetector), cache_dir=tmp_path)
    other = benchmark(data, make(OracleDetector, delay=0.001), cache_dir=tmp_path)
    assert first["timing"]["frames_computed"] == 4
    assert again["timing"]["frames_cached"] == 4 and again["timing"]["frames_computed"] == 0
    assert other["timing"]["frames_computed"] == 4


def test_an_unreadable_cache_entry_is_computed_again(tmp_path):
    data = hand_dataset(3)
    first = benchmark(data, make(OracleDetector), cache_dir=tmp_path)
    entries = sorted(tmp_path.glob("*/*.json"))
    entries[0].write_text('{"source": "cut sho')
    entries[1].write_text("[]")
    again = benchmark(data, make(OracleDetector), cache_dir=tmp_path)
    assert again["timing"]["frames_computed"] == 2 and again["timing"]["frames_cached"] == 1
    assert without_timing(again) == without_timing(first)
    assert json.loads(entries[0].read_text())["frame"] in range(3)


@pytest.mark.parametrize(
    "damage",
    [
        lambda entry: entry.write_bytes(b""),  # a crash right after the file was made
        lambda entry: entry.write_bytes(b"\0" * 64),  # a crash before unsynced data reached disk
        lambda entry: entry.write_text(entry.read_text().replace('"width": 40', '"width": "40"')),
        lambda entry: entry.write_text(entry.read_text().replace('"x": 13.0', '"x": true', 1)),
        lambda entry: entry.write_text(
            entry.read_text().replace('"detections": [', '"detections": [7, ')
        ),
    ],
    ids=["empty", "zeros", "text width", "bool x", "number as detection"],
)
def test_a_damaged_cache_entry_is_refused_whole_and_computed_again(tmp_path, damage):
    """Entries are written without fsync, so a crash can leave one empty or zero-filled; a
    hand edit can leave valid JSON of the wrong types. Either is computed again and rewritten,
    never handed to the metrics."""
    data = hand_dataset(2)
    first = benchmark(data, make(OracleDetector), cache_dir=tmp_path)
    damaged = sorted(tmp_path.glob("*/*.json"))[0]
    before = json.loads(damaged.read_text())
    damage(damaged)
    again = benchmark(data, make(OracleDetector), cache_dir=tmp_path)
    assert again["timing"]["frames_computed"] == 1 and again["timing"]["frames_cached"] == 1
    assert without_timing(again) == without_timing(first)
    rewritten = json.loads(damaged.read_text())
    assert {**rewritten, "ms": 0} == {**before, "ms": 0}


def test_compare_writes_side_by_side_report_and_paired_test(tmp_path):
    result = compare(
        hand_dataset(12), [make(OracleDetector), make(ShiftedDetector)], out=tmp_path, cache=False
    )
    assert [r["detector"]["name"] for r in result["reports"]] == ["oracle", "shifted"]
    test = result["paired_tests"][0]
    assert test["frames"] == 12 and test["verdict"] == "oracle better"
    assert (tmp_path / "oracle" / "report.json").is_file()
    assert "oracle better" in (tmp_path / "compare.md").read_text()


def test_bad_options_are_one_line_errors():
    with pytest.raises(BenchmarkError, match="unknown engine"):
        benchmark(hand_dataset(1), make(OracleDetector), engine="spark")
    with pytest.raises(BenchmarkError, match="needs a detector"):
        benchmark(hand_dataset(1), None)


SCRIPT = """
import sys
sys.path.insert(0, {tests!r})
from benchmark_fakes import OracleDetector, hand_dataset, make
from tsrkit.reporting.benchmarking import benchmark
benchmark(hand_dataset(30), make(OracleDetector, delay=0.04), out=sys.argv[1])
"""


def test_killed_benchmark_resumes_and_recomputes_only_missing_frames(tmp_path):
    script = tmp_path / "run.py"
    script.write_text(SCRIPT.format(tests=str(TESTS)))
    out = tmp_path / "out"
    cache = out / "cache"
    env = {**os.environ, "TSRKIT_LOAD_PLUGINS": ""}  # the fake needs no installed plugin
    proc = subprocess.Popen([sys.executable, str(script), str(out)], env=env)
    deadline = time.monotonic() + 60
    while len(list(cache.glob("*/*.json"))) < 10 and time.monotonic() < deadline:
        time.sleep(0.02)
    os.kill(proc.pid, signal.SIGKILL)
    proc.wait()
    done = len(list(cache.glob("*/*.json")))
    assert 10 <= done < 30 and not (out / "report.json").exists()

    subprocess.run([sys.executable, str(script), str(out)], check=True, env=env)
    resumed = json.loads((out / "report.json").read_text())
    assert resumed["timing"]["frames_cached"] == done
    assert resumed["timing"]["frames_computed"] == 30 - done

    fresh = benchmark(hand_dataset(30), make(OracleDetector, delay=0.04), out=tmp_path / "fresh")
    assert fresh["timing"]["frames_computed"] == 30
    assert without_timing(resumed) == without_timing(fresh)
