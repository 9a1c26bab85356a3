"""COCO export and AP: report.json's AP equals pycocotools on the written files."""

import contextlib
import io
import json

import pytest
from benchmark_fakes import OracleDetector, hand_dataset, make
from pycocotools.coco import COCO
from pycocotools.cocoeval import COCOeval

from tsrkit.eval.coco import coco_ap
from tsrkit.reporting.benchmarking import benchmark


def pycocotools_stats(gt_path, dt_path):
    with contextlib.redirect_stdout(io.StringIO()):
        gt = COCO(str(gt_path))
        evaluator = COCOeval(gt, gt.loadRes(str(dt_path)), "bbox")
        evaluator.evaluate()
        evaluator.accumulate()
        evaluator.summarize()
    return evaluator.stats


def test_report_ap_equals_pycocotools_on_written_files(tmp_path):
    report = benchmark(hand_dataset(8), make(OracleDetector), out=tmp_path, cache=False)
    stats = pycocotools_stats(
        tmp_path / "ground_truth.coco.json", tmp_path / "detections.coco.json"
    )
    assert report["iou50"]["ap"] == pytest.approx(stats[1], abs=1e-6)
    assert report["iou50"]["ap_50_95"] == pytest.approx(stats[0], abs=1e-6)
    # 12 of 16 boxes found exactly, 4 false positives ranked below every hit.
    assert 0.7 < report["iou50"]["ap"] < 0.8
    written = json.loads((tmp_path / "detections.coco.json").read_text())
    assert len(written) == 16 and {d["category_id"] for d in written} == {1}


def test_ap_edge_cases():
    gt = {
        "images": [{"id": 1, "width": 10, "height": 10}],
        "categories": [{"id": 1}],
        "annotations": [
            {
                "id": 1,
                "image_id": 1,
                "category_id": 1,
                "bbox": [0, 0, 2, 2],
                "area": 4,
                "iscrowd": 0,
            }
        ],
    }
    assert coco_ap(gt, [])["ap50"] == 0.0
    assert coco_ap({**gt, "annotations": []}, [])["ap50"] is None
    perfect = coco_ap(gt, [{"image_id": 1, "category_id": 1, "bbox": [0, 0, 2, 2], "score": 1.0}])
    assert perfect["ap50"] == pytest.approx(1.0) and perfect["ap"] == pytest.approx(1.0)
