"""Candidate recall of each paper detector (loosened) and of their ``union``, per set and size.

Candidate recall is the share of annotated lights with at least one candidate centre inside the
light's circle (Zheng 5.2.1's centre rule: the circle inscribed in the annotated box), before
any verifier: what a verifier can at best keep. Lights are binned by r = half the annotated
box's shorter side in px (for the housing-boxed sets, cinTA and DTLD, that is the housing's
half-width, about 1.2-1.5 lens radii). Also: candidates per frame and the detector's ms/frame.

The union's figures merge the members' cached candidates with the plugin's own
:func:`tsrkit_plugins.detectors.union.merge` (the members are not run twice).

Run: python benchmarks/candidate_recall.py [--out benchmarks/out/candidate_recall]
     python benchmarks/candidate_recall.py --quick --extra "lab-frst top=15 scale=2"
       (only the union's members, each --extra member alone, the union with it added and, for
       an extra whose detector is already a member, the union with that member replaced)
     python benchmarks/candidate_recall.py --tables benchmarks/out/candidate_recall/results.json
"""

from __future__ import annotations

import harness

harness.single_thread()

import argparse  # noqa: E402
import json  # noqa: E402
import time  # noqa: E402
from collections.abc import Iterable, Sequence  # noqa: E402
from pathlib import Path  # noqa: E402

import numpy as np  # noqa: E402

from tsrkit.datasets import open_datasets  # noqa: E402
from tsrkit.eval.matching import centre_hits  # noqa: E402
from tsrkit.params import parse_parts  # noqa: E402
from tsrkit.registry import get_registry  # noqa: E402
from tsrkit.types import Candidate, Sample  # noqa: E402
from tsrkit_plugins.detectors.union import (  # noqa: E402
    DEFAULT_MEMBERS,
    merge,
)

SETS = {
    "KR": "roboflow_traffic_light_kr:test",
    "cinTA": "roboflow_cinta_v2_id:test",
    "DTLD": "dtld_fridtjofs:test",
    "synthetic": "sample:test",
}
#: Size bins of r (px), down to lenses of 2-3 px.
SIZE_BINS = ((0, 2), (2, 3), (3, 4), (4, 6), (6, 12), (12, float("inf")))


def bin_label(low: float, high: float) -> str:
    """``r<2``, ``2-3``, ..., ``r>=12``."""
    if low == 0:
        return f"r<{high:g}"
    return f"r>={low:g}" if high == float("inf") else f"{low:g}-{high:g}"


def recall_by_size(
    samples: Sequence[Sample], candidates: Iterable[Sequence[Candidate]]
) -> dict[str, list]:
    """``{"all": [share, count], bin label: [share, count], ...}`` of ``samples``' lights with a
    candidate centre in their circle."""
    found_r: list[tuple[float, bool]] = []
    for sample, cands in zip(samples, candidates):
        boxes = [a.bbox for a in sample.annotations]
        if not boxes:
            continue
        points = [(c.x, c.y) for c in cands]
        found = centre_hits(points, boxes).any(axis=0) if points else np.zeros(len(boxes), bool)
        found_r += [(min(b[2] - b[0], b[3] - b[1]) / 2, bool(f)) for b, f in zip(boxes, found)]
    out: dict[str, list] = {}
    for label, keep in [("all", lambda r: True)] + [
        (bin_label(lo, hi), lambda r, lo=lo, hi=hi: lo <= r < hi) for lo, hi in SIZE_BINS
    ]:
        hits = [f for r, f in found_r if keep(r)]
        out[label] = [float(np.mean(hits)) if hits else None, len(hits)]
    return out


def run_detector(name: str, params: dict, samples: Sequence[Sample]):
    """Candidates of every sample and the median ms per frame."""
    detector = get_registry().create("detector", "union", {"members": detector_key(name, params)})
    detector = detector.members[0]
    found, times = [], []
    for sample in samples:
        frame = sample.load()
        start = time.perf_counter()
        found.append(detector.detect(frame))
        times.append(time.perf_counter() - start)
    return found, 1000 * float(np.median(times))


def detector_key(name: str, params: dict) -> str:
    return " ".join([name] + [f"{k}={v}" for k, v in params.items()])


def union_variants(members: list, extras: list) -> list[tuple[str, list]]:
    """The unions to score: the default one, with gray-tophat, and with each extra member added
    (and replacing the member of the same detector, when there is one)."""
    variants = [
        ("union", members),
        ("union + gray-tophat", members + [("gray-tophat", {"n_top": "15"})]),
    ]
    for name, values in extras:
        label = detector_key(name, values)
        variants.append((f"union + {label}", members + [(name, values)]))
        if any(n == name for n, _ in members):
            swapped = [(name, values) if n == name else (n, v) for n, v in members]
            variants.append((f"union, {name} -> {label}", swapped))
    return variants


def measure(extras: list, quick: bool) -> dict:
    members = parse_parts(DEFAULT_MEMBERS)
    configs = [] if quick else [(name, {}) for name in ("lab-frst", "conspicuity", "gray-tophat")]
    configs += [] if quick else [("adaboost-hsv", {}), ("tl-recognizer", {})]
    configs += [(n, v) for n, v in members if v or quick] + [("gray-tophat", {"n_top": "15"})]
    configs += extras
    results: dict = {"members": DEFAULT_MEMBERS, "sets": {}}
    for key, ref in SETS.items():
        samples = list(open_datasets([ref]).samples)
        rows: dict = {}
        cached: dict = {}
        for name, params in configs:
            found, ms = run_detector(name, params, samples)
            label = detector_key(name, params)
            cached[label] = (found, ms)
            rows[label] = {
                "recall": recall_by_size(samples, found),
                "per_frame": float(np.mean([len(f) for f in found])),
                "ms": round(ms, 1),
            }
            print(key, label, rows[label]["recall"]["all"], round(ms, 1), flush=True)
        for union_name, member_list in union_variants(members, extras):
            parts = [cached[detector_key(n, v)] for n, v in member_list]
            merged = [merge(list(lists), 1.0, 3.0) for lists in zip(*(p[0] for p in parts))]
            rows[union_name] = {
                "recall": recall_by_size(samples, merged),
                "per_frame": float(np.mean([len(f) for f in merged])),
                "ms": round(sum(p[1] for p in parts), 1),
            }
            print(key, union_name, rows[union_name]["recall"]["all"], flush=True)
        results["sets"][key] = rows
    return results


def _f(value) -> str:
    return "n/a" if value is None else f"{value:.2f}"


def markdown(results: dict) -> str:
    """One Markdown table per set: recall overall and per size bin, candidates/frame, ms."""
    labels = ["all"] + [bin_label(lo, hi) for lo, hi in SIZE_BINS]
    lines = [f"union members: `{results['members']}` (merge 1.0 radii, min 3 px)", ""]
    for key, rows in results["sets"].items():
        counts = next(iter(rows.values()))["recall"]
        lines += [
            f"**{key}** (lights per bin: " + ", ".join(f"{b} {counts[b][1]}" for b in labels) + ")",
            "",
            "| detector | " + " | ".join(labels) + " | cand./frame | ms/frame |",
            "|---|" + "---:|" * (len(labels) + 2),
        ]
        for name, row in rows.items():
            cells = [_f(row["recall"][b][0]) for b in labels]
            lines.append(
                f"| {name} | " + " | ".join(cells) + f" | {row['per_frame']:.1f} | {row['ms']} |"
            )
        lines.append("")
    return "\n".join(lines)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", default="benchmarks/out/candidate_recall")
    parser.add_argument("--tables", metavar="RESULTS_JSON", help="only print the tables")
    parser.add_argument(
        "--extra",
        action="append",
        default=[],
        metavar="MEMBER",
        help="a further union member, e.g. 'lab-frst top=15 scale=2' (repeatable)",
    )
    parser.add_argument(
        "--quick", action="store_true", help="skip the detectors at their paper defaults"
    )
    args = parser.parse_args()
    harness.announce()
    if args.tables:
        print(markdown(json.loads(Path(args.tables).read_text())))
        return
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    extras = [member for text in args.extra for member in parse_parts(text)]
    results = measure(extras, args.quick)
    (out / "results.json").write_text(json.dumps(results, indent=1))
    print(markdown(results))


if __name__ == "__main__":
    main()
