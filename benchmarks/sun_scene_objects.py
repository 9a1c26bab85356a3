"""Traffic lights and channelizers under a Sun at known positions (Lee 2017, 3.5 and 4.2-4.4),
on rendered sequences: what the Sun does to the paper methods beyond the work-zone signs.

Two measurements over Lee's sequences A-K (the relative azimuths of Table 4.3), each a rendered
sweep (``tsrkit.synth.sunlit``) with traffic lights and channelizers added to the scene:

* **Lit lamps.** A ``sun-pca`` model with the targets ``light_red``, ``light_yellow`` and
  ``light_green`` is trained on a 0-180 degree sweep (seed 21); its classifier reads every lit
  lens of the test sequences with and without the Sun's position, beside ``ab-hist`` (Zheng 3.3,
  its shipped model, trained on MIT crops). Accuracy and reds read as yellow, per sequence.
* **Channelizers.** Lee's chapter 3 channelizer detector (no colour model of the Sun) on the
  same frames: recall and precision at IoU >= 0.5.

Run from the repository root: ``python benchmarks/sun_scene_objects.py``.
"""

from __future__ import annotations

import argparse
import tempfile
from pathlib import Path

import harness
import numpy as np

from tsrkit import Candidate, get_registry, save_model
from tsrkit.api import parse_assignments
from tsrkit.eval.overlap import match_by_iou
from tsrkit.synth.sunlit import LENSES, sweep

SEQUENCES = {"A": 75, "B": 62, "C": 34, "D": 19, "E": 1, "F": 8, "G": 13,
             "H": 96, "I": 112, "J": 154, "K": 172}  # fmt: skip
TARGETS = tuple(LENSES)
PAPER_STATE = {"light_red": "red", "light_yellow": "yellow", "light_green": "green"}


def train(out: Path, lights: int) -> Path:
    """The lamp model: a 0-180 degree sweep, 6 frames every 15 degrees."""
    data = sweep(np.arange(0.0, 181.0, 15.0), frames_each=6, seed=21, lights=lights)
    plugin = get_registry().create("classifier", "sun-pca", {"targets": ",".join(TARGETS)})
    training = {"dataset": "tsrkit.synth.sunlit.sweep(0..180 step 15, 6 each, lights, seed 21)"}
    save_model(out, plugin.fit(data.samples), plugin="sun-pca", plugin_version="1",
               params=plugin.params, training=training)  # fmt: skip
    return out


def lamp_counts(sample, frame, classifier, to_paper: bool) -> np.ndarray:
    """Lit lamps read right, reds read as yellow, and reds, for one frame."""
    lamps = [a for a in sample.annotations if a.state in TARGETS]
    found = classifier.classify(frame, [Candidate.from_box(a.bbox, 1.0) for a in lamps])
    truth = [PAPER_STATE[a.state] if to_paper else a.state for a in lamps]
    red = PAPER_STATE["light_red"] if to_paper else "light_red"
    yellow = PAPER_STATE["light_yellow"] if to_paper else "light_yellow"
    right = sum(d.state == t for d, t in zip(found, truth))
    red_as_yellow = sum(d.state == yellow and t == red for d, t in zip(found, truth))
    return np.array([right, red_as_yellow, truth.count(red), len(lamps)])


def channelizer_counts(sample, frame, detector) -> np.ndarray:
    """TP, FP, FN of channelizers at IoU >= 0.5, for one frame."""
    found = detector.detect(frame)
    truth = [a.bbox for a in sample.annotations if a.state == "channelizer"]
    pairs = match_by_iou([c.bbox for c in found], [c.score for c in found], truth, 0.5)
    return np.array([len(pairs), len(found) - len(pairs), len(truth) - len(pairs)])


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    harness.add_frames(parser, 12, help="frames per sequence")
    parser.add_argument("--lights", type=int, default=3, help="traffic lights per frame")
    parser.add_argument("--channelizers", type=int, default=3, help="channelizers per frame")
    parser.add_argument("-p", "--param", action="append", default=[], help="channelizer KEY=V")
    args = parser.parse_args()
    harness.announce()
    registry = get_registry()
    with tempfile.TemporaryDirectory() as tmp:
        model = str(train(Path(tmp, "lamps"), args.lights))
        classifiers = {
            "sun-pca": registry.create("classifier", "sun-pca", {"model": model}),
            "sun-pca, no Sun": registry.create(
                "classifier", "sun-pca", {"model": model, "compensate": False}
            ),
            "ab-hist": registry.create("classifier", "ab-hist", {}),
        }
        settings = {"horizon": 0.4, **parse_assignments(args.param)}
        channelizer = registry.create("detector", "channelizer", settings)
        print("| seq | rel. az. | lamps | " + " | ".join(
            f"{name} acc. | red as yellow" for name in classifiers
        ) + " | panels | channelizer P | R |")  # fmt: skip
        print("|---" * (4 + 2 * len(classifiers) + 2) + "|")
        groups = {"behind": {}, "ahead": {}}
        for k, (name, rel) in enumerate(SEQUENCES.items()):
            data = sweep([float(rel)], frames_each=args.frames, seed=3000 + k,
                         lights=args.lights, channelizers=args.channelizers)  # fmt: skip
            lamps = {c: np.zeros(4, int) for c in classifiers}
            panels = np.zeros(3, int)
            for sample in data.samples:
                frame = sample.load()
                for c, classifier in classifiers.items():
                    lamps[c] += lamp_counts(sample, frame, classifier, c == "ab-hist")
                panels += channelizer_counts(sample, frame, channelizer)
            group = groups["behind" if rel < 90 else "ahead"]
            for key, value in [*lamps.items(), ("panels", panels)]:
                group[key] = group.get(key, 0) + value
            print(row(name, rel, lamps, panels))
        for label, group in groups.items():
            print(row(f"Sun {label}", "", {c: group[c] for c in classifiers}, group["panels"]))


def row(name: str, rel, lamps: dict[str, np.ndarray], panels: np.ndarray) -> str:
    counts = next(iter(lamps.values()))
    cells = [f"{c[0] / c[3]:.3f} | {c[1]}/{c[2]}" for c in lamps.values()]
    tp, fp, fn = (int(v) for v in panels)
    precision = tp / (tp + fp) if tp + fp else 0.0
    return (f"| {name} | {rel} | {counts[3]} | " + " | ".join(cells)
            + f" | {tp + fn} | {precision:.3f} | {tp / (tp + fn):.3f} |")  # fmt: skip


if __name__ == "__main__":
    main()
