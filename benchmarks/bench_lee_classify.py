"""Lee 3.4 log-polar + PCA + SVM on GTSRB (35 px subset): accuracy, rotation, pixel baseline.

Fixed split: scikit-learn ``train_test_split(test_size=0.5, stratify=class, random_state=0)``
over the 2,046 crops (43 classes, up to 50 each); the crop is the GTSRB ROI box. Compares the
log-polar features with plain pixels (same PCA + SVM), unrotated and with the test crops
rotated by +-10 deg about the ROI centre, and measures classified crops per second.

    python benchmarks/bench_lee_classify.py
"""

from __future__ import annotations

import argparse

import harness

harness.single_thread()

import dataclasses  # noqa: E402
import time  # noqa: E402

import cv2  # noqa: E402
import numpy as np  # noqa: E402
from sklearn.metrics import accuracy_score, recall_score  # noqa: E402
from sklearn.model_selection import train_test_split  # noqa: E402

from tsrkit import Candidate  # noqa: E402
from tsrkit.api import open_dataset  # noqa: E402
from tsrkit_plugins.classifiers.logpolar_svm import LogPolarSVM  # noqa: E402

CONFIGS = (("log-polar", 10), ("none", 10), ("log-polar", 50), ("none", 50))
ANGLES = (0, 10, -10)


def classifier(transform: str, n_components: int) -> LogPolarSVM:
    values = {p.name: p.default for p in LogPolarSVM.PARAMS}
    values.update(transform=transform, n_components=n_components)
    return LogPolarSVM(**values)


def rotated(sample, angle: float):
    """The sample's image rotated by ``angle`` deg (counter-clockwise) about its ROI centre."""
    image = sample.load().image
    if angle == 0:
        return image
    centre = sample.annotations[0].center
    matrix = cv2.getRotationMatrix2D(centre, angle, 1.0)
    return cv2.warpAffine(
        image, matrix, image.shape[1::-1], flags=cv2.INTER_LINEAR, borderMode=cv2.BORDER_REPLICATE
    )


def predict(clf: LogPolarSVM, samples, angle: float) -> tuple[list[str], float]:
    """Predicted class per sample and the crops per second of ``classify``."""
    out, seconds = [], 0.0
    for sample in samples:
        frame = dataclasses.replace(sample.load(), image=rotated(sample, angle))
        candidate = Candidate.from_box(sample.annotations[0].bbox, 1.0)
        start = time.perf_counter()
        out.append(clf.classify(frame, [candidate])[0].state)
        seconds += time.perf_counter() - start
    return out, len(samples) / seconds


def main() -> None:
    argparse.ArgumentParser(description=__doc__).parse_args()  # --help only
    harness.announce()
    data = open_dataset("gtsrb_test_35px_subset")
    labels = [s.annotations[0].state for s in data.samples]
    train, test = train_test_split(
        list(data.samples), test_size=0.5, stratify=labels, random_state=0
    )
    truth = [s.annotations[0].state for s in test]
    print(
        f"GTSRB 35 px subset: {len(train)} train / {len(test)} test crops, "
        f"{len(set(labels))} classes; SVM rbf C=10, gamma 1/(n_components var)"
    )
    print(
        "\n| features | PCA comps | explained var | fit s | acc 0 deg | acc +10 deg | "
        "acc -10 deg | mean per-class recall 0 deg | crops/s |"
    )
    print("|---|---|---|---|---|---|---|---|---|")
    per_class = {}
    for transform, comps in CONFIGS:
        clf = classifier(transform, comps)
        start = time.perf_counter()
        clf.use_model(clf.fit(train))
        fit_s = time.perf_counter() - start
        accs, rate = [], None
        for angle in ANGLES:
            predicted, speed = predict(clf, test, angle)
            accs.append(accuracy_score(truth, predicted))
            if angle == 0:
                rate = speed
                balanced = recall_score(truth, predicted, average="macro", zero_division=0)
                per_class[(transform, comps)] = recall_score(
                    truth, predicted, labels=sorted(set(labels)), average=None, zero_division=0
                )
        print(
            f"| {transform} | {comps} | {clf.model().info['explained_variance']:.3f} | "
            f"{fit_s:.1f} | {accs[0]:.3f} | {accs[1]:.3f} | {accs[2]:.3f} | "
            f"{balanced:.3f} | {rate:.0f} |"
        )
    names = sorted(set(labels))
    lp, px = per_class[("log-polar", 10)], per_class[("none", 10)]
    print("\nPer-class recall, 10 components (log-polar / pixels), worst log-polar first:")
    print("| class | log-polar | pixels |")
    print("|---|---|---|")
    for k in np.argsort(lp, kind="stable"):
        print(f"| {names[k]} | {lp[k]:.2f} | {px[k]:.2f} |")


if __name__ == "__main__":
    main()
