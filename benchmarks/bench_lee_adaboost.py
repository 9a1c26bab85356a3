"""Lee 3.2 AdaBoost colour detector on real traffic lights: pixel accuracy, defaults, speed.

1. Held-out pixel accuracy per colour for three training labellings (whole box, lit lens, lit
   lens + unlit-housing hard negatives), tested on lens-labelled pixels: KR -> cinTA, cinTA ->
   KR, and within each set (train on the ``valid`` split, test on ``test``).
2. The detection-defaults grid, run through tsrkit.reporting.benchmarking on the shipped model's
TRAINING set
   (roboflow_cinta_v2_id) only; ranks by the F1 of Zheng's per-frame recall and precision.
3. ms per 1280x720 frame on one thread (three-colour table vs. evaluating the stumps).

    python benchmarks/bench_lee_adaboost.py
"""

from __future__ import annotations

import argparse

import harness

harness.single_thread()

import itertools  # noqa: E402
import time  # noqa: E402

import cv2  # noqa: E402
import numpy as np  # noqa: E402

from tsrkit import Frame  # noqa: E402
from tsrkit.api import open_dataset  # noqa: E402
from tsrkit.reporting.benchmarking import benchmark  # noqa: E402
from tsrkit_plugins.detectors import adaboost_hsv as ab  # noqa: E402

KR, CINTA = "roboflow_traffic_light_kr", "roboflow_cinta_v2_id"
COLOURS = ab.TARGET_COLOURS["lights"]
LABELLINGS = (("box", False), ("lens", False), ("lens", True))
GRID = {"threshold": (0.5, 0.7, 0.9), "min_size": (3, 6, 10), "max_boxes": (1, 3, 5)}
THESIS = {"threshold": 0.5, "min_size": 30, "max_boxes": 1}


def detector(**params) -> ab.AdaBoostHSV:
    values = {p.name: p.default for p in ab.AdaBoostHSV.PARAMS}
    values.update(params)
    return ab.AdaBoostHSV(**values)


def balanced_accuracy(
    model, colour: str, positive: np.ndarray, negative: np.ndarray
) -> tuple[float, float, float]:
    """Balanced accuracy, TPR and TNR of the booster's decision f > 0 over pixel histograms."""
    stumps = {k: model.arrays[f"{colour}_{k}"] for k in ab.STUMP_KEYS}
    says = ab.boosted_margin(ab.plane_features(), stumps) > 0
    tpr = positive[says].sum() / positive.sum()
    tnr = negative[~says].sum() / negative.sum()
    return (tpr + tnr) / 2, tpr, tnr


def pixel_accuracy(train, test, label: str) -> None:
    """One row per training labelling; each colour trained alone (KR valid has no yellow)."""
    truth = ab.pixel_histograms(test, COLOURS, 50, "lens")
    for labels, hard in LABELLINGS:
        cells = []
        for t, colour in enumerate(COLOURS):
            if truth.positive[t].sum() == 0:
                cells.append("no test pixels")
                continue
            try:
                model = detector(target=colour, labels=labels, hard_negatives=hard).fit(train)
            except ValueError:
                cells.append("no training pixels")
                continue
            acc, tpr, tnr = balanced_accuracy(model, colour, truth.positive[t], truth.negative[t])
            cells.append(f"{acc:.3f} ({tpr:.2f} / {tnr:.3f})")
        name = labels + (" + hard neg." if hard else "")
        print(f"| {label} | {name} | " + " | ".join(cells) + " |", flush=True)


def f1(report: dict) -> float:
    r, p = report["per_frame"]["recall_mean"] or 0.0, report["per_frame"]["precision_mean"] or 0.0
    return 2 * r * p / (r + p) if r + p else 0.0


def report_row(settings: dict, report: dict) -> str:
    pf, state = report["per_frame"], report["state"]
    return (
        f"| {settings['threshold']} | {settings['min_size']} | {settings['max_boxes']} | "
        f"{_f(pf['recall_mean'])} | {_f(pf['precision_mean'])} | {f1(report):.3f} | "
        f"{_f(report['iou50']['ap'])} | {_f(state.get('accuracy'))} |"
    )


def defaults_grid(train) -> None:
    """Detection settings scored on the training set of the shipped model, best F1 first."""
    model = detector().fit(train)
    rows = []
    for values in itertools.chain(itertools.product(*GRID.values()), [tuple(THESIS.values())]):
        settings = dict(zip(GRID, values))
        det = detector(**settings)
        det.use_model(model)
        report = benchmark(train, det, cache=False)
        rows.append((f1(report), report_row(settings, report), settings == THESIS))
    print(
        "| threshold | min_size | max_boxes | recall_mean | precision_mean | F1 | AP50 | "
        "state acc |"
    )
    print("|---|---|---|---|---|---|---|---|")
    for _, row, thesis in sorted(rows, reverse=True):
        print(row + (" (Lee's values)" if thesis else ""))


def _f(value) -> str:
    return "n/a" if value is None else f"{value:.3f}"


def speed(train) -> None:
    det = detector()
    model = det.fit(train)
    det.use_model(model)
    image = cv2.resize(train.samples[0].load().image, (1280, 720))
    frame = Frame(image, "speed")
    times = []
    for _ in range(60):
        start = time.perf_counter()
        det.detect(frame)
        times.append((time.perf_counter() - start) * 1000)
    hue, sat, _ = ab.hsv_planes(image)
    start = time.perf_counter()
    for colour in COLOURS:
        ab.boosted_margin(
            ab.color_features(hue, sat), {k: model.arrays[f"{colour}_{k}"] for k in ab.STUMP_KEYS}
        )
    direct = (time.perf_counter() - start) * 1000
    print(
        f"\n## Speed (1280x720, one thread, 60 runs, target=lights): detect median "
        f"{np.median(times):.1f} ms (p90 {np.percentile(times, 90):.1f} ms); evaluating the "
        f"3 x {det.params['n_estimators']} stumps per pixel without the table: {direct:.0f} ms "
        f"(x{direct / np.median(times):.0f})"
    )


def main() -> None:
    argparse.ArgumentParser(description=__doc__).parse_args()  # --help only
    harness.announce()
    kr, cinta = open_dataset(KR), open_dataset(CINTA)
    print(
        "## Held-out pixel accuracy: balanced accuracy (TPR / TNR) of f > 0; test pixels: "
        "lit lens of the colour vs. outside every box and other colours' lenses"
    )
    print("| train -> test | training labels | " + " | ".join(COLOURS) + " |")
    print("|---|---|---|---|---|")
    pixel_accuracy(kr, cinta, "KR -> cinTA")
    pixel_accuracy(cinta, kr, "cinTA -> KR")
    pixel_accuracy(kr.split("valid"), kr.split("test"), "KR valid -> KR test")
    pixel_accuracy(cinta.split("valid"), cinta.split("test"), "cinTA valid -> cinTA test")
    print(f"\n## Detection defaults, validated on the training set {CINTA} (target=lights)")
    defaults_grid(cinta)
    speed(cinta)


if __name__ == "__main__":
    main()
