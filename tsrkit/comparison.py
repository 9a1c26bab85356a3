"""``compare``: several detectors benchmarked on the same frames, side by side, tested pairwise.

Each run writes its folder ``OUT/<detector>/``; ``OUT/compare.json`` and ``OUT/compare.md`` hold
the reports side by side and, for every pair, a Wilcoxon signed-rank test on per-frame recall
over the ground-truth frames both evaluated.
"""

from __future__ import annotations

import os
from collections.abc import Sequence
from pathlib import Path
from typing import Any

from tsrkit.atomic import atomic_open, write_json
from tsrkit.benchmarking import run_benchmark
from tsrkit.engine import BenchmarkError
from tsrkit.eval.perframe import frame_score
from tsrkit.eval.stats import paired_test
from tsrkit.plugin import Classifier, Detector
from tsrkit.report import HEADLINE, RunResult, fmt, headline, markdown_table, title
from tsrkit.types import Dataset


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


def compare(
    dataset: Dataset,
    detectors: Sequence[Detector],
    classifier: Classifier | None = None,
    *,
    out: str | os.PathLike | None = None,
    **options: Any,
) -> dict[str, Any]:
    """Benchmark several detectors on the same frames and test each pair.

    Other keyword options are those of :func:`tsrkit.benchmarking.benchmark` (``verifier=``,
    ``box=``, ``workers=``...). Returns ``{"dataset", "detectors", "reports", "paired_tests"}``.
    """
    names = [d.name for d in detectors]
    if len(set(names)) != len(names) or len(names) < 2:
        raise BenchmarkError(f"compare needs at least two different detectors; got {names}")
    runs = [
        run_benchmark(
            dataset,
            detector,
            classifier,
            out=Path(out) / detector.name if out is not None else None,
            **options,
        )
        for detector in detectors
    ]
    comparison = {
        "dataset": dataset.name,
        "detectors": names,
        "reports": [run.report for run in runs],
        "paired_tests": paired_tests(names, runs),
    }
    if out is not None:
        write_compare(Path(out), comparison)
    return comparison


def compare_markdown(comparison: dict) -> str:
    """compare.md: the side-by-side headline table and the paired tests."""
    reports = comparison["reports"]
    lines = [
        f"# Comparison on {comparison['dataset']}",
        "",
        markdown_table(
            ["method"] + [label for _, _, label, _ in HEADLINE],
            [[title(r)] + list(headline(r).values()) for r in reports],
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
                    fmt(t["p_value"]),
                    t["verdict"],
                ]
                for t in comparison["paired_tests"]
            ],
        )
    )
    return "\n".join(lines) + "\n"


def write_compare(out: Path, comparison: dict) -> None:
    """compare.json and compare.md in ``out``."""
    write_json(out / "compare.json", comparison)
    with atomic_open(out / "compare.md") as fh:
        fh.write(compare_markdown(comparison))
