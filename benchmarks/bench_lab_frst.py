"""Time the lab-frst detector on real road scenes at 480x356 and 1280x720, one thread.

Frames are the Korean Roboflow scenes resized to each size. Also times the fast FRST against the
loop oracle of tests/oracles on the same feature maps (one frame) and checks they agree, and
the detector against its straightforward version (``lab_frst_straightforward.py``) at both
sizes, interleaved, with how many of the reference's candidates it reproduces.
``--baseline COMMIT`` also times the FRST of both feature-map parts against ``frst.py`` as of
that commit (interleaved, maps checked equal).
Run: python benchmarks/bench_lab_frst.py [--frames N] [--repeats R] [--reference-frames N]
[--baseline 74eb292]
"""

from __future__ import annotations

import harness

harness.single_thread()

import argparse  # noqa: E402
import json  # noqa: E402
import statistics  # noqa: E402
import sys  # noqa: E402
import time  # noqa: E402

import cv2  # noqa: E402
import numpy as np  # noqa: E402

REPO = harness.REPO
sys.path.insert(0, str(REPO / "tests"))

from oracles.frst_oracle import frst_oracle  # noqa: E402

sys.path.insert(0, str(REPO / "benchmarks"))
from at_commit import module_at  # noqa: E402
from lab_frst_straightforward import lab_frst_straightforward  # noqa: E402

import tsrkit  # noqa: E402
from tsrkit import Frame  # noqa: E402
from tsrkit_plugins.detectors.frst.frst import frst  # noqa: E402
from tsrkit_plugins.detectors.frst.lab_frst import lab_feature_map  # noqa: E402

SIZES = ((480, 356), (1280, 720))


def scenes(count: int) -> list[np.ndarray]:
    """The first ``count`` images of roboflow_traffic_light_kr, as BGR uint8."""
    root = harness.data_dir()
    entries = json.loads((root / "roboflow_traffic_light_kr" / "annotations.json").read_text())
    return [
        cv2.imread(str(root / "roboflow_traffic_light_kr" / e["file"])) for e in entries[:count]
    ]


def timings_ms(detector: tsrkit.Detector, frames: list[Frame], repeats: int) -> dict[str, float]:
    """Median and minimum wall time, and median CPU time, of one ``detect`` call (ms).

    CPU time (``time.process_time``) is less sensitive than wall time to other processes on a
    shared machine, so both are printed.
    """
    wall, cpu = [], []
    for frame in frames:
        detector.detect(frame)
        for _ in range(repeats):
            start, start_cpu = time.perf_counter(), time.process_time()
            detector.detect(frame)
            wall.append((time.perf_counter() - start) * 1000)
            cpu.append((time.process_time() - start_cpu) * 1000)
    return {
        "median": statistics.median(wall),
        "min": min(wall),
        "cpu_median": statistics.median(cpu),
    }


def oracle_comparison(image: np.ndarray) -> dict[str, float]:
    """Fast vs loop FRST on the two parts of one 480x356 feature map: time and agreement."""
    feature = lab_feature_map(image)
    parts = ((np.maximum(feature, 0), "bright"), (np.minimum(feature, 0), "dark"))
    start = time.perf_counter()
    slow = [frst_oracle(part, alpha=3.0, mode=mode) for part, mode in parts]
    oracle_s = time.perf_counter() - start
    fast_times = []
    for _ in range(20):
        start = time.perf_counter()
        fast = [frst(part, alpha=3.0, mode=mode) for part, mode in parts]
        fast_times.append(time.perf_counter() - start)
    fast_s = statistics.median(fast_times)
    diff = max(float(np.abs(f - s).max()) for f, s in zip(fast, slow))
    peak = max(float(np.abs(s).max()) for s in slow)
    return {
        "oracle_ms": oracle_s * 1000,
        "fast_ms": fast_s * 1000,
        "speedup": oracle_s / fast_s,
        "max_abs_diff": diff,
        "max_abs_value": peak,
    }


def reference_comparison(
    detector: tsrkit.Detector, images: list[np.ndarray], repeats: int
) -> dict[str, float]:
    """Median wall ms of the detector and of the straightforward version (interleaved, every
    repetition runs both on every frame), and the reference candidates it reproduces (same
    state, centre within 0.01 px)."""
    times: dict[str, list[float]] = {"shipped": [], "reference": []}
    calls = {
        "shipped": lambda image: detector.detect(Frame(image, "bench")),
        "reference": lab_frst_straightforward,
    }
    for _ in range(repeats):
        for image in images:
            for name, call in calls.items():
                start = time.perf_counter()
                call(image)
                times[name].append((time.perf_counter() - start) * 1000)
    same = total = 0
    for image in images:
        shipped = calls["shipped"](image)
        for ref in lab_frst_straightforward(image):
            total += 1
            same += any(
                c.state == ref.state and abs(c.x - ref.x) + abs(c.y - ref.y) < 0.01 for c in shipped
            )
    return {
        "shipped": statistics.median(times["shipped"]),
        "reference": statistics.median(times["reference"]),
        "same": same,
        "total": total,
    }


def baseline_comparison(images: list[np.ndarray], commit: str, repeats: int) -> dict[str, float]:
    """Median wall and CPU ms of the FRST of both feature-map parts, now and at ``commit``
    (interleaved), and the number of frames whose transforms differ."""
    old = module_at(commit, "plugins/detectors/frst/frst.py").frst
    wall: dict[str, list[float]] = {"now": [], "baseline": []}
    cpu: dict[str, list[float]] = {"now": [], "baseline": []}
    differ = 0
    for image in images:
        feature = lab_feature_map(image)
        parts = ((np.maximum(feature, 0), "bright"), (np.minimum(feature, 0), "dark"))
        differ += any(
            not np.array_equal(frst(p, alpha=3.0, mode=m), old(p, alpha=3.0, mode=m))
            for p, m in parts
        )
        for _ in range(repeats):
            for name, transform in (("now", frst), ("baseline", old)):
                start, start_cpu = time.perf_counter(), time.process_time()
                for part, mode in parts:
                    transform(part, alpha=3.0, mode=mode)
                wall[name].append((time.perf_counter() - start) * 1000)
                cpu[name].append((time.process_time() - start_cpu) * 1000)
    return {
        **{f"{k}_wall": statistics.median(v) for k, v in wall.items()},
        **{f"{k}_cpu": statistics.median(v) for k, v in cpu.items()},
        "differ": differ,
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    harness.add_frames(parser, 10)
    harness.add_repeats(parser, 10)
    parser.add_argument("--beta", type=float, default=None, help="override the beta default")
    parser.add_argument("--reference-frames", type=int, default=3)
    parser.add_argument("--baseline", default="", help="commit whose FRST is timed alongside")
    args = parser.parse_args()
    harness.announce()
    images = scenes(args.frames)
    detector = tsrkit.detector("lab-frst", **({} if args.beta is None else {"beta": args.beta}))
    print(f"lab-frst params: {detector.params}")
    results = {}
    for width, height in SIZES:
        frames = [
            Frame(cv2.resize(im, (width, height), interpolation=cv2.INTER_AREA), "bench")
            for im in images
        ]
        results[width, height] = timings_ms(detector, frames, args.repeats)
        t = results[width, height]
        print(
            f"{width}x{height}: median {t['median']:.1f} ms/frame, min {t['min']:.1f}, "
            f"CPU median {t['cpu_median']:.1f} ({len(frames)} frames x {args.repeats} repeats)"
        )
    small, large = results[SIZES[0]], results[SIZES[1]]
    print(
        f"1280x720 / 480x356 ratio: median {large['median'] / small['median']:.2f}, "
        f"CPU {large['cpu_median'] / small['cpu_median']:.2f} "
        f"(pixel ratio {1280 * 720 / (480 * 356):.2f})"
    )
    small_frame = cv2.resize(images[0], SIZES[0], interpolation=cv2.INTER_AREA)
    check = oracle_comparison(small_frame)
    print(
        f"FRST of both feature-map parts, 480x356, alpha 3, radii 1..10, beta 0: "
        f"oracle {check['oracle_ms']:.0f} ms, fast {check['fast_ms']:.1f} ms, "
        f"speed-up {check['speedup']:.0f}x, max abs diff {check['max_abs_diff']:.2e} "
        f"(max |S| {check['max_abs_value']:.3g})"
    )
    if args.beta is None:
        for width, height in SIZES:
            sized = [
                cv2.resize(im, (width, height), interpolation=cv2.INTER_AREA)
                for im in images[: args.reference_frames]
            ]
            ref = reference_comparison(detector, sized, max(1, args.repeats // 5))
            print(
                f"{width}x{height}: detect {ref['shipped']:.1f} ms, straightforward "
                f"{ref['reference']:.1f} ms: {ref['reference'] / ref['shipped']:.1f}x; "
                f"{ref['same']} of {ref['total']} reference candidates reproduced"
            )
    if args.baseline:
        for width, height in SIZES:
            sized = [
                cv2.resize(im, (width, height), interpolation=cv2.INTER_AREA)
                for im in images[: args.reference_frames]
            ]
            ab = baseline_comparison(sized, args.baseline, args.repeats)
            print(
                f"{width}x{height}: FRST of both parts now {ab['now_wall']:.1f} ms (CPU "
                f"{ab['now_cpu']:.1f}), at {args.baseline} {ab['baseline_wall']:.1f} ms (CPU "
                f"{ab['baseline_cpu']:.1f}): {ab['baseline_wall'] / ab['now_wall']:.2f}x wall, "
                f"{ab['baseline_cpu'] / ab['now_cpu']:.2f}x CPU; frames differing: {ab['differ']}"
            )


if __name__ == "__main__":
    main()
