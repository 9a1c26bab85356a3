"""Accuracy, per-class recall, confusion and single-thread speed of the state classifiers
(ab-hist, hsi-backprojection) on the real sets, each trained on udacity_mit_tl_crops train.

Run: python benchmarks/bench_classifiers.py [--repeats 5]
"""

from __future__ import annotations

import harness

harness.single_thread()

import argparse  # noqa: E402
import statistics  # noqa: E402
import tempfile  # noqa: E402
import time  # noqa: E402
from pathlib import Path  # noqa: E402

from tsrkit import (  # noqa: E402
    Candidate,
    Dataset,
    get_registry,
)
from tsrkit.api import open_dataset  # noqa: E402
from tsrkit.runner.training import train as train_model  # noqa: E402

CLASSIFIERS = ("ab-hist", "hsi-backprojection")
#: The papers' methods as printed (Zheng 3.3, Lee 5.3.3), run beside the defaults.
PAPER_EXACT = {
    "ab-hist": {"smooth": "0", "min_chroma": "0", "red_prior": "false"},
    "hsi-backprojection": {"hue_smooth": "0", "red_prior": "false", "clip": "256"},
}
STATES = ("red", "yellow", "green")


def by_lighting(dataset: Dataset, lighting: str) -> Dataset:
    """The samples of ``dataset`` whose metadata ``lighting`` is ``lighting`` (day, night)."""
    chosen = tuple(s for s in dataset if s.metadata.get("lighting") == lighting)
    return Dataset(f"{dataset.name}:{lighting}", chosen, dataset.format, dataset.root, dataset.info)


def benchmark_sets() -> tuple[Dataset, dict[str, Dataset]]:
    """The training split (MIT train) and the named test sets of this benchmark."""
    mit = open_dataset("udacity_mit_tl_crops", format="crops")
    vgis = open_dataset("lisa_vgis_bulb_crops", format="crops")
    return mit.split("train"), {
        "mit test": mit.split("test"),
        "vgis day": by_lighting(vgis, "day"),
        "vgis night": by_lighting(vgis, "night"),
        "kr boxes": open_dataset("roboflow_traffic_light_kr"),
        "cinta boxes": open_dataset("roboflow_cinta_v2_id"),
    }


def evaluate(classifier, dataset: Dataset) -> dict:
    """Accuracy, per-class recall and confusion (true -> predicted) over red/yellow/green."""
    confusion: dict[str, dict[str, int]] = {s: {} for s in STATES}
    for sample in dataset:
        anns = [a for a in sample.annotations if a.state in STATES]
        if not anns:
            continue
        frame = sample.load()
        found = classifier.classify(frame, [Candidate.from_box(a.bbox, 1.0) for a in anns])
        for ann, det in zip(anns, found):
            row = confusion[ann.state]
            row[det.state] = row.get(det.state, 0) + 1
    totals = {s: sum(confusion[s].values()) for s in STATES}
    correct = sum(confusion[s].get(s, 0) for s in STATES)
    return {
        "n": sum(totals.values()),
        "accuracy": correct / max(sum(totals.values()), 1),
        "recall": {s: (confusion[s].get(s, 0) / totals[s] if totals[s] else None) for s in STATES},
        "counts": totals,
        "confusion": confusion,
    }


def crops_per_second(classifier, dataset: Dataset, repeats: int) -> float:
    """Median over ``repeats`` of crops classified per second (images already decoded)."""
    frames = [(s.load(), [Candidate.from_box(s.annotations[0].bbox, 1.0)]) for s in dataset]
    rates = []
    for _ in range(repeats):
        start = time.perf_counter()
        for frame, cands in frames:
            classifier.classify(frame, cands)
        rates.append(len(frames) / (time.perf_counter() - start))
    return statistics.median(rates)


def show(name: str, result: dict) -> None:
    recall = " ".join(
        f"{s}={'-' if r is None else f'{r:.3f}'}" for s, r in result["recall"].items()
    )
    print(f"  {name:<22} n={result['n']:<4} acc={result['accuracy']:.3f}  recall {recall}")
    for state, row in result["confusion"].items():
        print(f"      {state:<7} -> {dict(sorted(row.items()))}")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    harness.add_repeats(parser, 5)
    parser.add_argument(
        "--param",
        action="append",
        default=[],
        help="CLASSIFIER:KEY=VALUE passed to that classifier",
    )
    parser.add_argument(
        "--paper-exact",
        action="store_true",
        help="also run each classifier with the paper's exact settings",
    )
    args = parser.parse_args()
    harness.announce()
    registry = get_registry()
    train, sets = benchmark_sets()
    tmp = tempfile.mkdtemp(prefix="bench_classifiers_")
    runs = [
        (
            name,
            dict(
                p.split(":", 1)[1].split("=", 1) for p in args.param if p.split(":", 1)[0] == name
            ),
        )
        for name in CLASSIFIERS
    ]
    if args.paper_exact:
        runs += list(PAPER_EXACT.items())
    for name, given in runs:
        start = time.perf_counter()
        path = train_model(name, train, Path(tmp) / name, given)
        fit_s = time.perf_counter() - start
        classifier = registry.create("classifier", name, {**given, "model": str(path)})
        print(f"{name} {given or ''} trained on {len(train)} MIT train crops in {fit_s:.1f} s")
        for set_name, dataset in sets.items():
            show(set_name, evaluate(classifier, dataset))
        rate = crops_per_second(classifier, sets["mit test"], args.repeats)
        print(f"  speed: {rate:.0f} crops/s (MIT test, single thread, median of {args.repeats})")


if __name__ == "__main__":
    main()
