"""``compare``: several detectors benchmarked on the same frames, side by side, tested pairwise.

Each run writes its folder ``OUT/<run>/``; ``OUT/compare.json`` and ``OUT/compare.md`` hold
the reports side by side, for every pair a Wilcoxon signed-rank test on per-frame recall over
the ground-truth frames both evaluated, and every run's AP50 on the lens box and on the housing
box. With ``without_verifier`` each detector runs twice, with and without the verifier, so the
paired tests show what the verifier adds.
"""

from __future__ import annotations

import contextlib
import os
from collections.abc import Sequence
from pathlib import Path
from typing import Any

from tsrkit.core.atomic import atomic_open, write_json
from tsrkit.core.results import fmt
from tsrkit.core.types import Dataset
from tsrkit.eval.coco import coco_ap, coco_run
from tsrkit.eval.perframe import frame_score
from tsrkit.eval.stats import format_p, paired_test
from tsrkit.plugin.base import Classifier, Detector, Verifier
from tsrkit.reporting.benchmarking import run_benchmark
from tsrkit.reporting.report import RunResult, headline_rows, markdown_table, title
from tsrkit.runner.engine import BenchmarkError
from tsrkit.runner.outlock import locked

__all__ = [
    "box_ap50",
    "compare",
    "compare_markdown",
    "compare_runs",
    "frame_recalls",
    "paired_tests",
    "verifier_tests",
    "write_compare",
]


def frame_recalls(run: RunResult) -> dict[int, float]:
    """Zheng 5.2.1 recall of every evaluated ground-truth frame, by dataset position."""
    scores = {record.index: frame_score(sample, record) for sample, record in run.pairs()}
    return {index: s.recall for index, s in scores.items() if s.recall is not None}


def paired_tests(names: Sequence[str], runs: Sequence[RunResult]) -> list[dict[str, Any]]:
    """A Wilcoxon signed-rank test on per-frame recall for every pair of runs, over the
    ground-truth frames both evaluated."""
    recalls = [frame_recalls(run) for run in runs]
    tests = []
    for a in range(len(runs)):
        for b in range(a + 1, len(runs)):
            common = sorted(recalls[a].keys() & recalls[b].keys())
            test = paired_test(
                [recalls[a][i] for i in common], [recalls[b][i] for i in common], names[a], names[b]
            )
            tests.append({"a": names[a], "b": names[b], "metric": "per-frame recall", **test})
    return tests


def verifier_tests(without: RunResult, with_it: RunResult, a: str, b: str) -> list[dict[str, Any]]:
    """What a verifier changes on the same frames: Wilcoxon signed-rank tests of per-frame
    recall, precision (frames with detections in both runs) and false positives (fewer is
    better; exhaustively labelled datasets only) of run ``b`` (with) against ``a`` (without)."""
    left = {r.index: frame_score(s, r) for s, r in without.pairs()}
    right = {r.index: frame_score(s, r) for s, r in with_it.pairs()}
    common = sorted(left.keys() & right.keys())
    measures = {
        "per-frame recall": lambda f: f.recall,
        "per-frame precision": lambda f: f.precision if f.n_gt else None,
        "false positives per frame (negated: higher is fewer)": lambda f: -(f.n_det - f.det_tp),
    }
    exhaustive = (without.report.get("iou50") or {}).get("ap") is not None
    tests = []
    for metric, value in measures.items():
        if metric != "per-frame recall" and not exhaustive:
            continue
        kept = [i for i in common if value(left[i]) is not None and value(right[i]) is not None]
        test = paired_test([value(right[i]) for i in kept], [value(left[i]) for i in kept], b, a)
        tests.append({"a": b, "b": a, "metric": metric, **test})
    return tests


def box_ap50(run: RunResult) -> dict[str, float | None]:
    """AP50 of a run on the lens box and on the housing box (``bbox``); None for both when
    the run's evaluation leaves AP out (a dataset not exhaustively labelled)."""
    if (run.report.get("iou50") or {}).get("ap") is None:
        return {"lens": None, "housing": None}
    pairs = list(run.pairs())
    return {
        box: coco_ap(*coco_run(run.report["dataset"], pairs, box))["ap50"]
        for box in ("lens", "housing")
    }


def compare(
    dataset: Dataset,
    detectors: Sequence[Detector],
    classifier: Classifier | None = None,
    *,
    out: str | os.PathLike | None = None,
    without_verifier: bool = False,
    **options: Any,
) -> dict[str, Any]:
    """Benchmark several detectors on the same frames and test each pair.

    Other keyword options are those of :func:`tsrkit.reporting.benchmarking.benchmark`
    (``verifier=``, ``box=``, ``workers=``...). With ``without_verifier`` (and a ``verifier``)
    every detector also runs without it, as ``DETECTOR`` beside ``DETECTOR+VERIFIER``. Returns
    ``{"dataset", "detectors", "runs", "reports", "paired_tests", "box_ap50"}``. The ``out``
    folder is locked for the whole comparison (:func:`tsrkit.runner.outlock.locked`).
    """
    names = [d.name for d in detectors]
    verifier = options.pop("verifier", None)
    ablate = without_verifier and verifier is not None
    if len(set(names)) != len(names) or len(names) < (1 if ablate else 2):
        raise BenchmarkError(f"compare needs at least two different detectors; got {names}")
    plan = [
        (f"{d.name}+{verifier.name}" if verifier is not None else d.name, d, verifier, classifier)
        for d in detectors
    ]
    if ablate:
        plan = [
            run
            for d, with_it in zip(detectors, plan)
            for run in ((d.name, d, None, classifier), with_it)
        ]
    return compare_runs(dataset, plan, out=out, pairs_of_two=ablate, **options)


Plan = tuple[str, Detector, Verifier | None, Classifier | None]


def compare_runs(
    dataset: Dataset,
    plan: Sequence[Plan],
    *,
    out: str | os.PathLike | None = None,
    pairs_of_two: bool = False,
    **options: Any,
) -> dict[str, Any]:
    """Benchmark each run of ``plan`` (label, detector, verifier, classifier: whole pipelines,
    such as two presets) on the same frames and test each pair. ``pairs_of_two``: the runs
    are pairs without and with a verifier (:func:`verifier_tests` on each pair). Other keyword
    options are those of :func:`tsrkit.reporting.benchmarking.benchmark`. The ``out`` folder
    is locked for the whole comparison (:func:`tsrkit.runner.outlock.locked`).
    """
    labels = [label for label, _, _, _ in plan]
    if len(set(labels)) != len(labels) or len(labels) < (1 if pairs_of_two else 2):
        raise BenchmarkError(f"compare needs at least two different runs; got {labels}")
    # the whole folder is this run's: a second compare into it refuses, naming the lock
    with locked(out) if out is not None else contextlib.nullcontext():
        runs = [
            run_benchmark(
                dataset,
                detector,
                classifier,
                out=Path(out) / label if out is not None else None,
                **{**options, "verifier": stage},
            )
            for label, detector, stage, classifier in plan
        ]
        comparison = {
            "dataset": dataset.name,
            "detectors": list(dict.fromkeys(d.name for _, d, _, _ in plan)),
            "runs": labels,
            "reports": [run.report for run in runs],
            "paired_tests": paired_tests(labels, runs),
            "box_ap50": [{"run": label, **box_ap50(run)} for label, run in zip(labels, runs)],
        }
        if pairs_of_two:
            comparison["verifier_tests"] = [
                test
                for k in range(0, len(runs), 2)
                for test in verifier_tests(runs[k], runs[k + 1], labels[k], labels[k + 1])
            ]
        if out is not None:
            write_compare(Path(out), comparison)
    return comparison


def compare_markdown(comparison: dict) -> str:
    """compare.md: the side-by-side headline table and the paired tests."""
    reports = comparison["reports"]
    columns, rows = headline_rows(reports)
    lines = [
        f"# Comparison on {comparison['dataset']}",
        "",
        markdown_table(
            ["method"] + [f.label for f in columns],
            [[title(r), *row] for r, row in zip(reports, rows)],
        ),
        "",
        "## Paired tests on the same frames (Wilcoxon signed-rank, per-frame recall)",
        "",
    ]
    lines.append(
        markdown_table(
            ["A", "B", "frames", "mean A - B", "p", "verdict"],
            [
                [
                    t["a"],
                    t["b"],
                    str(t["frames"]),
                    fmt(t["mean_difference"]),
                    format_p(t["p_value"]),
                    t["verdict"],
                ]
                for t in comparison["paired_tests"]
            ],
        )
    )
    if comparison.get("verifier_tests"):
        lines += [
            "",
            "## With vs without the verifier (Wilcoxon signed-rank on the same frames)",
            "",
            markdown_table(
                ["with", "without", "figure", "frames", "mean with - without", "p", "verdict"],
                [
                    [
                        t["a"],
                        t["b"],
                        t["metric"],
                        str(t["frames"]),
                        fmt(t["mean_difference"]),
                        format_p(t["p_value"]),
                        t["verdict"],
                    ]
                    for t in comparison["verifier_tests"]
                ],
            ),
        ]
    lines += [
        "",
        "## AP50 by evaluated box (pycocotools): the lens circle's box vs the housing",
        "",
        markdown_table(
            ["run", "lens AP50", "housing AP50"],
            [[b["run"], fmt(b["lens"]), fmt(b["housing"])] for b in comparison["box_ap50"]],
        ),
    ]
    return "\n".join(lines) + "\n"


def write_compare(out: Path, comparison: dict) -> None:
    """compare.json and compare.md in ``out``."""
    write_json(out / "compare.json", comparison)
    with atomic_open(out / "compare.md") as fh:
        fh.write(compare_markdown(comparison))
