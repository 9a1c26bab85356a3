"""Sun compensation measured as Lee did (2017, 4.4, Table 4.3), on rendered sequences.

A ``sun-pca`` model is trained on rendered frames sweeping the relative azimuth 0-180 degrees
(Lee's 4.2 protocol; seed 11). Test sequences (seed 2016) hold the relative azimuth nearly
fixed, as Lee's A-K do: seven with the Sun behind the camera (< 90 degrees) and four towards it.
On each, the ``sun-pca`` detector looks for the orange work-zone signs with and without
compensation (the same model; without it, every frame takes the uncompensated form): TP, FP and
FN at IoU >= 0.5, and red stop signs detected as orange counted apart (Table 4.3's red-orange
confusion). The classifier is also run on every annotated sign (orange vs red). A one-sided
Wilcoxon signed-rank test pairs the frames of the Sun-behind sequences: errors (FP + FN) with
compensation against without.

Run from the repository root: ``python benchmarks/sun_compensation.py``; with
``--write-default-model`` it also writes the model ``sun-pca`` ships.
"""

from __future__ import annotations

import argparse
import tempfile
import time
from pathlib import Path

import harness
import numpy as np
from scipy.stats import wilcoxon

from tsrkit import Candidate, get_registry, save_model
from tsrkit.api import iou_matrix
from tsrkit.eval.overlap import match_by_iou
from tsrkit.synth.sunlit import sweep

#: Lee's sequences A-G (Sun behind) and H-K (Sun ahead), by their mean relative azimuth.
SEQUENCES = {"A": 75, "B": 62, "C": 34, "D": 19, "E": 1, "F": 8, "G": 13,
             "H": 96, "I": 112, "J": 154, "K": 172}  # fmt: skip
FRAMES = 20
DEFAULT_MODEL = Path("plugins/classifiers/sun_pca/models/sun_pca_default")


def train(out: Path) -> Path:
    data = sweep(np.arange(0.0, 181.0, 15.0), frames_each=6, seed=11)
    plugin = get_registry().create("classifier", "sun-pca", {})
    model = plugin.fit(data.samples)
    training = {"dataset": "tsrkit.synth.sunlit.sweep(0..180 step 15, 6 each, seed 11)"}
    save_model(out, model, plugin="sun-pca", plugin_version="1", params=plugin.params,
               training=training)  # fmt: skip
    return out


def score_frame(sample, frame, detector, classifier) -> tuple[int, int, int, int, int, int]:
    """TP, FP, FN of orange signs; red signs detected as orange; signs classified right; signs."""
    found = detector.detect(frame)
    boxes = [c.bbox for c in found]
    orange = [a.bbox for a in sample.annotations if a.state == "orange"]
    red = [a.bbox for a in sample.annotations if a.state == "red"]
    pairs = match_by_iou(boxes, [c.score for c in found], orange, 0.5)
    matched = {i for i, _ in pairs}
    spare = [b for i, b in enumerate(boxes) if i not in matched]
    confused = int((iou_matrix(spare, red) >= 0.3).any(axis=1).sum()) if spare and red else 0
    states = classifier.classify(
        frame, [Candidate.from_box(a.bbox, 1.0) for a in sample.annotations]
    )
    right = sum(d.state == a.state for d, a in zip(states, sample.annotations))
    tp = len(pairs)
    return tp, len(found) - tp, len(orange) - tp, confused, right, len(sample.annotations)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--write-default-model", action="store_true")
    args = parser.parse_args()
    harness.announce()
    with tempfile.TemporaryDirectory() as tmp:
        model = train(DEFAULT_MODEL if args.write_default_model else Path(tmp, "sun_pca"))
        registry = get_registry()
        plugins = {
            comp: (
                registry.create("detector", "sun-pca", {"model": str(model), "compensate": comp}),
                registry.create("classifier", "sun-pca", {"model": str(model), "compensate": comp}),
            )
            for comp in (True, False)
        }
        rows, errors, seconds, frames = [], {True: [], False: []}, {True: 0.0, False: 0.0}, 0
        for seed, (name, rel) in enumerate(SEQUENCES.items()):
            data = sweep([float(rel)], frames_each=FRAMES, seed=2016 + seed)
            totals = {True: np.zeros(6, int), False: np.zeros(6, int)}
            for sample in data.samples:
                frame = sample.load()
                frames += 1
                for comp, (detector, classifier) in plugins.items():
                    start = time.perf_counter()
                    counts = np.array(score_frame(sample, frame, detector, classifier))
                    seconds[comp] += time.perf_counter() - start
                    totals[comp] += counts
                    if rel < 90:
                        errors[comp].append(counts[1] + counts[2])
            rows.append((name, rel, totals))
    header = ("| seq | rel. az. | signs | TP | FP | FN | P | R | red as orange | cls. acc. "
              "| TP | FP | FN | P | R | red as orange | cls. acc. |")  # fmt: skip
    print("with Sun position (left) and without (right); cls. acc.: classifier on every sign")
    print(header)
    print("|---" * 17 + "|")
    groups = {"behind (< 90)": np.zeros((2, 6), int), "ahead (> 90)": np.zeros((2, 6), int)}
    for name, rel, totals in rows:
        group = groups["behind (< 90)" if rel < 90 else "ahead (> 90)"]
        group[0] += totals[True]
        group[1] += totals[False]
        print(f"| {name} | {rel} | {totals[True][0] + totals[True][2]} | " + " | ".join(
            cells(totals[comp]) for comp in (True, False)) + " |")  # fmt: skip
    for label, group in groups.items():
        print(f"| {label} | | {group[0][0] + group[0][2]} | " + " | ".join(
            cells(group[k]) for k in (0, 1)) + " |")  # fmt: skip
    stat = wilcoxon(errors[True], errors[False], alternative="less", zero_method="zsplit")
    print(f"frames with the Sun behind: {len(errors[True])}; errors per frame (FP + FN) with "
          f"{np.mean(errors[True]):.3f}, without {np.mean(errors[False]):.3f}; one-sided "
          f"Wilcoxon p = {stat.pvalue:.2g}")  # fmt: skip
    for comp in (True, False):
        print(f"ms per 640x480 frame (detector + classifier), compensate={comp}: "
              f"{1000 * seconds[comp] / frames:.1f}")  # fmt: skip


def cells(c: np.ndarray) -> str:
    tp, fp, fn, confused, right, signs = (int(v) for v in c)
    precision = tp / (tp + fp) if tp + fp else 0.0
    recall = tp / (tp + fn) if tp + fn else 0.0
    return (f"{tp} | {fp} | {fn} | {precision:.3f} | {recall:.3f} | {confused} | "
            f"{right / signs:.3f}")  # fmt: skip


if __name__ == "__main__":
    main()
