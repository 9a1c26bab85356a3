"""How the recommended pipeline's keep decision should fuse the verifier's probability with the
union's agreement: held-out candidates dumped once, decision rules compared offline.

For each of KR, cinTA and DTLD, the verifier is trained on the two other sets' training splits
(as ``verifier_loso.py`` does, with the same parameters), and every candidate of the held-out
set's test split and of synthetic no-light frames is dumped after the housing stage: its
learned probability ``p``, the union's agreement ``a``, the box model's probability ``b``, its
Zheng label (centre in a ground-truth box's circle) and its frame. ``--rules`` then replays
keep decisions offline (threshold and the per-frame ``relative`` gate) for several fusion
rules, and prints Zheng hit / recall / precision / FP per frame on the held-out test split and
false lights per synthetic no-light frame, at every threshold.

Run: python benchmarks/fusion_study.py --out benchmarks/out/fusion        # dump (~10 min)
     python benchmarks/fusion_study.py --out benchmarks/out/fusion --rules  # tables
"""

from __future__ import annotations

import harness

harness.single_thread()

import argparse  # noqa: E402
from collections.abc import Callable  # noqa: E402
from pathlib import Path  # noqa: E402

import numpy as np  # noqa: E402
from verifier_loso import SETS, Memo, no_light_dataset  # noqa: E402

from tsrkit.datasets import open_datasets  # noqa: E402
from tsrkit.eval.matching import centre_hits  # noqa: E402
from tsrkit.registry import get_registry  # noqa: E402
from tsrkit.training import train  # noqa: E402
from tsrkit_plugins.verifiers.features import candidate_features  # noqa: E402
from tsrkit_plugins.verifiers.learned import passes  # noqa: E402

#: The recommended preset's verifier training parameters (tsrkit/presets/recommended.yaml).
TRAINING = {"after": "housing", "prior": 0.7, "box_rank": 0.5}
THRESHOLDS = (0.2, 0.25, 0.3, 0.35, 0.4, 0.5, 0.6)


def dump(samples, detector, verifier) -> dict[str, np.ndarray]:
    """Per-candidate arrays of ``samples`` (after the housing stage): p, a, b, label, frame,
    and per frame the number of annotated lights."""
    rows: dict[str, list] = {k: [] for k in ("p", "a", "b", "label", "frame")}
    lights = []
    for index, sample in enumerate(samples):
        frame = sample.load()
        truth = [a.bbox for a in sample.annotations]
        lights.append(len(truth))
        staged = verifier._stage()(frame, detector.detect(frame))
        if not staged:
            continue
        features = candidate_features(frame.image, staged)
        rows["p"].append(verifier.forest.probability(features))
        rows["b"].append(verifier.box_forest.probability(features))
        rows["a"].append(np.clip([c.score for c in staged], 0.0, 1.0))
        hits = centre_hits([(c.x, c.y) for c in staged], truth) if truth else None
        label = np.zeros((len(staged), max(len(truth), 1)), bool) if hits is None else hits
        # which light each candidate hits (-1: none), to count hit lights per frame
        rows["label"].append(np.where(label.any(axis=1), label.argmax(axis=1), -1))
        rows["frame"].append(np.full(len(staged), index))
    out = {k: np.concatenate(v) if v else np.zeros(0) for k, v in rows.items()}
    out["lights"] = np.asarray(lights)
    return out


def collect(out: Path) -> None:
    """Train the held-out verifiers and dump every fold's candidates to ``out``."""
    reg = get_registry()
    detector = Memo(reg.create("detector", "union"))
    nolight = no_light_dataset(30)
    for s in SETS:
        others = [f"{o.name}:{o.train}" for o in SETS if o.key != s.key]
        model = out / f"verifier_loso_{s.key}"
        if not (model.with_suffix(".npz")).exists():
            train("verifier", open_datasets(others), model, TRAINING, detector)
        verifier = reg.create("verifier", "verifier", {"model": str(model), **TRAINING})
        test = open_datasets([f"{s.name}:{s.test}"])
        for part, samples in (("test", test.samples), ("nolight", nolight.samples)):
            arrays = dump(samples, detector, verifier)
            np.savez(out / f"{s.key}_{part}.npz", **arrays)
            print(s.key, part, len(arrays["p"]), "candidates", flush=True)


Rule = Callable[[np.ndarray, np.ndarray, np.ndarray], np.ndarray]
RULES: dict[str, Rule] = {
    "preset 0.3p+0.7a": lambda p, a, b: 0.3 * p + 0.7 * a,
    "0.5p+0.5a": lambda p, a, b: 0.5 * p + 0.5 * a,
    "p alone": lambda p, a, b: p,
    "a alone": lambda p, a, b: a,
    "sqrt(p a)": lambda p, a, b: np.sqrt(p * a),
    "p^0.3 a^0.7": lambda p, a, b: p**0.3 * a**0.7,
    "(0.3p+0.7a) b^0.5": lambda p, a, b: (0.3 * p + 0.7 * a) * np.sqrt(b),
}


def figures(d: dict[str, np.ndarray], score: np.ndarray, t: float, relative: float) -> dict:
    """Zheng per-frame figures of the candidates that ``score`` keeps at ``t`` / ``relative``."""
    hit, recall, precision, fps = [], [], [], []
    for index, n in enumerate(d["lights"]):
        rows = np.flatnonzero(d["frame"] == index)
        keep = rows[passes(score[rows], t, relative)] if len(rows) else rows
        labels = d["label"][keep]
        tp = int(np.count_nonzero(labels >= 0))
        fps.append(len(keep) - tp)
        if n:
            found = len(np.unique(labels[labels >= 0]))
            hit.append(found > 0)
            recall.append(found / n)
            if len(keep):
                precision.append(tp / len(keep))
    return {
        "hit": np.mean(hit) if hit else np.nan,
        "recall": np.mean(recall) if recall else np.nan,
        "precision": np.mean(precision) if precision else np.nan,
        "fp": np.mean(fps),
    }


def tables(out: Path, relative: float) -> None:
    """Print, per rule and threshold, hit / recall / precision / FP per frame per held-out set
    and no-light false lights per frame (the mean over the three folds' models)."""
    data = {
        s.key: {part: dict(np.load(out / f"{s.key}_{part}.npz")) for part in ("test", "nolight")}
        for s in SETS
    }
    print(
        "| rule | t | " + " | ".join(f"{s.key} hit/rec/prec/FP" for s in SETS) + " | no-light FP |"
    )
    print("|---|---|" + "---|" * (len(SETS) + 1))
    for name, rule in RULES.items():
        for t in THRESHOLDS:
            cells, nolight = [], []
            for s in SETS:
                test, nl = data[s.key]["test"], data[s.key]["nolight"]
                f = figures(test, rule(test["p"], test["a"], test["b"]), t, relative)
                cells.append(
                    f"{f['hit']:.2f} / {f['recall']:.2f} / {f['precision']:.2f} / {f['fp']:.2f}"
                )
                nolight.append(figures(nl, rule(nl["p"], nl["a"], nl["b"]), t, relative)["fp"])
            print(f"| {name} | {t} | " + " | ".join(cells) + f" | {np.mean(nolight):.2f} |")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", default="benchmarks/out/fusion")
    parser.add_argument("--rules", action="store_true", help="only the tables of a finished dump")
    parser.add_argument("--relative", type=float, default=0.6, help="the per-frame gate")
    args = parser.parse_args()
    harness.announce()
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    if args.rules:
        tables(out, args.relative)
    else:
        collect(out)


if __name__ == "__main__":
    main()
