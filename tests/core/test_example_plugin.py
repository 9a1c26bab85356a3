"""A third-party plugin, installed by pip like a stranger's package, is found and runs."""

import json
import os
import subprocess
import sys
from pathlib import Path

import cv2
import numpy as np
import pytest

EXAMPLE = Path(__file__).resolve().parents[2] / "examples" / "tsrkit-brightest-blobs"


@pytest.fixture(scope="module")
def installed(tmp_path_factory):
    """pip-install the example into its own folder; return an environment that sees it."""
    target = tmp_path_factory.mktemp("site")
    subprocess.run(
        [
            sys.executable,
            "-m",
            "pip",
            "install",
            "--quiet",
            "--no-deps",
            "--no-build-isolation",
            "--no-index",
            "--target",
            str(target),
            str(EXAMPLE),
        ],
        check=True,
        capture_output=True,
    )
    env = dict(os.environ, PYTHONPATH=str(target))
    env.pop("TSRKIT_LOAD_PLUGINS", None)
    return env


def tsrkit(env, *args):
    return subprocess.run(
        [sys.executable, "-m", "tsrkit", *args], env=env, capture_output=True, text=True
    )


def test_installed_plugin_is_listed(installed):
    done = tsrkit(installed, "plugins", "--json")
    assert done.returncode == 0, done.stderr
    found = {p["name"]: p for p in json.loads(done.stdout)}
    for name, kind in (
        ("brightest-blobs", "detector"),
        ("centre-error", "metric"),
        ("missed-boxes", "writer"),
    ):
        assert found[name] == {
            **found[name],
            "kind": kind,
            "package": "tsrkit-brightest-blobs",
            "version": "0.1.0",
        }


def test_installed_plugin_detects(installed, tmp_path):
    image = np.full((50, 80, 3), 20, np.uint8)
    cv2.circle(image, (60, 12), 4, (255, 255, 255), -1)
    cv2.imwrite(str(tmp_path / "lamp.png"), image)
    done = tsrkit(
        installed,
        "detect",
        str(tmp_path / "lamp.png"),
        "--detector",
        "brightest-blobs",
        "--param",
        "top=1",
    )
    assert done.returncode == 0, done.stderr
    (det,) = json.loads(done.stdout)["detections"]
    assert abs(det["x"] - 60) < 1 and abs(det["y"] - 12) < 1


def test_load_filter_hides_it(installed):
    env = dict(installed, TSRKIT_LOAD_PLUGINS="format-*")
    done = tsrkit(env, "plugins", "--json")
    assert all(p["name"] != "brightest-blobs" for p in json.loads(done.stdout))


def coco_ap50(folder: Path) -> float:
    """AP at IoU 0.5 computed by pycocotools directly from the files a benchmark wrote."""
    from pycocotools.coco import COCO
    from pycocotools.cocoeval import COCOeval

    truth = COCO(str(folder / "ground_truth.coco.json"))
    found = json.loads((folder / "detections.coco.json").read_text())
    evaluation = COCOeval(truth, truth.loadRes(found), "bbox")
    evaluation.params.iouThrs = np.array([0.5])
    evaluation.evaluate()
    evaluation.accumulate()
    evaluation.summarize()
    return float(evaluation.stats[0])


@pytest.mark.parametrize("dataset", ["roboflow_traffic_light_kr", "sample", "coco-file"])
def test_installed_plugin_benchmarks_real_coco_and_sample(
    installed, tmp_path, dataset, shared_datasets
):
    if dataset == "coco-file":  # a COCO path: the bundled sample's coco.json
        from tsrkit.synth import sample_path

        dataset = str(sample_path().parent / "coco.json")
    out = tmp_path / "bench"
    done = tsrkit(
        installed,
        "benchmark",
        "--dataset",
        dataset,
        "--detector",
        "brightest-blobs",
        "--workers",
        "1",
        "--quiet",
        "--out",
        str(out),
    )
    assert done.returncode == 0, done.stderr
    for name in (
        "report.json",
        "summary.md",
        "detections.jsonl",
        "detections.coco.json",
        "ground_truth.coco.json",
        "plots/recall_fpr_bubbles.png",
    ):
        assert (out / name).is_file(), name
    report = json.loads((out / "report.json").read_text())
    assert report["detector"]["name"] == "brightest-blobs"
    # The package's own metric and report writer: one file each, no change to tsrkit.
    error = report["centre_error"]
    assert (error["pairs"] > 0) == (report["per_frame"]["hit_frame_fraction"] > 0)
    assert error["pairs"] == 0 or min(error["mean_px"], error["median_px"]) >= 0
    # ... and every writer shows the metric's result without knowing it.
    summary = (out / "summary.md").read_text()
    assert "| centre px |" in summary and "Centre error" in summary
    assert "centre_error.mean_px" in (out / "headline.csv").read_text().splitlines()[0]
    assert ("plots/centre_error.png" in report["plots"]) == (error["pairs"] > 0)
    missed = (out / "missed.csv").read_text().splitlines()
    assert "missed.csv" in report["files"] and missed[0].startswith("frame,source,state")
    assert len(missed) > 1
    assert report["frames"] > 0 and report["per_frame"]["frames_with_gt"] > 0
    assert 0 <= report["per_frame"]["recall_mean"] <= 1
    assert abs(report["iou50"]["ap"] - coco_ap50(out)) <= 1e-6
