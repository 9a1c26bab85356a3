"""The housing stage: speed at 50 candidates on a 1280x720 frame (one thread), fit quality on
the real housing boxes given their lit lens, and housing AP50 / recall after the paper detectors.

    python benchmarks/bench_housing.py
"""

from __future__ import annotations

import os

for _var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ[_var] = "1"

import json  # noqa: E402
import subprocess  # noqa: E402
import sys  # noqa: E402
import tempfile  # noqa: E402
import time  # noqa: E402
from pathlib import Path  # noqa: E402

import cv2  # noqa: E402
import numpy as np  # noqa: E402

from tsrkit.datasets import open_dataset  # noqa: E402
from tsrkit.geometry import iou_matrix  # noqa: E402
from tsrkit.registry import get_registry  # noqa: E402
from tsrkit.synth.heads import background, render_head  # noqa: E402
from tsrkit.types import Candidate, Frame  # noqa: E402
from tsrkit_plugins.classifiers.regions import find_lens  # noqa: E402
from tsrkit_plugins.housing.fit import fit_housings  # noqa: E402

cv2.setNumThreads(1)


def speed() -> float:
    """Median ms of the housing stage on a 1280x720 frame with 50 candidates."""
    image = background(720, 1280)
    rng = np.random.default_rng(0)
    candidates = []
    for k in range(50):
        x, y = 60 + 23 * k, 100 + 10 * (k % 40)
        render_head(image, (x, y), 4 + k % 6, 3, k % 3)
        candidates.append(Candidate.from_circle(x, y, 4 + k % 6, float(rng.random())))
    stage = get_registry().create("verifier", "housing")
    frame = Frame(image, "bench")
    times = []
    for _ in range(30):
        start = time.perf_counter()
        stage.verify(frame, candidates)
        times.append(time.perf_counter() - start)
    return 1000 * float(np.median(times))


def fit_quality(name: str) -> str:
    """IoU of the fit with each test housing box, its lit lens found inside the box."""
    ious = []
    for sample in open_dataset(name).split("test"):
        frame = sample.load()
        gray = cv2.cvtColor(frame.image, cv2.COLOR_BGR2GRAY)
        boxes = [a.bbox for a in sample.annotations]
        lenses = [find_lens(frame.image, b) for b in boxes]
        fitted, _, _ = fit_housings(gray, [(c.x, c.y, c.radius) for c in lenses])
        ious += [iou_matrix([b], [f])[0, 0] for b, f in zip(boxes, fitted)]
    iou = np.array(ious)
    return (
        f"{name} test: {len(iou)} housings, mean IoU {iou.mean():.2f}, "
        f"IoU >= 0.5: {(iou >= 0.5).mean():.2f}, >= 0.7: {(iou >= 0.7).mean():.2f}"
    )


def detector_runs(name: str, detector: str, stage: list[str]) -> str:
    """Housing AP50 and recall at IoU 0.5 of ``detector`` with ``stage`` on ``name`` test."""
    with tempfile.TemporaryDirectory() as out:
        tsrkit = Path(sys.executable).parent / "tsrkit"
        cmd = [str(tsrkit), "benchmark", "--dataset", name, "--split", "test", "-d", detector]
        cmd += [*stage, "--eval-box", "housing", "-o", out, "-q", "--writer", "json"]
        subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        report = json.loads((Path(out) / "report.json").read_text())
    iou = report["iou50"]
    ap = "n/a" if iou.get("ap") is None else f"{iou['ap']:.3f}"
    return (
        f"| {name} | {detector} | {' '.join(stage) or '-'} | {ap} | {iou['recall']:.3f} | "
        f"{report['per_frame']['hit_frame_fraction']:.3f} |"
    )


def main() -> None:
    print(f"housing stage, 1280x720, 50 candidates, one thread: {speed():.2f} ms (median of 30)")
    for name in ("roboflow_cinta_v2_id", "dtld_fridtjofs"):
        print(fit_quality(name))
    print("\n| set (test) | detector | stage | housing AP50 | recall at IoU 0.5 | hit |")
    print("|---|---|---|---:|---:|---:|")
    for name in ("roboflow_cinta_v2_id", "dtld_fridtjofs"):
        for detector in ("lab-frst", "conspicuity"):
            for stage in ([], ["-V", "housing"]):
                print(detector_runs(name, detector, stage), flush=True)


if __name__ == "__main__":
    main()
