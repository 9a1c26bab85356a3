"""Leave-one-dataset-out evaluation of the learned verifier on the real detection sets.

For each of KR, cinTA and DTLD: train the ``verifier`` on the other sets' training splits (plus
synthetic no-light scenes), test the pipeline (candidate detector [+ housing stage] + verifier)
on the left-out set's test split; also in-domain (trained on the set's own training split).
Beside it, every paper detector alone, and the best of them. Figures: housing AP50 (lens AP50
on KR, whose boxes are mostly lenses), Zheng 5.2.1 per-frame recall / precision / hit-frame
fraction, false positives per frame (exhaustive sets only) and on synthetic no-light frames,
candidate recall per light size.

Run: python benchmarks/verifier_loso.py [--detector lab-frst]... [-p lab-frst.KEY=V]
         [-p verifier.KEY=V] [--housing housing] [--no-light 30] [--skip-paper]
         [--out benchmarks/out/verifier_loso]
Training-time augmentation (plugins/verifiers/augment.py): ``-p verifier.augment_scales=1,0.5,1.5``
``-p verifier.augment_colour=2``; the augmented views carry their own ``source``, so the cached
candidates below keep them apart.
Box-aware order (``-p verifier.box_rank=0.5``): the tables' thresholds and ``relative`` read each
detection's decision score, as the verifier's own keep decision does; AP50 reads the reported
score (the order). ``--box-weights 0,0.25,0.5 --out DIR`` re-reads the models a run left in DIR
and gives AP50 at each ``box_rank`` weight (which candidates are kept does not depend on it).
Several detectors: ``--detector union -p "union.members=lab-frst top=15; conspicuity n_top=15"``
(the ``union`` plugin; its default members are the loosened four of RESULTS.verifier.md).
"""

from __future__ import annotations

import harness

harness.single_thread()

import argparse  # noqa: E402
import json  # noqa: E402
import time  # noqa: E402
from dataclasses import dataclass, replace  # noqa: E402
from pathlib import Path  # noqa: E402

import numpy as np  # noqa: E402
from candidate_recall import SIZE_BINS, bin_label, recall_by_size  # noqa: E402

from tsrkit import (  # noqa: E402  # noqa: E402
    Dataset,
    Detector,
    Sample,
    Verifier,
    get_registry,
)
from tsrkit.api import (  # noqa: E402
    iou_matrix,
    open_datasets,
    parse_assignments,
)
from tsrkit.eval.perframe import score_frame  # noqa: E402
from tsrkit.reporting.benchmarking import run_benchmark  # noqa: E402
from tsrkit.runner.training import train  # noqa: E402
from tsrkit_plugins.verifiers.learned import LearnedVerifier, passes  # noqa: E402
from tsrkit_plugins.verifiers.mining import no_light_frames  # noqa: E402

PAPER = ("conspicuity", "gray-tophat", "lab-frst", "tl-recognizer", "adaboost-hsv")


@dataclass(frozen=True)
class RealSet:
    """A detection set: registry name, training and test splits, evaluated box, exhaustive."""

    key: str
    name: str
    train: str
    test: str
    box: str
    exhaustive: bool


SETS = (
    # The Roboflow sets ship test + valid only (their train splits are augmented copies):
    # valid is the training split here.
    RealSet("KR", "roboflow_traffic_light_kr", "valid", "test", "lens", True),
    RealSet("cinTA", "roboflow_cinta_v2_id", "valid", "test", "housing", True),
    RealSet("DTLD", "dtld_fridtjofs", "train", "test", "housing", False),
)
LABELS = [bin_label(lo, hi) for lo, hi in SIZE_BINS]
THRESHOLDS = (0.1, 0.2, 0.25, 0.3, 0.4, 0.5, 0.6, 0.7, 0.8, 0.9)


class Memo(Detector):
    """A detector whose candidates are computed once per image (the folds share frames)."""

    def __init__(self, inner: Detector):
        super().__init__(**inner.params)
        self.inner = inner
        self.name = inner.name  # type: ignore[misc]
        self._seen: dict[str, list] = {}

    def detect(self, frame):
        key = f"{frame.source}#{frame.index}"
        if key not in self._seen:
            self._seen[key] = self.inner.detect(frame)
        return self._seen[key]


class Chain(Verifier):
    """Verifiers applied in turn (the housing stage, then the learned verifier)."""

    name = "chain"

    def __init__(self, stages):
        super().__init__()
        self.stages = stages

    def verify(self, frame, candidates):
        for stage in self.stages:
            candidates = stage.verify(frame, candidates) if candidates else []
        return candidates


class Decided(Verifier):
    """The learned verifier keeping every candidate (its threshold 0), remembering each kept
    candidate's decision score (:meth:`LearnedVerifier.scores`) by source, centre and reported
    score, so that the tables' thresholds read what the verifier's keep decision reads."""

    name = "decided"

    def __init__(self, inner: LearnedVerifier):
        super().__init__()
        self.inner = inner
        self.decisions: dict[tuple, float] = {}

    def verify(self, frame, candidates):
        if not candidates:
            return []
        staged, decision, score = self.inner.scores(frame, candidates)
        for c, d, s in zip(staged, decision, score):
            self.decisions[self.key(frame.source, c.x, c.y, float(s))] = float(d)
        kept = [replace(c, score=float(s)) for c, s in zip(staged, score)]
        return sorted(kept, key=lambda c: -c.score)

    @staticmethod
    def key(source, x, y, score) -> tuple:
        return source, round(x, 3), round(y, 3), score

    def decision(self, record, detection) -> float:
        """The decision score of one of ``record``'s detections."""
        key = self.key(record.source, detection.x, detection.y, detection.score)
        return self.decisions[key]


def no_light_dataset(count: int) -> Dataset:
    """Synthetic 1280x720 scenes without a lit light (another seed than training's)."""
    samples = tuple(
        Sample(f.source, (), f.width, f.height, "test", image=f.image)
        for f in no_light_frames(count, seed=2024)
    )
    return Dataset("synthetic-no-light", samples, info={"box": "housing"})


def evaluate(dataset, detector, verifier, box, thresholds=(0.0,), relative=0.0):
    """One run (verifier threshold 0); Zheng figures and the share of lights some kept box
    overlaps at IoU >= 0.5 (``iou50_recall``, the set's ``box``) recomputed at every threshold
    (with the verifier's ``relative`` gate: :func:`passes`; on the decision scores where the
    verifier is :class:`Decided`)."""
    run = run_benchmark(dataset, detector, verifier=verifier, cache=False, box=box)
    ap = run.report["iou50"]["ap"]
    pairs = list(run.pairs())
    rows = {}
    for t in thresholds:
        scores, box_hits = [], []
        for sample, record in pairs:
            decide = verifier.decision if isinstance(verifier, Decided) else None
            decisions = [decide(record, d) if decide else d.score for d in record.detections]
            keep = passes(decisions, t, relative)
            kept = [d for d, k in zip(record.detections, keep) if k]
            truth = [a.bbox for a in sample.annotations]
            scores.append(score_frame([(d.x, d.y) for d in kept], truth))
            if truth:
                boxes = [d.bbox if box == "housing" else d.lens_bbox for d in kept]
                overlap = iou_matrix(truth, boxes) if boxes else np.zeros((len(truth), 1))
                box_hits += list(overlap.max(axis=1) >= 0.5)
        gt = [s for s in scores if s.n_gt]
        with_det = [s for s in gt if s.n_det]
        fps = [s.n_det - s.det_tp for s in scores]
        rows[t] = {
            "recall": float(np.mean([s.recall for s in gt])) if gt else None,
            "precision": float(np.mean([s.precision for s in with_det])) if with_det else None,
            "hit": float(np.mean([s.gt_hit > 0 for s in gt])) if gt else None,
            "fp_per_frame": float(np.mean(fps)) if fps else None,
            "det_per_frame": float(np.mean([s.n_det for s in scores])) if scores else None,
            "iou50_recall": float(np.mean(box_hits)) if box_hits else None,
        }
    return ap, rows, pairs


def candidate_recall(pairs) -> dict:
    """Share of annotated lights with a candidate centre in their circle, per lens radius."""
    pairs = list(pairs)
    return recall_by_size([p[0] for p in pairs], [p[1].detections for p in pairs])


def _f(value, spec=".2f") -> str:
    return "n/a" if value is None else format(value, spec)


def markdown(results: dict, threshold: str = "0.5") -> str:
    """The result tables (Markdown) of a results.json."""
    exhaustive = {s.key: s.exhaustive for s in SETS}
    boxes = {s.key: s.box for s in SETS}
    lines = [
        f"Candidates: {' + '.join(results['detector'])} "
        f"({' '.join(results['params']) or 'defaults'})"
        f"{', housing: ' + results['housing'] if results['housing'] else ''}; verifier threshold "
        f"{threshold}, relative {results.get('relative', 0.0)}. FP/frame: detections outside "
        "every ground-truth circle (exhaustive sets only); no-light: synthetic 1280x720 "
        "scenes without a lit light.",
        "",
        "| test set | pipeline | AP50 (box) | recall IoU.5 | recall | hit | precision | FP/frame "
        "| no-light FP/frame |",
        "|---|---|---|---|---|---|---|---|---|",
    ]
    for key, fold in results["folds"].items():
        c = fold["candidates"]
        rows = [("candidates alone", c, c["ap50"])]
        rows += [
            (f"+ verifier, {mode}", fold[mode]["by_threshold"][threshold], fold[mode]["ap50"])
            for mode in ("loso", "in-domain")
        ]
        paper = results.get("paper", {}).get(key, {})
        if paper:
            best = max(paper, key=lambda n: (paper[n]["hit"], paper[n]["recall"]))
            rows.append((f"best paper detector: {best}", paper[best], paper[best]["ap50"]))
        for label, r, ap in rows:
            lines.append(
                f"| {key} | {label} | {_f(ap)} ({boxes[key]}) | {_f(r.get('iou50_recall'))}"
                f" | {_f(r['recall'])} | {_f(r['hit'])}"
                f" | {_f(r['precision'] if exhaustive[key] else None)}"
                f" | {_f(r['fp_per_frame'] if exhaustive[key] else None)} | {_f(r['nolight_fp'])} |"
            )
    lines += [
        "",
        "Candidate recall (share of annotated lights with a candidate centre in their circle) "
        "by lens radius r = half the box's shorter side, px (count):",
        "",
        "| test set | all | " + " | ".join(LABELS) + " |",
        "|---|---|" + "---|" * len(LABELS),
    ]
    for key, fold in results["folds"].items():
        cr = fold["candidates"]["candidate_recall"]
        cells = [f"{_f(cr[b][0])} ({cr[b][1]})" for b in LABELS]
        lines.append(f"| {key} | {_f(cr['all'][0])} ({cr['all'][1]}) | " + " | ".join(cells) + " |")
    return "\n".join(lines) + "\n"


def box_weights(out: Path, weights: list[float]) -> str:
    """AP50 (Markdown table) of the verifier models of the finished run in ``out`` on the
    exhaustive sets' test splits, their reported scores ordered at each ``box_rank`` weight."""
    results = json.loads((out / "results.json").read_text())
    assigned = parse_assignments(results["params"])
    (name,) = results["detector"]
    detector = Memo(
        get_registry().create(
            "detector",
            name,
            {k.split(".", 1)[1]: v for k, v in assigned.items() if k.startswith(f"{name}.")},
        )
    )
    lines = [
        "| test set | verifier | " + " | ".join(f"w = {w:g}" for w in weights) + " |",
        "|---|---|" + "---:|" * len(weights),
    ]
    for s in (s for s in SETS if s.exhaustive):
        test = open_datasets([f"{s.name}:{s.test}"])
        for mode in ("loso", "in-domain"):
            cells = []
            for w in weights:
                verifier = get_registry().create(
                    "verifier",
                    "verifier",
                    {
                        "model": str(out / f"verifier_{mode}_{s.key}"),
                        "threshold": 0.0,
                        "after": results["housing"],
                        "prior": assigned.get("verifier.prior", 0.0),
                        "box_rank": w,
                    },
                )
                ap, _, _ = evaluate(test, detector, Decided(verifier), s.box)
                cells.append(f"{ap:.3f}")
            lines.append(f"| {s.key} ({s.box}) | {mode} | " + " | ".join(cells) + " |")
    return "\n".join(lines)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--detector", action="append", default=[], help="candidate detector")
    parser.add_argument(
        "-p", "--param", action="append", default=[], help="DETECTOR.KEY=V / verifier.KEY=V"
    )
    parser.add_argument("--housing", default="", help="housing verifier run before the verifier")
    parser.add_argument("--no-light", type=int, default=30, help="synthetic no-light test frames")
    parser.add_argument("--out", default="benchmarks/out/verifier_loso")
    parser.add_argument("--skip-paper", action="store_true", help="no paper-detector baselines")
    parser.add_argument(
        "--paper-from",
        metavar="RESULTS_JSON",
        help="take the paper-detector baselines from an earlier run's results.json (they do "
        "not depend on the candidates or the verifier)",
    )
    parser.add_argument(
        "--tables", metavar="RESULTS_JSON", help="only print the Markdown tables of a results.json"
    )
    parser.add_argument("--threshold", default="0.5", help="verifier threshold of the tables")
    parser.add_argument(
        "--box-weights",
        metavar="W,W,...",
        help="only AP50 of the models of the finished run in --out at these box_rank weights",
    )
    args = parser.parse_args()
    harness.announce()
    if args.tables:
        results = json.loads(Path(args.tables).read_text())
        measured = next(iter(results["folds"].values()))["loso"]["by_threshold"]
        if args.threshold not in measured:
            parser.error(f"--threshold {args.threshold}: this run has {', '.join(measured)}")
        print(markdown(results, args.threshold))
        return
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    if args.box_weights:
        print(box_weights(out, [float(w) for w in args.box_weights.split(",")]))
        return
    reg = get_registry()
    assigned = parse_assignments(args.param)
    names = args.detector or ["lab-frst"]
    ver_params = {k[9:]: v for k, v in assigned.items() if k.startswith("verifier.")}
    ver_params["after"] = args.housing or ""
    relative = float(ver_params.pop("relative", 0.0))  # applied to the records, like thresholds
    members = [
        reg.create(
            "detector",
            name,
            {k.split(".", 1)[1]: v for k, v in assigned.items() if k.startswith(f"{name}.")},
        )
        for name in names
    ]
    if len(members) != 1:
        parser.error("one --detector (several: the union detector)")
    detector = Memo(members[0])
    housing = [reg.create("verifier", args.housing)] if args.housing else []
    tests = {s.key: open_datasets([f"{s.name}:{s.test}"]) for s in SETS}
    nolight = no_light_dataset(args.no_light)
    started = time.perf_counter()
    results: dict = {
        "detector": names,
        "params": args.param,
        "housing": args.housing,
        "relative": relative,
    }

    if args.paper_from:
        results["paper"] = json.loads(Path(args.paper_from).read_text())["paper"]
    elif not args.skip_paper:
        paper: dict = {}
        for s in SETS:
            for name in PAPER:
                det = Memo(reg.create("detector", name))
                ap, rows, _ = evaluate(tests[s.key], det, None, s.box)
                _, nl, _ = evaluate(nolight, det, None, "housing")
                paper.setdefault(s.key, {})[name] = {
                    **rows[0.0],
                    "ap50": ap,
                    "nolight_fp": nl[0.0]["fp_per_frame"],
                }
                print(s.key, name, paper[s.key][name], flush=True)
        results["paper"] = paper

    folds: dict = {}
    for s in SETS:
        others = [f"{o.name}:{o.train}" for o in SETS if o.key != s.key]
        for mode, refs in (("loso", others), ("in-domain", [f"{s.name}:{s.train}"])):
            model = out / f"verifier_{mode}_{s.key}"
            t0 = time.perf_counter()
            train("verifier", open_datasets(refs), model, ver_params, detector)
            fit_s = time.perf_counter() - t0
            verifier = reg.create(
                "verifier",
                "verifier",
                {
                    "model": str(model),
                    "threshold": 0.0,
                    "after": ver_params["after"],
                    "prior": ver_params.get("prior", 0.0),
                    "box_rank": ver_params.get("box_rank", 0.0),
                },
            )
            # the verifier runs its `after` stage (housing) itself
            ap, rows, pairs = evaluate(
                tests[s.key], detector, Decided(verifier), s.box, THRESHOLDS, relative
            )
            _, nl, _ = evaluate(
                nolight, detector, Decided(verifier), "housing", THRESHOLDS, relative
            )
            folds.setdefault(s.key, {})[mode] = {
                "train": refs,
                "fit_seconds": round(fit_s, 1),
                "ap50": ap,
                "by_threshold": {
                    str(t): {**rows[t], "nolight_fp": nl[t]["fp_per_frame"]} for t in THRESHOLDS
                },
            }
            print(s.key, mode, json.dumps(folds[s.key][mode])[:400], flush=True)
        ap, rows, pairs = evaluate(
            tests[s.key], detector, Chain(housing) if housing else None, s.box
        )
        _, nl, _ = evaluate(nolight, detector, Chain(housing) if housing else None, "housing")
        folds[s.key]["candidates"] = {
            **rows[0.0],
            "ap50": ap,
            "nolight_fp": nl[0.0]["fp_per_frame"],
            "candidate_recall": candidate_recall(pairs),
        }
        print(s.key, "candidates", folds[s.key]["candidates"], flush=True)
    results["folds"] = folds
    results["seconds"] = round(time.perf_counter() - started, 1)
    (out / "results.json").write_text(json.dumps(results, indent=1))
    print(markdown(results))
    print(f"wrote {out / 'results.json'} in {results['seconds']} s")


if __name__ == "__main__":
    main()
