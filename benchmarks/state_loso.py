"""lamp-state across cameras: leave-one-dataset-out and in-domain accuracy and red recall, with
the paper classifiers (ab-hist, hsi-backprojection, as shipped) on the same lights.

Training follows ``lamp-state``'s fit: its default parameters (colour-jittered copies
included), the lights of the training parts only; test lights are not jittered.

Sets: MIT crops (train / test), VGIS bulb crops day and night (deduplicated by sha256, first
occurrence kept, as the datasets README asks), KR (test + valid), cinTA (test + valid), DTLD
(train / test). Leave-one-dataset-out trains on every other dataset (their train parts: MIT
train, all VGIS, all KR, all cinTA, DTLD train) and tests on the held-out one; in-domain adds
the held-out dataset's own train part (MIT train, KR valid, cinTA valid, DTLD train) and tests
on its test split. Features are computed once per light. A late fusion (the equal-weight mean
of lamp-state's LOSO probabilities and ab-hist's normalised scores) is measured beside both;
ab-hist there is the shipped model, trained on MIT train. lamp-state's red+amber rule
(``red_yellow_ratio``, on housings and on boxes taller than wide too square to be read as
housings, as its ``classify`` reads them) and its red prior (``red_prior``) apply to all three.

    python benchmarks/state_loso.py [--seed N] [--colour-weight W]

``--seed`` (default 0, the shipped model's) seeds the colour jitter of the training copies and
the boosting: a change of lamp-state's outputs is judged against the spread of several seeds,
as one light can move a set's figures.
``--colour-weight`` sets lamp-state's ``colour_weight`` (its colour model's share; 0 reads the
full model alone, as before the colour model).
"""

from __future__ import annotations

import harness

harness.single_thread(opencv=False)

import argparse  # noqa: E402
import hashlib  # noqa: E402
import time  # noqa: E402
from collections import Counter  # noqa: E402

import numpy as np  # noqa: E402

from tsrkit.datasets import open_dataset  # noqa: E402
from tsrkit.registry import get_registry  # noqa: E402
from tsrkit.types import Candidate, Dataset  # noqa: E402
from tsrkit_plugins.classifiers.lamp_state import (  # noqa: E402
    STATES,
    blend,
    fit_colour,
    fit_estimator,
    labelled_features,
    learned_probability,
    prefer_red,
    red_yellow,
)
from tsrkit_plugins.classifiers.lamp_state.features import (  # noqa: E402
    lamp_features,
    red_amber_rows,
)


def deduplicated(dataset: Dataset, lighting: str) -> Dataset:
    """VGIS crops of one lighting, each distinct file once (first occurrence)."""
    seen, kept = set(), []
    for sample in dataset:
        with open(sample.source, "rb") as fh:
            digest = hashlib.sha256(fh.read()).hexdigest()
        if sample.metadata.get("lighting") == lighting and digest not in seen:
            kept.append(sample)
        seen.add(digest)
    return Dataset(f"vgis {lighting}", tuple(kept), dataset.format, dataset.root, dataset.info)


def parts() -> dict[str, dict[str, Dataset]]:
    """Per dataset: its ``train`` part (used when the dataset trains) and ``test`` sets."""
    mit = open_dataset("udacity_mit_tl_crops")
    vgis = open_dataset("lisa_vgis_bulb_crops")
    kr = open_dataset("roboflow_traffic_light_kr")
    cinta = open_dataset("roboflow_cinta_v2_id")
    dtld = open_dataset("dtld_fridtjofs")
    day, night = deduplicated(vgis, "day"), deduplicated(vgis, "night")
    both = Dataset("vgis", day.samples + night.samples, vgis.format, vgis.root, vgis.info)
    return {
        "mit": {
            "train": mit.split("train"),
            "own": mit.split("train"),
            "mit test": mit.split("test"),
        },
        "vgis": {"train": both, "vgis day": day, "vgis night": night},
        "kr": {"train": kr, "own": kr.split("valid"), "kr": kr, "kr test": kr.split("test")},
        "cinta": {
            "train": cinta,
            "own": cinta.split("valid"),
            "cinta": cinta,
            "cinta test": cinta.split("test"),
        },
        "dtld": {
            "train": dtld.split("train"),
            "own": dtld.split("train"),
            "dtld test": dtld.split("test"),
        },
    }


def scores(truth: np.ndarray, predicted: list[str]) -> tuple[float, float, int]:
    """Accuracy, red recall and count over lights whose true state is in :data:`STATES`."""
    names = [STATES[i] for i in truth]
    right = sum(t == p for t, p in zip(names, predicted))
    reds = [p for t, p in zip(names, predicted) if t == "red"]
    red = sum(p == "red" for p in reds) / len(reds) if reds else float("nan")
    return right / max(len(names), 1), red, len(names)


def paper(name: str, dataset: Dataset) -> tuple[list[str], np.ndarray]:
    """A shipped classifier's states of the lights of ``dataset`` and its scores, one column
    per state of :data:`STATES` (0 for states it does not score)."""
    classifier = get_registry().create("classifier", name)
    out, rows = [], []
    for sample in dataset:
        boxes = wanted_boxes(sample)
        if boxes:
            found = classifier.classify(sample.load(), boxes)
            out += [d.state for d in found]
            rows += [[d.state_scores.get(s, 0.0) for s in STATES] for d in found]
    return out, np.array(rows, np.float64).reshape(-1, len(STATES))


def wanted_boxes(sample) -> list[Candidate]:
    """The annotated lights of ``sample`` whose state is in :data:`STATES`, as candidates."""
    return [Candidate.from_box(a.bbox, 1.0) for a in sample.annotations if a.state in STATES]


def rule_rows(dataset: Dataset, features: np.ndarray) -> np.ndarray:
    """The ``features`` of the lights of ``dataset`` (in order, no copies) as lamp-state's
    red+amber rule reads them (:func:`red_amber_rows`: squarer boxes' two lamps too)."""
    out, start = [], 0
    for sample in dataset:
        boxes = wanted_boxes(sample)
        if boxes:
            rows = features[start : start + len(boxes)]
            out.append(red_amber_rows(sample.load().image, boxes, rows))
            start += len(boxes)
    return np.concatenate(out)


def read(probability: np.ndarray, states: list[str], rule: np.ndarray, params) -> list[str]:
    """lamp-state's reading of its learned ``probability`` (columns ``states``), with its
    red+amber rule (:func:`red_yellow`) on the ``rule`` rows (:func:`rule_rows`)."""
    table = blend(probability, states, np.zeros((len(probability), len(STATES))), 0.0)
    table = red_yellow(table, rule, params["red_yellow_ratio"])
    return [STATES[i] for i in np.argmax(table, axis=1)]


def learned(train: list[tuple[np.ndarray, np.ndarray]], x: np.ndarray, params):
    """lamp-state's probabilities of ``x`` (red prior applied) by the full and the colour model
    fitted on the ``train`` parts, and the states they know."""
    features = np.concatenate([t[0] for t in train])
    labels = np.concatenate([t[1] for t in train])
    estimator, states = fit_estimator(features, labels, params)
    colour = fit_colour(features, labels, params)
    probability = learned_probability(estimator, colour, x, params["colour_weight"])
    return prefer_red(probability, states, params["red_prior"]), states


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seed", type=int, default=0, help="jitter and boosting seed")
    parser.add_argument(
        "--colour-weight",
        type=float,
        default=None,
        help="lamp-state's colour_weight (default: its own)",
    )
    args = parser.parse_args()
    harness.announce()
    chosen = {"seed": args.seed}
    if args.colour_weight is not None:
        chosen["colour_weight"] = args.colour_weight
    params = get_registry().create("classifier", "lamp-state", chosen).params
    data = parts()
    copies = params["copies"]
    features = {
        (group, key): labelled_features(
            ds, copies if key in ("train", "own") else 0, seed=params["seed"]
        )
        for group, sets in data.items()
        for key, ds in sets.items()
    }
    print(
        "lights:",
        {f"{g}/{k}": len(v[1]) for (g, k), v in features.items() if k not in ("train", "own")},
    )
    rows = []
    for group, sets in data.items():
        for key, dataset in sets.items():
            if key in ("train", "own"):
                continue
            x, y = features[(group, key)]
            rule = rule_rows(dataset, x)
            others = [features[(g, "train")] for g in data if g != group]
            probability, states = learned(others, x, params)
            predicted = read(probability, states, rule, params)
            row = {"set": key, "n": len(y), "loso": scores(y, predicted)[:2]}
            if "own" in sets and key.endswith("test"):
                own_probability, own_states = learned(
                    others + [features[(group, "own")]], x, params
                )
                found = read(own_probability, own_states, rule, params)
                row["in-domain"] = scores(y, found)[:2]
            for name in ("ab-hist", "hsi-backprojection"):
                found, found_scores = paper(name, dataset)
                row[name] = scores(y, found)[:2]
                if name == "ab-hist":
                    mixed = blend(probability, states, found_scores, 0.5)
                    mixed = red_yellow(mixed, rule, params["red_yellow_ratio"])
                    row["fused"] = scores(y, [STATES[i] for i in np.argmax(mixed, axis=1)])[:2]
            row["truth"] = dict(Counter(STATES[i] for i in y))
            pairs = zip((STATES[i] for i in y), predicted)
            row["loso misread"] = dict(Counter(f"{t}>{p}" for t, p in pairs if t != p))
            rows.append(row)
            print(row, flush=True)
    print()
    print(
        "| set | lights | lamp-state LOSO acc / red recall | lamp-state in-domain "
        "| lamp-state LOSO + ab-hist (mean) | ab-hist | hsi-backprojection |"
    )
    print("|---|---:|---|---|---|---|---|")

    def pair(v):
        return "-" if v is None else f"{v[0]:.3f} / {v[1]:.3f}"

    for row in rows:
        print(
            f"| {row['set']} | {row['n']} | {pair(row['loso'])} | {pair(row.get('in-domain'))} | "
            f"{pair(row['fused'])} | {pair(row['ab-hist'])} | {pair(row['hsi-backprojection'])} |"
        )
    for column in ("loso", "fused", "ab-hist", "hsi-backprojection"):
        values = [row[column][0] for row in rows if row["set"] not in ("kr test", "cinta test")]
        print(f"{column}: mean {np.mean(values):.3f}, worst {min(values):.3f} over the six sets")
    frame = open_dataset("roboflow_cinta_v2_id").samples[0].load()
    candidates = [Candidate.from_box((10 + 8 * i, 20, 30 + 8 * i, 80), 1.0) for i in range(50)]
    start = time.perf_counter()
    for _ in range(20):
        lamp_features(frame.image, candidates)
    feature_ms = (time.perf_counter() - start) / 20 * 1000
    print(f"\nspeed, one thread, 50 housing candidates: features {feature_ms:.2f} ms")
    for name, params in (
        ("lamp-state", {}),
        ("lamp-state", {"ab_hist_weight": 0.5}),
        ("ab-hist", {}),
    ):
        classifier = get_registry().create("classifier", name, params)
        classifier.classify(frame, candidates)
        start = time.perf_counter()
        for _ in range(20):
            classifier.classify(frame, candidates)
        print(f"classify {name} {params}: {(time.perf_counter() - start) / 20 * 1000:.2f} ms")


if __name__ == "__main__":
    main()
