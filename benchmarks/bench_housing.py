"""The housing stage: speed at 50 candidates on a 1280x720 frame (one thread), fit quality on
the real housing boxes given their lit lens, and housing AP50 / recall after the paper detectors.

    python benchmarks/bench_housing.py
    python benchmarks/bench_housing.py --stages    # only: where the fit is lost, stage by stage
    python benchmarks/bench_housing.py --fit       # only: speed and fit quality

``--stages`` fits each test housing from four starts and gives the share at IoU >= 0.5: the
true lit lens (centre and radius from the box, :func:`find_lens`), the ``union`` detector's
best-scored candidate whose centre lies in the box's circle (Zheng's rule), and the two mixed
(true centre with the candidate's radius, the candidate's centre with the true radius).

Datasets draw their boxes with different margins around the head (DTLD's carry several pixels
of background), so each share is also given margin-free (:func:`margin_free_iou`): a fit that
only misses the annotation's margin counts, a wrong housing does not.
"""

from __future__ import annotations

import os

for _var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ[_var] = "1"

import argparse  # noqa: E402
import json  # noqa: E402
import subprocess  # noqa: E402
import sys  # noqa: E402
import tempfile  # noqa: E402
import time  # noqa: E402
from pathlib import Path  # noqa: E402

import cv2  # noqa: E402
import numpy as np  # noqa: E402

from tsrkit.datasets import open_dataset  # noqa: E402
from tsrkit.eval.matching import centre_hits  # noqa: E402
from tsrkit.geometry import iou_matrix  # noqa: E402
from tsrkit.registry import get_registry  # noqa: E402
from tsrkit.synth.heads import background, render_head  # noqa: E402
from tsrkit.types import Candidate, Frame  # noqa: E402
from tsrkit_plugins.classifiers.regions import find_lens  # noqa: E402
from tsrkit_plugins.housing.fit import fit_housings  # noqa: E402
from tsrkit_plugins.housing.margin import learn_margin, margin_free_iou, widen  # noqa: E402

cv2.setNumThreads(1)


def speed() -> tuple[float, float]:
    """Median wall-clock and CPU ms of the housing stage on a 1280x720 frame with 50
    candidates (the CPU time is the one to read on a shared machine)."""
    image = background(720, 1280)
    rng = np.random.default_rng(0)
    candidates = []
    for k in range(50):
        x, y = 60 + 23 * k, 100 + 10 * (k % 40)
        render_head(image, (x, y), 4 + k % 6, 3, k % 3)
        candidates.append(Candidate.from_circle(x, y, 4 + k % 6, float(rng.random())))
    stage = get_registry().create("verifier", "housing")
    frame = Frame(image, "bench")
    wall, cpu = [], []
    for _ in range(30):
        start, start_cpu = time.perf_counter(), time.process_time()
        stage.verify(frame, candidates)
        wall.append(time.perf_counter() - start)
        cpu.append(time.process_time() - start_cpu)
    return 1000 * float(np.median(wall)), 1000 * float(np.median(cpu))


#: The training split of each housing set (as in ``verifier_loso.py``): its margin is learned
#: there, never on the test split.
TRAIN_SPLIT = {"roboflow_cinta_v2_id": "valid", "dtld_fridtjofs": "train"}


def fit_quality(name: str) -> str:
    """IoU of the fit with each test housing box, its lit lens found inside the box; also
    margin-free, and with the margin learned on the set's training split."""
    margin = learn_margin(open_dataset(name).split(TRAIN_SPLIT[name]))
    ious, free, widened = [], [], []
    for sample in open_dataset(name).split("test"):
        frame = sample.load()
        gray = cv2.cvtColor(frame.image, cv2.COLOR_BGR2GRAY)
        boxes = [a.bbox for a in sample.annotations]
        lenses = [find_lens(frame.image, b) for b in boxes]
        fitted, _, _ = fit_housings(gray, [(c.x, c.y, c.radius) for c in lenses])
        ious += [iou_matrix([b], [f])[0, 0] for b, f in zip(boxes, fitted)]
        free += [margin_free_iou(b, f) for b, f in zip(boxes, fitted)]
        widened += [iou_matrix([b], [f])[0, 0] for b, f in zip(boxes, widen(fitted, margin))]
    iou = np.array(ious)
    return (
        f"{name} test: {len(iou)} housings, mean IoU {iou.mean():.2f}, "
        f"IoU >= 0.5: {(iou >= 0.5).mean():.2f}, >= 0.7: {(iou >= 0.7).mean():.2f}; "
        f"margin-free IoU >= 0.5: {(np.array(free) >= 0.5).mean():.2f}; margin learned on "
        f"{TRAIN_SPLIT[name]} {margin:.2f}, then IoU >= 0.5: "
        f"{(np.array(widened) >= 0.5).mean():.2f}"
    )


def stage_starts(name: str) -> str:
    """Share of ``name`` test housings fitted at IoU >= 0.5 from each start (module docstring)."""
    union = get_registry().create("detector", "union")
    starts = ("true lens", "true centre, cand. radius", "cand. centre, true radius", "candidate")
    fitted: dict[str, list[float]] = {k: [] for k in starts}
    free: dict[str, list[float]] = {k: [] for k in starts}
    offsets, total = [], 0
    for sample in open_dataset(name).split("test"):
        boxes = [a.bbox for a in sample.annotations]
        if not boxes:
            continue
        total += len(boxes)
        frame = sample.load()
        gray = cv2.cvtColor(frame.image, cv2.COLOR_BGR2GRAY)
        found = union.detect(frame)
        hits = centre_hits([(c.x, c.y) for c in found], boxes) if found else None
        for j, box in enumerate(boxes):
            lens = find_lens(frame.image, box)
            idx = np.flatnonzero(hits[:, j]) if hits is not None else []
            lenses = {"true lens": (lens.x, lens.y, lens.radius)}
            if len(idx):
                c = max((found[i] for i in idx), key=lambda c: c.score)
                lenses["true centre, cand. radius"] = (lens.x, lens.y, c.radius)
                lenses["cand. centre, true radius"] = (c.x, c.y, lens.radius)
                lenses["candidate"] = (c.x, c.y, c.radius)
                offsets.append(np.hypot(c.x - lens.x, c.y - lens.y) / lens.radius)
            for key, start in lenses.items():
                fit, _, _ = fit_housings(gray, [start])
                fitted[key].append(iou_matrix([box], fit)[0, 0])
                free[key].append(margin_free_iou(box, fit[0]))
    cells = " | ".join(
        f"{np.sum(np.array(fitted[k]) >= 0.5) / total:.2f} "
        f"({np.sum(np.array(free[k]) >= 0.5) / total:.2f})"
        for k in starts
    )
    return f"| {name} | {total} | {len(offsets) / total:.2f} | {cells} | {np.median(offsets):.2f} |"


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
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--stages", action="store_true", help="only the stage-by-stage table")
    parser.add_argument("--fit", action="store_true", help="only the speed and fit quality")
    args = parser.parse_args()
    if args.stages:
        print("shares at IoU >= 0.5, margin-free in brackets\n")
        print(
            "| set (test) | housings | union hit | true lens | true centre, cand. radius "
            "| cand. centre, true radius | candidate | cand. offset (true radii, median) |"
        )
        print("|---|---:|---:|---:|---:|---:|---:|---:|")
        for name in ("roboflow_cinta_v2_id", "dtld_fridtjofs"):
            print(stage_starts(name), flush=True)
        return
    wall, cpu = speed()
    print(
        f"housing stage, 1280x720, 50 candidates, one thread: {wall:.2f} ms wall, "
        f"{cpu:.2f} ms CPU (medians of 30)"
    )
    for name in ("roboflow_cinta_v2_id", "dtld_fridtjofs"):
        print(fit_quality(name))
    if args.fit:
        return
    print("\n| set (test) | detector | stage | housing AP50 | recall at IoU 0.5 | hit |")
    print("|---|---|---|---:|---:|---:|")
    for name in ("roboflow_cinta_v2_id", "dtld_fridtjofs"):
        for detector in ("lab-frst", "conspicuity"):
            for stage in ([], ["-V", "housing"]):
                print(detector_runs(name, detector, stage), flush=True)


if __name__ == "__main__":
    main()
