"""Candidate recall of each paper detector (loosened) and of their ``union``, per set and size.

Candidate recall is the share of annotated lights with at least one candidate centre inside the
light's circle (Zheng 5.2.1's centre rule: the smallest circle enclosing the annotated box), before
any verifier: what a verifier can at best keep. Lights are binned by their lens radius r in px:
half the annotated box's shorter side on the lens-boxed sets (KR, synthetic), that divided by
:data:`HOUSING_PER_LENS` on the housing-boxed ones (cinTA, DTLD, Japan: a head's width across
is about 1.2-1.5 lens diameters); "r<=3" gathers the lenses of radius 3 px and less. Also:
candidates per frame and the detector's ms/frame (on each set's own frame size).

Sets: KR and cinTA test splits, DTLD, Japan (``iwai_japan_tl``, horizontal heads, not
exhaustively labelled, which does not matter for recall) and the synthetic sample whole (its
small lenses are few per split).

The union's figures merge the members' cached candidates with the plugin's own
:func:`tsrkit_plugins.detectors.union.merge` (the members are not run twice).

Run: python benchmarks/candidate_recall.py [--out benchmarks/out/candidate_recall] [--sets KR,DTLD]
     python benchmarks/candidate_recall.py --quick --extra "lab-frst top=15 scale=2"
       (only the union's members, each --extra member alone, the union with it added and, for
       an extra whose detector is already a member, the union with that member replaced)
     python benchmarks/candidate_recall.py --quick --members "lab-frst top=15; conspicuity"
       (another union in place of the preset's; --without NAME: the union without a member)
     python benchmarks/candidate_recall.py --tables benchmarks/out/candidate_recall/results.json
"""

from __future__ import annotations

import harness

harness.single_thread()

import argparse  # noqa: E402
import hashlib  # noqa: E402
import json  # noqa: E402
import time  # noqa: E402
from collections.abc import Iterable, Sequence  # noqa: E402
from dataclasses import asdict  # noqa: E402
from pathlib import Path  # noqa: E402

import numpy as np  # noqa: E402

from tsrkit import (  # noqa: E402
    Candidate,
    ParamError,
    Sample,
    TsrkitError,
    get_registry,
)
from tsrkit.api import (  # noqa: E402
    centre_hits,
    open_dataset,
    open_datasets,
    write_json,
)
from tsrkit.plugin.params import parse_parts  # noqa: E402
from tsrkit_plugins.detectors.union import (  # noqa: E402
    DEFAULT_MEMBERS,
    merge,
)

SETS = {
    "KR": "roboflow_traffic_light_kr:test",
    "cinTA": "roboflow_cinta_v2_id:test",
    "DTLD": "dtld_fridtjofs",
    "Japan": "iwai_japan_tl",
    "synthetic": "sample",
}
#: Lens radii per housing half-width on the housing-boxed sets.
HOUSING_PER_LENS = 1.3
#: The sets whose boxes are housings.
HOUSING_BOXED = ("cinTA", "DTLD", "Japan")
#: The largest lens radius (px) of a "small" lens, whose recall gets its own column.
SMALL = 3.0
#: Size bins of r (px), down to the 2-3 px lenses.
SIZE_BINS = ((0, 2), (2, 3), (3, 4), (4, 6), (6, 12), (12, float("inf")))


def bin_label(low: float, high: float) -> str:
    """``r<2``, ``2-3``, ..., ``r>=12``."""
    if low == 0:
        return f"r<{high:g}"
    return f"r>={low:g}" if high == float("inf") else f"{low:g}-{high:g}"


def recall_by_size(
    samples: Sequence[Sample],
    candidates: Iterable[Sequence[Candidate]],
    lens_factor: float = 1.0,
    small: float | None = None,
) -> dict[str, list]:
    """``{"all": [share, count], bin label: [share, count], ...}`` of ``samples``' lights with a
    candidate centre in their circle, binned by half the box's shorter side divided by
    ``lens_factor``; with ``small``, also ``"r<=SMALL"``: the lights of radius up to it."""
    found_r: list[tuple[float, bool]] = []
    for sample, cands in zip(samples, candidates):
        boxes = [a.bbox for a in sample.annotations]
        if not boxes:
            continue
        points = [(c.x, c.y) for c in cands]
        found = centre_hits(points, boxes).any(axis=0) if points else np.zeros(len(boxes), bool)
        found_r += [
            (min(b[2] - b[0], b[3] - b[1]) / 2 / lens_factor, bool(f)) for b, f in zip(boxes, found)
        ]
    out: dict[str, list] = {}
    bins = [("all", lambda r: True)]
    bins += [(f"r<={small:g}", lambda r: r <= small)] if small is not None else []
    bins += [(bin_label(lo, hi), lambda r, lo=lo, hi=hi: lo <= r < hi) for lo, hi in SIZE_BINS]
    for label, keep in bins:
        hits = [f for r, f in found_r if keep(r)]
        out[label] = [float(np.mean(hits)) if hits else None, len(hits)]
    return out


def open_set(key: str) -> list[Sample]:
    """The samples of set ``key`` of :data:`SETS` (Japan by its folder while the registry
    does not name it)."""
    ref = SETS[key]
    try:
        return list(open_datasets([ref]).samples)
    except TsrkitError:
        if key != "Japan":
            raise
        return list(open_dataset(harness.data_dir() / ref, format="normalized").samples)


def run_detector(name: str, params: dict, samples: Sequence[Sample]):
    """Candidates of every sample and the median CPU ms per frame."""
    detector = get_registry().create("detector", "union", {"members": detector_key(name, params)})
    detector = detector.members[0]
    found, times = [], []
    for sample in samples:
        frame = sample.load()
        start = time.process_time()
        found.append(detector.detect(frame))
        times.append(time.process_time() - start)
    return found, 1000 * float(np.median(times))


def cached_run(name: str, params: dict, samples: Sequence[Sample], key: str, cache: Path | None):
    """:func:`run_detector`, read from or written to ``cache`` (a JSON file per set and
    detector) when given."""
    file = None
    if cache is not None:
        digest = hashlib.sha256(f"{key} {detector_key(name, params)}".encode()).hexdigest()
        file = cache / f"{digest[:16]}.json"
        if file.exists():
            data = json.loads(file.read_text())
            found = [[candidate_from(c) for c in cands] for cands in data["found"]]
            return found, data["ms"]
    found, ms = run_detector(name, params, samples)
    if file is not None:
        rows = [[asdict(c) for c in cands] for cands in found]
        write_json(file, {"found": rows, "ms": ms})
    return found, ms


def candidate_from(fields: dict) -> Candidate:
    """A candidate from its JSON fields (boxes back to tuples)."""
    boxes = {k: tuple(fields[k]) for k in ("bbox", "housing") if fields.get(k) is not None}
    return Candidate(**{**fields, **boxes})


def detector_key(name: str, params: dict) -> str:
    return " ".join([name] + [f"{k}={v}" for k, v in params.items()])


def union_variants(
    members: list, extras: list, without: list[str], quick: bool
) -> list[tuple[str, list]]:
    """The unions to score: the given one, (unless ``quick``) with gray-tophat, with each extra
    member added (and replacing the member of the same detector, when there is one) and
    without each member named in ``without``."""
    variants = [("union", members)]
    if not quick:
        variants.append(("union + gray-tophat", members + [("gray-tophat", {"n_top": "15"})]))
    for name, values in extras:
        label = detector_key(name, values)
        variants.append((f"union + {label}", members + [(name, values)]))
        if any(n == name for n, _ in members):
            swapped = [(name, values) if n == name else (n, v) for n, v in members]
            variants.append((f"union, {name} -> {label}", swapped))
    for name in without:
        kept = [(n, v) for n, v in members if n != name]
        if len(kept) == len(members):
            raise SystemExit(f"candidate_recall: --without {name}: not a member")
        variants.append((f"union without {name}", kept))
    return variants


def measure(
    member_text: str,
    extras: list,
    without: list[str],
    quick: bool,
    sets: list[str],
    cache: Path | None,
) -> dict:
    members = parse_parts(member_text)
    configs = [] if quick else [(name, {}) for name in ("lab-frst", "conspicuity", "gray-tophat")]
    configs += [] if quick else [("adaboost-hsv", {}), ("tl-recognizer", {})]
    configs += [(n, v) for n, v in members if v or quick]
    configs += [] if quick else [("gray-tophat", {"n_top": "15"})]
    configs += [c for c in extras if c not in configs]
    results: dict = {"members": member_text, "housing_per_lens": HOUSING_PER_LENS, "sets": {}}
    for key in sets:
        samples = open_set(key)
        factor = HOUSING_PER_LENS if key in HOUSING_BOXED else 1.0
        rows: dict = {}
        cached: dict = {}
        for name, params in configs:
            found, ms = cached_run(name, params, samples, key, cache)
            label = detector_key(name, params)
            cached[label] = (found, ms)
            rows[label] = {
                "recall": recall_by_size(samples, found, factor, SMALL),
                "per_frame": float(np.mean([len(f) for f in found])),
                "ms": round(ms, 1),
            }
            print(key, label, rows[label]["recall"]["all"], round(ms, 1), flush=True)
        for union_name, member_list in union_variants(members, extras, without, quick):
            parts = [cached[detector_key(n, v)] for n, v in member_list]
            merged = [merge(list(lists), 1.0, 3.0) for lists in zip(*(p[0] for p in parts))]
            rows[union_name] = {
                "recall": recall_by_size(samples, merged, factor, SMALL),
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
    labels = ["all", f"r<={SMALL:g}"] + [bin_label(lo, hi) for lo, hi in SIZE_BINS]
    lines = [
        f"union members: `{results['members']}` (merge 1.0 radii, min 3 px); r: lens radius, px "
        f"(housing-boxed sets: half the box's shorter side / {results['housing_per_lens']})",
        "",
    ]
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
        "--members", default=DEFAULT_MEMBERS, help="the union's members (default: the preset's)"
    )
    parser.add_argument(
        "--extra",
        action="append",
        default=[],
        metavar="MEMBER",
        help="a further union member, e.g. 'lab-frst top=15 scale=2' (repeatable)",
    )
    parser.add_argument(
        "--without", action="append", default=[], metavar="NAME", help="score the union without it"
    )
    parser.add_argument(
        "--quick", action="store_true", help="skip the detectors at their paper defaults"
    )
    parser.add_argument(
        "--sets", default=",".join(SETS), help=f"comma-separated subset of {', '.join(SETS)}"
    )
    parser.add_argument(
        "--cache",
        metavar="DIR",
        help="reuse each detector's candidates per set from DIR (keyed by set and member text "
        "only: clear it after changing a detector)",
    )
    args = parser.parse_args()
    harness.announce()
    if args.tables:
        print(markdown(json.loads(Path(args.tables).read_text())))
        return
    sets = [s for s in args.sets.split(",") if s]
    unknown = [s for s in sets if s not in SETS]
    if unknown or not sets:
        raise SystemExit(f"candidate_recall: --sets takes names among {', '.join(SETS)}")
    try:
        extras = [member for text in args.extra for member in parse_parts(text)]
        parse_parts(args.members)
    except ParamError as error:
        raise SystemExit(f"candidate_recall: {error}") from None
    cache = Path(args.cache) if args.cache else None
    results = measure(args.members, extras, args.without, args.quick, sets, cache)
    write_json(Path(args.out) / "results.json", results)
    print(markdown(results))


if __name__ == "__main__":
    main()
