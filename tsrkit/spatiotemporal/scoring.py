"""Scoring ``timelines.csv`` and ``events.csv`` of ``tsrkit track`` against the truth of a
rendered drive (``truth_timelines.csv``, ``truth_events.csv``: :mod:`tsrkit.synth.behaviour`).

Traversals are paired by time: each estimated traversal goes to the true one whose timeline
span overlaps its own the most. An estimated event matches a true one of the same traversal and
kind within :data:`MATCH_S` seconds (each used once, closest first): precision and recall per
kind and pooled. Timeline accuracy is the share of the time covered by both a true and an
estimated timeline where the states agree (sampled every 0.05 s), with the share published as
``unknown`` apart. The amber-onset distance error is that of the matched amber onsets.
"""

from __future__ import annotations

import csv
import os
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from tsrkit.core.errors import TsrkitError
from tsrkit.spatiotemporal.events import EVENT_KINDS

__all__ = ["MATCH_S", "match_events", "pair_traversals", "read_rows", "score", "timeline_scores"]

#: An estimated event matches a true one within this many seconds.
MATCH_S = 0.5
_STEP_S = 0.05


def read_rows(path: str | os.PathLike) -> list[dict[str, Any]]:
    """The rows of a timelines or events CSV, ``traversal`` as int and times as floats."""
    try:
        with Path(path).open(encoding="utf-8", newline="") as fh:
            rows = list(csv.DictReader(fh))
    except OSError as exc:
        raise TsrkitError(f"{path}: cannot read ({exc.strerror or exc})") from None
    for row in rows:
        try:
            row["traversal"] = int(row["traversal"])
            for key in ("time", "end", "distance"):
                if row.get(key) not in (None, ""):
                    row[key] = float(row[key])
        except (KeyError, ValueError) as exc:
            raise TsrkitError(f"{path}: not a timelines / events table ({exc})") from None
    return rows


def _spans(timelines: Sequence[Mapping[str, Any]]) -> dict[int, tuple[float, float]]:
    spans: dict[int, tuple[float, float]] = {}
    for row in timelines:
        lo, hi = spans.get(row["traversal"], (np.inf, -np.inf))
        spans[row["traversal"]] = (min(lo, row["time"]), max(hi, row["end"]))
    return spans


def pair_traversals(
    estimated: Sequence[Mapping[str, Any]], truth: Sequence[Mapping[str, Any]]
) -> dict[int, int]:
    """Estimated traversal -> true traversal, by the largest overlap of timeline spans."""
    true_spans = _spans(truth)
    pairs = {}
    for number, (lo, hi) in _spans(estimated).items():
        overlaps = {k: min(hi, b) - max(lo, a) for k, (a, b) in true_spans.items()}
        best = max(overlaps, key=lambda k: overlaps[k], default=None)
        if best is not None and overlaps[best] > 0:
            pairs[number] = best
    return pairs


def match_events(
    estimated: Sequence[Mapping[str, Any]],
    truth: Sequence[Mapping[str, Any]],
    pairs: Mapping[int, int],
) -> list[tuple[Mapping[str, Any], Mapping[str, Any]]]:
    """``(estimated, true)`` event pairs: same traversal and kind, within :data:`MATCH_S`."""
    candidates = []
    for i, e in enumerate(estimated):
        for j, t in enumerate(truth):
            same = pairs.get(e["traversal"]) == t["traversal"] and e["kind"] == t["kind"]
            gap = abs(e["time"] - t["time"])
            if same and gap <= MATCH_S:
                candidates.append((gap, i, j))
    used_e, used_t, matched = set(), set(), []
    for _, i, j in sorted(candidates):
        if i not in used_e and j not in used_t:
            used_e.add(i)
            used_t.add(j)
            matched.append((estimated[i], truth[j]))
    return matched


def _state_grid(rows: Sequence[Mapping[str, Any]], times: np.ndarray) -> np.ndarray:
    states = np.full(len(times), "", dtype=object)
    for row in rows:
        states[(times >= row["time"]) & (times < row["end"])] = row["kind"]
    return states


def timeline_scores(
    estimated: Sequence[Mapping[str, Any]],
    truth: Sequence[Mapping[str, Any]],
    pairs: Mapping[int, int],
) -> dict[str, float]:
    """Seconds compared, the share of them in agreement and the share published unknown."""
    compared = agree = unknown = 0
    for number, true_number in pairs.items():
        mine = [r for r in estimated if r["traversal"] == number]
        theirs = [r for r in truth if r["traversal"] == true_number]
        lo = max(min(r["time"] for r in mine), min(r["time"] for r in theirs))
        hi = min(max(r["end"] for r in mine), max(r["end"] for r in theirs))
        times = np.arange(lo, hi, _STEP_S)
        a, b = _state_grid(mine, times), _state_grid(theirs, times)
        both = (a != "") & (b != "")
        compared += int(both.sum())
        agree += int((both & (a == b)).sum())
        unknown += int((both & (a == "unknown")).sum())
    return {
        "seconds": round(compared * _STEP_S, 1),
        "accuracy": agree / compared if compared else float("nan"),
        "unknown_share": unknown / compared if compared else float("nan"),
    }


def score(run: str | os.PathLike, drive: str | os.PathLike) -> dict[str, Any]:
    """Every figure of the module notes for the run folder ``run`` against the drive folder
    ``drive``."""
    est_t, true_t = (
        read_rows(Path(run, "timelines.csv")),
        read_rows(Path(drive, "truth_timelines.csv")),
    )
    est_e, true_e = read_rows(Path(run, "events.csv")), read_rows(Path(drive, "truth_events.csv"))
    pairs = pair_traversals(est_t, true_t)
    matched = match_events(est_e, true_e, pairs)
    kinds = {}
    for kind in EVENT_KINDS:
        kinds[kind] = {
            "estimated": sum(e["kind"] == kind for e in est_e),
            "true": sum(t["kind"] == kind for t in true_e),
            "matched": sum(e["kind"] == kind for e, _ in matched),
        }
    amber = [abs(e["distance"] - t["distance"]) for e, t in matched if e["kind"] == "amber_onset"]
    flags = kinds["red_crossing"]
    return {
        "traversals": {"estimated": len(_spans(est_t)), "true": len(_spans(true_t))},
        "paired": len(pairs),
        "events": {
            "estimated": len(est_e),
            "true": len(true_e),
            "matched": len(matched),
            "precision": len(matched) / len(est_e) if est_e else float("nan"),
            "recall": len(matched) / len(true_e) if true_e else float("nan"),
        },
        "kinds": kinds,
        "red_crossing": {
            "true": flags["true"],
            "flagged": flags["estimated"],
            "false_flags": flags["estimated"] - flags["matched"],
            "missed": flags["true"] - flags["matched"],
        },
        "timeline": timeline_scores(est_t, true_t, pairs),
        "amber_distance_error_m": {
            "matched": len(amber),
            "max": max(amber) if amber else float("nan"),
            "mean": float(np.mean(amber)) if amber else float("nan"),
        },
    }
