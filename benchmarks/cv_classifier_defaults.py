"""Choose a state classifier's defaults without test data: 5-fold stratified cross-validation
on the ``udacity_mit_tl_crops`` *train* split, over a grid of parameter values.

Every grid point is trained on four folds and scored on the fifth (annotated boxes as
candidates, as in ``bench_classifiers.py``); the accuracy and per-class recall pooled over the
five folds are printed, best accuracy last.

Run::

    python benchmarks/cv_classifier_defaults.py hsi-backprojection \\
        --grid min_saturation=0,40,80 --grid clip=250,256
"""

from __future__ import annotations

import harness

harness.single_thread()

import argparse  # noqa: E402
import itertools  # noqa: E402
import tempfile  # noqa: E402
from pathlib import Path  # noqa: E402

from sklearn.model_selection import StratifiedKFold  # noqa: E402

from tsrkit import (  # noqa: E402
    Candidate,
    Dataset,
    get_registry,
)
from tsrkit.api import open_dataset  # noqa: E402
from tsrkit.runner.training import train as train_model  # noqa: E402

STATES = ("red", "yellow", "green")


def grid_points(grid: list[str]) -> list[dict[str, str]]:
    """Every combination of ``KEY=V1,V2,...`` values, as parameter dicts."""
    axes = [(key, values.split(",")) for key, values in (g.split("=", 1) for g in grid)]
    return [
        dict(zip([k for k, _ in axes], combo)) for combo in itertools.product(*[v for _, v in axes])
    ]


def cross_validate(
    name: str, params: dict[str, str], samples: list, frames: dict, folds: list, workdir: Path
) -> dict[str, int]:
    """Pooled ``(state, predicted) -> count`` over the folds for one parameter setting."""
    registry = get_registry()
    counts: dict[str, int] = {}
    for k, (train_idx, test_idx) in enumerate(folds):
        fold = Dataset(f"fold{k}", tuple(samples[i] for i in train_idx))
        path = train_model(name, fold, workdir / f"{name}-{k}", params)
        classifier = registry.create("classifier", name, {**params, "model": str(path)})
        for i in test_idx:
            truth = samples[i].annotations[0]
            found = classifier.classify(frames[i], [Candidate.from_box(truth.bbox, 1.0)])[0]
            key = f"{truth.state}>{found.state}"
            counts[key] = counts.get(key, 0) + 1
    return counts


def summary(counts: dict[str, int]) -> tuple[float, str]:
    """Accuracy and a per-class recall line from pooled confusion counts."""
    total = sum(counts.values())
    correct = sum(counts.get(f"{s}>{s}", 0) for s in STATES)
    recalls = []
    for state in STATES:
        n = sum(v for k, v in counts.items() if k.startswith(f"{state}>"))
        recalls.append(
            f"{state}={counts.get(f'{state}>{state}', 0) / n:.3f}" if n else f"{state}=-"
        )
    return correct / total, " ".join(recalls)


def grid_parser(description: str) -> argparse.ArgumentParser:
    """Command line of a grid search: a classifier name and repeatable ``--grid`` options."""
    parser = argparse.ArgumentParser(
        description=description, formatter_class=argparse.RawDescriptionHelpFormatter
    )
    parser.add_argument("classifier")
    parser.add_argument(
        "--grid",
        action="append",
        default=[],
        metavar="KEY=V1,V2",
        help="values to try for one parameter (repeat for more)",
    )
    return parser


def main() -> None:
    parser = grid_parser(__doc__)
    parser.add_argument("--folds", type=int, default=5)
    args = parser.parse_args()
    harness.announce()
    train = open_dataset("udacity_mit_tl_crops", format="crops").split("train")
    samples = [s for s in train if s.annotations and s.annotations[0].state in STATES]
    labels = [s.annotations[0].state for s in samples]
    frames = {i: s.load() for i, s in enumerate(samples)}
    folds = list(StratifiedKFold(args.folds, shuffle=True, random_state=0).split(samples, labels))
    results = []
    with tempfile.TemporaryDirectory(prefix="cv_classifier_") as tmp:
        for params in grid_points(args.grid) or [{}]:
            accuracy, recalls = summary(
                cross_validate(args.classifier, params, samples, frames, folds, Path(tmp))
            )
            results.append((accuracy, params, recalls))
            print(f"{params} cv_acc={accuracy:.4f} recall {recalls}", flush=True)
    best = max(results, key=lambda r: r[0])
    print(f"best: {best[1]} cv_acc={best[0]:.4f} recall {best[2]}")


if __name__ == "__main__":
    main()
