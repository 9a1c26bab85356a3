"""Key frames and following on rendered drives: what ``tsrkit detect VIDEO --key-every K`` costs
and finds against the whole pipeline on every frame.

Each run decodes a drive of ``tsrkit.synth.drive`` (the three short drives of
``benchmarks/track_drive.py``, rendered once into ``benchmarks/out/track_drive/``) and runs a
:class:`tsrkit.runner.follow.Follower` over its frames in this process; CPU time is the process's
(``time.process_time``) around the pipeline calls only (decoding excluded), one OpenCV thread.
Per frame the records are scored against ``truth.jsonl`` with Zheng's centre rule (5.2.1, a
detection's centre inside a light's minimum enclosing circle):

- a *gradable* light is in the image, at least half unoccluded and of lens radius >= 1.5 px
  (Zheng's smallest); light recall is over gradable (frame, light) pairs;
- state accuracy is over the hits of gradable lights (the detection's state against the truth);
- a *false light* is a detection whose centre is in no light's circle (any light of the frame,
  gradable or not); false lights per frame is over all frames.

    python benchmarks/bench_follow.py                              # both configurations, K 1-6
    python benchmarks/bench_follow.py --config zheng --keys 1,4 --drives through
"""

from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

import harness

harness.single_thread()

from track_drive import SHORT, rendered  # noqa: E402

from tsrkit import Frame  # noqa: E402
from tsrkit.api import centre_hits  # noqa: E402
from tsrkit.plugin.selection import build  # noqa: E402
from tsrkit.runner.agreement import Agreement  # noqa: E402
from tsrkit.runner.follow import Follower  # noqa: E402
from tsrkit.runner.inputs import iter_video  # noqa: E402

#: The two detector settings: ``track_drive.py``'s (Zheng's conspicuity with ab-hist) and the
#: recommended preset.
CONFIGS = {
    "zheng": dict(
        detector="conspicuity",
        classifier="ab-hist",
        params=["h_peak=0.8", "radii=1,2,3,4,5,6"],
    ),
    "recommended": dict(config="recommended"),
}
MIN_RADIUS, MIN_VISIBLE = 1.5, 0.5


def frames_of(video: Path) -> list[Frame]:
    """Every decoded frame of ``video``."""
    return [f for f in iter_video(video) if isinstance(f, Frame)]


def run(frames: list[Frame], follower: Follower) -> tuple[list, float]:
    """The follower's results on ``frames`` and the CPU seconds they took."""
    results, cpu = [], 0.0
    for frame in frames:
        start = time.process_time()
        results.append(follower.process(frame))
        cpu += time.process_time() - start
    return results, cpu


def is_gradable(light: dict) -> bool:
    """Whether ``light`` (one of ``truth.jsonl``'s) counts for recall (see the module notes)."""
    return (
        light["status"] == "in"
        and light["visible"] >= MIN_VISIBLE
        and light["radius"] >= MIN_RADIUS
    )


def ceiling(runs: list[tuple[list, list[dict]]], k: int) -> float:
    """An estimate of the best light recall following can reach at key frames every ``k``, from
    every-frame ``(results, truth)`` of each drive: a gradable light counts on frame t when it is
    hit there and on the key frame ``t - t % k`` (following finds what a key frame found, and a
    light that a window around a neighbouring followed light holds, which this leaves out)."""
    got = total = 0
    for results, truth in runs:
        hit = []
        for result, record in zip(results, truth, strict=True):
            centres = [[d.candidate.x, d.candidate.y] for d in result.detections]
            lights = [light for light in record["lights"] if is_gradable(light)]
            boxes = [light["bbox"] for light in lights]
            found = centre_hits(centres, boxes).any(axis=0) if centres and boxes else []
            hit.append({light["id"]: bool(f) for light, f in zip(lights, found)})
            total += len(lights)
        got += sum(
            ok and hit[t - t % k].get(i, False) for t in range(len(hit)) for i, ok in hit[t].items()
        )
    return got / max(total, 1)


def score(results, truth: list[dict]) -> dict[str, float]:
    """Light recall, state accuracy and false lights per frame (see the module notes)."""
    gradable = hits = correct = false = 0
    for result, record in zip(results, truth, strict=True):
        lights = record["lights"]
        centres = [[d.candidate.x, d.candidate.y] for d in result.detections]
        boxes = [light["bbox"] for light in lights]
        matrix = centre_hits(centres, boxes) if centres and boxes else None
        for j, light in enumerate(lights):
            if not is_gradable(light):
                continue
            gradable += 1
            hitting = [i for i in range(len(centres)) if matrix is not None and matrix[i, j]]
            if hitting:
                hits += 1
                correct += any(result.detections[i].state == light["state"] for i in hitting)
        false += sum(1 for i in range(len(centres)) if matrix is None or not matrix[i].any())
    return {
        "recall": hits / gradable if gradable else float("nan"),
        "state": correct / hits if hits else float("nan"),
        "false_per_frame": false / len(truth),
        "gradable": gradable,
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--config", default="zheng,recommended")
    parser.add_argument("--keys", default="1,2,3,4,6")
    parser.add_argument("--drives", default=",".join(SHORT))
    parser.add_argument("--reach", type=float, default=3.0)
    parser.add_argument("--confirm", default="1,2,3", help="temporal agreement: frames")
    args = parser.parse_args()
    harness.announce()
    keys = [int(k) for k in args.keys.split(",")]
    drives = {}
    for name in args.drives.split(","):
        folder, _ = rendered(name, SHORT[name])
        truth = [json.loads(line) for line in (folder / "truth.jsonl").open()]
        drives[name] = (frames_of(folder / "drive.mp4"), truth)
    total = sum(len(t) for _, t in drives.values())
    print(f"drives {', '.join(drives)}: {total} frames 480x356; reach {args.reach} radii\n")
    confirms = [int(c) for c in args.confirm.split(",")]
    print("| config | K | agreement frames | CPU ms/frame | speed-up | light recall | state acc. "
          "| false lights / frame | key / followed frames | regions |")  # fmt: skip
    print("|---|---:|---:|---:|---:|---:|---:|---:|---|---:|")
    for config in args.config.split(","):
        base, every = None, None
        for k in keys:
            cpu, per_drive = 0.0, []
            calls = {"key": 0, "followed": 0, "regions": 0}
            for frames, truth in drives.values():
                follower = Follower(build(**CONFIGS[config]).pipeline(), k, args.reach)
                results, seconds = run(frames, follower)
                cpu += seconds
                per_drive.append((results, truth[: len(results)]))
                calls = {key: calls[key] + follower.calls[key] for key in calls}
            n = sum(len(r) for r, _ in per_drive)
            ms = 1000 * cpu / n
            base = base or ms
            for confirm in confirms:
                kept, truth_all = [], []
                for results, truth in per_drive:
                    kept += [r for r, _ in Agreement(confirm).filter((r, None) for r in results)]
                    truth_all += truth
                figures = score(kept, truth_all)
                print(
                    f"| {config} | {k} | {confirm} | {ms:.1f} | {base / ms:.2f}x "
                    f"| {figures['recall']:.3f} | {figures['state']:.3f} "
                    f"| {figures['false_per_frame']:.3f} | {calls['key']} / {calls['followed']} "
                    f"| {calls['regions']} |",
                    flush=True,
                )
            if k == 1:
                every = per_drive
        if every is not None:
            ceilings = [ceiling(every, k) for k in keys]
            print(
                f"\n{config}: ceiling of light recall by K (a light hit on its frame and on the key"
                " frame before, from K 1's results): "
                + ", ".join(f"K {k} {c:.3f}" for k, c in zip(keys, ceilings))
            )


if __name__ == "__main__":
    main()
