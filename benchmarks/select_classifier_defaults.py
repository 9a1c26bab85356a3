"""Cross-camera model selection for the state classifiers, with honest held-out numbers.

Cross-validation on MIT train (``cv_classifier_defaults.py``) sees one camera and so cannot
choose settings for the situation measured here: a model trained on MIT crops read on other
cameras. This script trains every grid point on MIT train, scores it on the five test sets of
``bench_classifiers.py`` and then, for each set in turn, picks the grid point with the best
mean *balanced accuracy* (mean per-class recall over red, yellow, green) on the *other four*
sets and reports that set's numbers under it: leave-one-set-out selection, so every number in
the held-out table comes from settings chosen without that set. The last line names the grid
point best over all five sets (the candidate default; its own numbers are selected in view of
every set and so are optimistic).

Run::

    python benchmarks/select_classifier_defaults.py hsi-backprojection \\
        --grid min_saturation=0,20,40 --grid clip=250,256
"""

from __future__ import annotations

import harness

harness.single_thread()

import tempfile  # noqa: E402
from pathlib import Path  # noqa: E402

import numpy as np  # noqa: E402
from bench_classifiers import STATES, benchmark_sets, evaluate  # noqa: E402
from cv_classifier_defaults import grid_parser, grid_points  # noqa: E402

from tsrkit import get_registry  # noqa: E402
from tsrkit.runner.training import train as train_model  # noqa: E402


def balanced_accuracy(result: dict) -> float:
    """Mean recall over the states present in a result of ``bench_classifiers.evaluate``."""
    return float(np.mean([r for r in result["recall"].values() if r is not None]))


def describe(result: dict) -> str:
    """``acc (red/yellow/green recall)`` of one result."""
    recalls = "/".join(
        "-" if result["recall"][s] is None else f"{result['recall'][s]:.2f}" for s in STATES
    )
    return f"{result['accuracy']:.3f} ({recalls})"


def main() -> None:
    args = grid_parser(__doc__).parse_args()
    harness.announce()
    registry = get_registry()
    train, sets = benchmark_sets()
    points = grid_points(args.grid) or [{}]
    scores: list[dict[str, dict]] = []
    with tempfile.TemporaryDirectory(prefix="select_classifier_") as tmp:
        for k, params in enumerate(points):
            path = train_model(args.classifier, train, Path(tmp) / f"m{k}", params)
            classifier = registry.create(
                "classifier", args.classifier, {**params, "model": str(path)}
            )
            scores.append({name: evaluate(classifier, data) for name, data in sets.items()})
            print(
                f"{params} " + "  ".join(f"{n}={describe(r)}" for n, r in scores[-1].items()),
                flush=True,
            )
    balanced = np.array([[balanced_accuracy(s[name]) for name in sets] for s in scores])
    print("\nleave-one-set-out selection (chosen on the other sets; acc and r/y/g recall):")
    for j, name in enumerate(sets):
        others = np.delete(balanced, j, axis=1).mean(axis=1)
        best = int(np.argmax(others))
        print(f"  {name:<12} {describe(scores[best][name])}  chosen {points[best]}")
    best = int(np.argmax(balanced.mean(axis=1)))
    print(f"best over all sets: {points[best]} mean balanced accuracy {balanced[best].mean():.3f}")


if __name__ == "__main__":
    main()
