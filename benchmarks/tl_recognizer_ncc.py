"""How well TL-recognizer's NCC separates lights from other patches on a tuning split (5.2).

For each validation setting (bare lens MBR or housing context; core filling off or on) the script
scores every pruned patch of the tuning split, splits them into lights and others by the
annotations, and prints their NCC quantiles, the ROC AUC, the T that 5.2 would choose (the highest
score of a non-light) and the share of annotated lights a pruned patch reaches (the recall
ceiling) and keeps at that T. Usage: ``python benchmarks/tl_recognizer_ncc.py``.
"""

from __future__ import annotations

import harness

harness.single_thread()

import argparse  # noqa: E402

import numpy as np  # noqa: E402
from sklearn.metrics import roc_auc_score  # noqa: E402

import tsrkit  # noqa: E402
from tsrkit.api import centre_hits  # noqa: E402

#: Tuning split of each set (disjoint from the split the accuracy runs test on).
TUNING = {"roboflow_traffic_light_kr": "valid", "roboflow_cinta_v2_id": "valid", "sample": "train"}
#: The settings compared: name -> detector parameters.
SETTINGS = {
    "lens": {"context": "lens"},
    "lens+cores": {"context": "lens", "fill_cores": True},
    "housing": {"context": "housing", "orientation": "both"},
    "housing+cores": {"context": "housing", "orientation": "both", "fill_cores": True},
}


def frame_scores(detector, frame, boxes) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """One frame's pruned-patch scores (lights, others) and each box's best score (-inf: none)."""
    candidates = detector.scored(frame)
    scores = np.array([c.score for c in candidates], dtype=np.float64)
    if not candidates or not boxes:
        return np.zeros(0), scores, np.full(len(boxes), -np.inf)
    hits = centre_hits([(c.x, c.y) for c in candidates], boxes)
    inside = hits.any(axis=1)
    best = np.where(hits, scores[:, None], -np.inf).max(axis=0)
    return scores[inside], scores[~inside], best


def separation(detector, samples) -> dict:
    """Light / other NCC statistics of ``detector`` over ``samples``."""
    parts = [frame_scores(detector, s.load(), [a.bbox for a in s.annotations]) for s in samples]
    lights, others, best = (np.concatenate([p[i] for p in parts]) for i in range(3))
    threshold = others.max() if len(others) else -1.0
    auc = (
        roc_auc_score(np.r_[np.ones(len(lights)), np.zeros(len(others))], np.r_[lights, others])
        if len(lights) and len(others)
        else float("nan")
    )
    return {
        "lights": lights,
        "others": others,
        "auc": auc,
        "T": threshold,
        "reached": float(np.mean(np.isfinite(best))),
        "kept": float(np.mean(best > threshold)),
    }


def quantiles(values: np.ndarray) -> str:
    """Median / 90th / 99th percentile / maximum, or a dash for no values."""
    if not len(values):
        return "-"
    return "/".join(f"{q:.2f}" for q in np.quantile(values, [0.5, 0.9, 0.99, 1.0]))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--resize-factor", type=int, default=1)
    args = parser.parse_args()
    harness.announce()
    print(f"resize factor {args.resize_factor}; quantiles are median/p90/p99/max")
    print(
        f"{'set':<28} {'setting':<14} {'lights':>6} {'others':>7} {'lights NCC':>22} "
        f"{'others NCC':>22} {'AUC':>5} {'T':>5} {'reached':>7} {'kept@T':>6}"
    )
    for name, split in TUNING.items():
        samples = list(tsrkit.dataset(name).split(split))
        for setting, params in SETTINGS.items():
            det = tsrkit.detector("tl-recognizer", resize_factor=args.resize_factor, **params)
            r = separation(det, samples)
            print(
                f"{name + ':' + split:<28} {setting:<14} {len(r['lights']):>6} "
                f"{len(r['others']):>7} {quantiles(r['lights']):>22} "
                f"{quantiles(r['others']):>22} {r['auc']:>5.3f} {r['T']:>5.3f} "
                f"{r['reached']:>7.3f} {r['kept']:>6.3f}"
            )


if __name__ == "__main__":
    main()
