"""Lee 3.2 AdaBoost colour detector on real traffic lights: pixel accuracy, detection, speed.

Trains one model per colour on one Roboflow set and tests on the other (and the reverse), plus a
within-set split (train on ``valid``, test on ``test``). Prints pixel-wise accuracy (the thesis
reports 97 %), detection numbers from tsrkit.runner, and ms per 1280x720 frame on one thread.

    /work/venv/bin/python benchmarks/bench_lee_adaboost.py
"""
from __future__ import annotations

import os

for _var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ[_var] = "1"

import dataclasses  # noqa: E402
import time  # noqa: E402

import cv2  # noqa: E402
import numpy as np  # noqa: E402

from tsrkit.datasets import open_dataset  # noqa: E402
from tsrkit.runner import benchmark  # noqa: E402
from tsrkit.types import Frame  # noqa: E402
from tsrkit_plugins.detectors import adaboost_hsv as ab  # noqa: E402

SETS = ("roboflow_traffic_light_kr", "roboflow_cinta_v2_id")
TARGETS = ("red", "yellow", "green")
DETECT = {"min_size": 3, "max_boxes": 20, "nms_overlap": 0.3}
THRESHOLDS = (0.5, 0.9, 0.99)


def detector(target: str, **extra) -> ab.AdaBoostHSV:
    values = {p.name: p.default for p in ab.AdaBoostHSV.params}
    values.update(target=target, **extra)
    return ab.AdaBoostHSV(**values)


def pixel_scores(det: ab.AdaBoostHSV, model, positive, negative) -> dict[str, float]:
    """Pixel accuracy of the booster's decision (f > 0) and of the posterior threshold."""
    stumps = {k: model.arrays[k] for k in ab.STUMP_KEYS}
    f = ab.boosted_margin(ab.plane_features(), stumps)
    out = {}
    for name, says_target in (("f>0", f > 0), ("posterior>0.5", det.table() > 0.5)):
        tpr = positive[says_target].sum() / max(positive.sum(), 1)
        tnr = negative[~says_target].sum() / negative.sum()
        acc = (positive[says_target].sum() + negative[~says_target].sum()) / \
            (positive.sum() + negative.sum())
        out[name] = {"accuracy": acc, "balanced": (tpr + tnr) / 2, "tpr": tpr, "tnr": tnr}
    return out


def only_target(dataset, target: str):
    """The dataset with only the boxes of ``target`` as ground truth (other lights: background)."""
    samples = tuple(dataclasses.replace(s, annotations=tuple(
        a for a in s.annotations if a.state == target)) for s in dataset.samples)
    return dataclasses.replace(dataset, name=f"{dataset.name}[{target}]", samples=samples)


def run_pair(train, test, label: str) -> None:
    print(f"\n## {label}: train {train.name} ({len(train)} images) -> test {test.name} "
          f"({len(test)} images)")
    print("| target | train px target/bg | prior | acc f>0 | bal. acc f>0 | TPR | TNR | "
          "bal. acc posterior>0.5 | fit s |")
    print("|---|---|---|---|---|---|---|---|---|")
    detection = []
    for target in TARGETS:
        det = detector(target)
        start = time.perf_counter()
        try:
            model = det.fit(train)
        except ValueError as exc:
            print(f"| {target} | {exc} |")
            continue
        fit_s = time.perf_counter() - start
        det.use_model(model)
        counts = ab.pixel_histograms(test, target, det.params["min_value"])
        a, b = pixel_scores(det, model, counts.positive, counts.negative).values()
        print(f"| {target} | {model.info['target_pixels']}/{model.info['background_pixels']} | "
              f"{model.info['prior']:.2f} | {a['accuracy']:.4f} | {a['balanced']:.4f} | "
              f"{a['tpr']:.3f} | {a['tnr']:.4f} | {b['balanced']:.4f} | {fit_s:.1f} |")
        for threshold in THRESHOLDS:
            tuned = detector(target, threshold=threshold, **DETECT)
            tuned.use_model(model)
            report = benchmark(only_target(test, target), tuned, cache=False)
            pf, iou = report["per_frame"], report["iou50"]
            detection.append(f"| {target} | {threshold} | {_f(pf['recall_mean'])} | "
                             f"{_f(pf['precision_mean'])} | {_f(pf['hit_frame_fraction'])} | "
                             f"{_f(iou['recall'])} | {_f(iou['precision'])} | {_f(iou['ap'])} |")
    print("\n| target | threshold | recall_mean | precision_mean | hit_frame_fraction | "
          "IoU50 recall | IoU50 precision | AP50 |")
    print("|---|---|---|---|---|---|---|---|")
    print("\n".join(detection))


def _f(value) -> str:
    return "n/a" if value is None else f"{value:.3f}"


def speed(train) -> None:
    cv2.setNumThreads(1)
    det = detector("red")
    model = det.fit(train)
    det.use_model(model)
    image = cv2.resize(train.samples[0].load().image, (1280, 720))
    frame = Frame(image, "speed")
    times = []
    for _ in range(60):
        start = time.perf_counter()
        det.detect(frame)
        times.append((time.perf_counter() - start) * 1000)
    stumps = {k: model.arrays[k] for k in ab.STUMP_KEYS}
    hue, sat, _ = ab.hsv_planes(image)
    start = time.perf_counter()
    ab.boosted_margin(ab.color_features(hue, sat), stumps)
    direct = (time.perf_counter() - start) * 1000
    print(f"\n## Speed (1280x720, one thread, 60 runs): detect median "
          f"{np.median(times):.1f} ms (p90 {np.percentile(times, 90):.1f} ms); "
          f"evaluating the {det.params['n_estimators']} stumps per pixel without the table: "
          f"{direct:.0f} ms (x{direct / np.median(times):.1f})")


def main() -> None:
    data = {name: open_dataset(name) for name in SETS}
    run_pair(data[SETS[0]], data[SETS[1]], "cross-set")
    run_pair(data[SETS[1]], data[SETS[0]], "cross-set")
    for name in SETS:
        run_pair(data[name].split("valid"), data[name].split("test"), "within-set")
    speed(data[SETS[1]])


if __name__ == "__main__":
    main()
