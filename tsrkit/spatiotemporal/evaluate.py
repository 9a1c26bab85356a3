"""Temporal accuracy of tracks against per-frame ground truth (Zheng 2016, 5.4).

A track belongs to the ground-truth light its detected candidates hit most often under Zheng's
centre rule (5.2.1: the centre inside the minimum enclosing circle of the light's box,
:func:`tsrkit.eval.matching.centre_hits`), when they hit it at least half the time; otherwise it
is a false track. Temporal accuracy is "the ratio of the number of candidates that are correctly
classified over the number of all candidates in a track" (5.4), counted over the frames where
the light is in view. It is given for every candidate (a DOF candidate carries the state of the
frame it was projected from) and for the detected candidates alone.

Ground truth is JSON Lines, one record per frame: ``{"frame": N, "lights": [{"id", "state",
"bbox": [x0, y0, x1, y1], "status"}]}`` (``tsrkit.synth.drive`` writes it as ``truth.jsonl``);
``status`` ``out`` marks a light outside the image.
"""

from __future__ import annotations

import json
import math
import os
from collections import Counter
from pathlib import Path
from typing import Any

import numpy as np

from tsrkit.core.errors import TsrkitError
from tsrkit.eval.matching import centre_hits

__all__ = [
    "Truth",
    "TruthError",
    "evaluate_traversal",
    "hit_light",
    "ratio",
    "read_truth",
    "temporal_accuracy",
    "temporal_section",
    "track_light",
]

Truth = dict[int, dict[str, dict[str, Any]]]


class TruthError(TsrkitError):
    """A ground-truth file that is missing or malformed."""


def read_truth(path: str | os.PathLike) -> Truth:
    """``truth[frame][light id]`` -> ``{"state", "bbox", "status"}`` from a JSON Lines file.

    Raises
    ------
    TruthError
        Naming the file and line.
    """
    path = Path(path)
    truth: Truth = {}
    try:
        lines = path.read_text(encoding="utf-8").splitlines()
    except FileNotFoundError:
        raise TruthError(f"{path}: no such file") from None
    except (OSError, UnicodeDecodeError) as exc:
        raise TruthError(f"{path}: cannot read as UTF-8 text ({exc})") from None
    for number, line in enumerate(lines, start=1):
        if not line.strip():
            continue
        try:
            record = json.loads(line)
            lights: dict[str, dict[str, Any]] = {
                str(light["id"]): {
                    "state": str(light["state"]),
                    "bbox": [float(v) for v in light["bbox"]][:4],
                    "status": str(light.get("status", "in")),
                }
                for light in record["lights"]
            }
            frame = int(record["frame"])
        except (ValueError, KeyError, TypeError) as exc:
            raise TruthError(
                f"{path}: line {number}: not a frame record with lights ({exc!r})"
            ) from None
        if any(
            len(v["bbox"]) != 4 or not all(math.isfinite(c) for c in v["bbox"])
            for v in lights.values()
        ):
            raise TruthError(f"{path}: line {number}: a light's bbox is not 4 finite numbers")
        truth[frame] = lights
    if not truth:
        raise TruthError(f"{path}: no frame record")
    return truth


def hit_light(point: dict[str, Any], lights: dict[str, dict[str, Any]]) -> str | None:
    """The id of the light (in view) whose enclosing circle holds the point's centre."""
    ids = [k for k, v in lights.items() if v["status"] != "out"]
    if not ids:
        return None
    hits = centre_hits([[point["x"], point["y"]]], [lights[k]["bbox"] for k in ids])[0]
    return ids[int(np.argmax(hits))] if hits.any() else None


def track_light(track: dict[str, Any], truth: Truth) -> str | None:
    """The light a track follows: the one its detected candidates hit most, if at least half."""
    detected = [p for p in track["points"] if p["origin"] == "detected"]
    hits = Counter(hit_light(p, truth.get(p["frame"], {})) for p in detected)
    hits.pop(None, None)
    if not hits:
        return None
    light, count = hits.most_common(1)[0]
    return light if count * 2 >= len(detected) else None


def temporal_accuracy(track: dict[str, Any], light: str, truth: Truth) -> dict[str, int]:
    """Candidates and correctly classified candidates of a track, over the frames where its
    light is in view; all candidates and detected ones apart."""
    counts = {"candidates": 0, "correct": 0, "detected": 0, "detected_correct": 0}
    for point in track["points"]:
        seen = truth.get(point["frame"], {}).get(light)
        if seen is None or seen["status"] == "out" or point["status"] == "out":
            continue
        right = int(point["state"] == seen["state"])
        counts["candidates"] += 1
        counts["correct"] += right
        if point["origin"] == "detected":
            counts["detected"] += 1
            counts["detected_correct"] += right
    return counts


def ratio(numerator: int, denominator: int) -> float | None:
    """``numerator / denominator``, None for an empty denominator."""
    return numerator / denominator if denominator else None


def evaluate_traversal(record: dict[str, Any], truth: Truth) -> dict[str, Any]:
    """Per track its light and counts; pooled over the true tracks, the traversal's temporal
    accuracy (all candidates and detected ones)."""
    tracks: list[dict[str, Any]] = []
    pooled: Counter[str] = Counter()
    for track in record["tracks"]:
        light = track_light(track, truth)
        counts = temporal_accuracy(track, light, truth) if light else {}
        pooled.update(counts)
        tracks.append({"id": track["id"], "light": light, **counts})
    return {
        "traversal": record["traversal"],
        "true_tracks": sum(t["light"] is not None for t in tracks),
        "false_tracks": sum(t["light"] is None for t in tracks),
        "lights": sorted({t["light"] for t in tracks if t["light"]}),
        **{k: pooled[k] for k in ("candidates", "correct", "detected", "detected_correct")},
        "temporal_accuracy": ratio(pooled["correct"], pooled["candidates"]),
        "detected_accuracy": ratio(pooled["detected_correct"], pooled["detected"]),
        "tracks": tracks,
    }


def temporal_section(evaluations: list[dict[str, Any]]) -> dict[str, Any]:
    """The ``temporal`` section of ``report.json``: every traversal and the pooled figures."""
    candidates, correct, detected, detected_correct = (
        sum(e[k] for e in evaluations)
        for k in ("candidates", "correct", "detected", "detected_correct")
    )
    return {
        "traversals": len(evaluations),
        "true_tracks": sum(e["true_tracks"] for e in evaluations),
        "false_tracks": sum(e["false_tracks"] for e in evaluations),
        "candidates": candidates,
        "temporal_accuracy": ratio(correct, candidates),
        "detected": detected,
        "detected_accuracy": ratio(detected_correct, detected),
        "per_traversal": evaluations,
    }
