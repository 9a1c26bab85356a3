"""The ``channelizer`` detector (Lee 2017, 3.5) on rendered work-zone scenes with known depth:
recall and precision at IoU >= 0.5, recall by depth, the relative error of ``distance_m``
(Eq. 3.5) by depth, and the time per 1280x720 frame.

Run from the repository root: ``python benchmarks/bench_channelizer.py [--frames N]``.
"""

from __future__ import annotations

import argparse
import time

import harness
import numpy as np

from tsrkit import get_registry
from tsrkit.api import parse_assignments
from tsrkit.eval.overlap import match_by_iou
from tsrkit.synth.workzone import generate

BINS = ((5, 10), (10, 20), (20, 30), (30, 50), (50, 60))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    harness.add_frames(parser, 200)
    parser.add_argument("--seed", type=int, default=2017)
    parser.add_argument("-p", "--param", action="append", default=[], help="channelizer KEY=V")
    args = parser.parse_args()
    harness.announce()
    detector = get_registry().create("detector", "channelizer", parse_assignments(args.param))
    data = generate(args.frames, seed=args.seed)
    tp = fp = 0
    truth, found, errors = [], [], []
    seconds = 0.0
    for sample in data:
        frame = sample.load()
        start = time.perf_counter()
        candidates = detector.detect(frame)
        seconds += time.perf_counter() - start
        boxes = [a.bbox for a in sample.annotations]
        scores = [c.score for c in candidates]
        pairs = {j: i for i, j in match_by_iou([c.bbox for c in candidates], scores, boxes)}
        tp += len(pairs)
        fp += len(candidates) - len(pairs)
        for j, ann in enumerate(sample.annotations):
            depth = ann.attributes["distance_m"]
            truth.append(depth)
            found.append(j in pairs)
            if j in pairs:
                errors.append((depth, candidates[pairs[j]].distance_m / depth - 1.0))
    truth_a, found_a, err = np.array(truth), np.array(found), np.array(errors)
    print(f"{args.frames} frames, {len(truth)} channelizers: recall {tp / len(truth):.3f}, "
          f"precision {tp / max(tp + fp, 1):.3f}, {fp} false positives; "
          f"{1000 * seconds / args.frames:.1f} ms per 1280x720 frame (one thread)")  # fmt: skip
    print(
        "| depth (m) | panels | recall | depth error median | 95th pct. | max | share within 5 % |"
    )
    print("|---|---:|---:|---:|---:|---:|---:|")
    for low, high in BINS:
        inside = (truth_a >= low) & (truth_a < high)
        e = np.abs(err[(err[:, 0] >= low) & (err[:, 0] < high), 1])
        if not inside.any() or not len(e):
            print(f"| {low}-{high} | {inside.sum()} | - | - | - | - | - |")
            continue
        print(f"| {low}-{high} | {inside.sum()} | {found_a[inside].mean():.3f} | "
              f"{np.median(e):.3f} | {np.percentile(e, 95):.3f} | {e.max():.3f} | "
              f"{np.mean(e <= 0.05):.3f} |")  # fmt: skip


if __name__ == "__main__":
    main()
