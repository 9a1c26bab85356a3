"""Speed of TL-recognizer on 1413x1884 frames; the resize-factor trade-off (Mascetti 4.2, Fig. 18).

Real frames of roboflow_traffic_light_kr are stretched to 1413 wide x 1884 high (the paper's test
resolution) with their boxes; for resize factors 1-4 the script prints the median detection time
per frame (single thread; the factors are interleaved within every repetition of every frame, so
machine load falls on all of them alike) and the per-frame recall and precision that tsrkit's
runner measures on those frames. Usage: ``python benchmarks/bench_tl_recognizer.py
[-p context=housing ...]``.
"""

from __future__ import annotations

import os

for _var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ[_var] = "1"

import argparse  # noqa: E402
import statistics  # noqa: E402
import tempfile  # noqa: E402
import time  # noqa: E402

import cv2  # noqa: E402

import tsrkit  # noqa: E402
from tsrkit.types import Annotation, Dataset, Sample  # noqa: E402

WIDTH, HEIGHT = 1413, 1884


def stretched(dataset: Dataset) -> Dataset:
    """The dataset's frames and boxes resized to WIDTH x HEIGHT, held in memory."""
    samples = []
    for sample in dataset:
        image = sample.load().image
        sx, sy = WIDTH / image.shape[1], HEIGHT / image.shape[0]
        big = cv2.resize(image, (WIDTH, HEIGHT), interpolation=cv2.INTER_LINEAR)
        boxes = tuple(
            Annotation(
                (a.bbox[0] * sx, a.bbox[1] * sy, a.bbox[2] * sx, a.bbox[3] * sy),
                a.state,
                a.attributes,
            )
            for a in sample.annotations
        )
        samples.append(Sample(sample.source, boxes, WIDTH, HEIGHT, sample.split, image=big))
    return Dataset(f"{dataset.name}@{WIDTH}x{HEIGHT}", tuple(samples), dataset.format)


def interleaved_ms(detectors: dict, frames, repeats: int) -> dict:
    """Median over frames of each frame's median detection time (ms), per detector.

    Every repetition of every frame runs all detectors back to back, so slow spells of a shared
    machine hit each of them, not whichever happened to be measured then.
    """
    per_frame = {key: [] for key in detectors}
    for frame in frames:
        times = {key: [] for key in detectors}
        for _ in range(repeats):
            for key, detector in detectors.items():
                start = time.perf_counter()
                detector.detect(frame)
                times[key].append((time.perf_counter() - start) * 1000)
        for key in detectors:
            per_frame[key].append(statistics.median(times[key]))
    return {key: statistics.median(values) for key, values in per_frame.items()}


def parsed(pairs) -> dict:
    """``KEY=VALUE`` strings as a dict (values converted by the plugin's schema)."""
    return dict(pair.split("=", 1) for pair in pairs)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--dataset", default="roboflow_traffic_light_kr")
    parser.add_argument("--repeats", type=int, default=5)
    parser.add_argument(
        "-p",
        "--param",
        action="append",
        default=[],
        help="detector parameter KEY=VALUE (repeatable)",
    )
    args = parser.parse_args()
    params = parsed(args.param)
    cv2.setNumThreads(1)
    data = stretched(tsrkit.dataset(args.dataset))
    frames = [s.load() for s in data]
    print(
        f"{len(frames)} frames of {args.dataset} at {WIDTH}x{HEIGHT}, "
        f"{args.repeats} repetitions, single thread, params {params or 'default'}"
    )
    detectors = {
        factor: tsrkit.detector("tl-recognizer", **{**params, "resize_factor": factor})
        for factor in (1, 2, 3, 4)
    }
    detectors["3, 2 threads"] = tsrkit.detector(
        "tl-recognizer", **{**params, "resize_factor": 3, "threads": 2}
    )
    ms = interleaved_ms(detectors, frames, args.repeats)
    print(
        f"{'factor':>12} {'ms median':>10} {'vs 1':>6} {'recall':>7} {'precision':>9} "
        f"{'hit frames':>10}"
    )
    for key, det in detectors.items():
        with tempfile.TemporaryDirectory() as cache:
            report = tsrkit.benchmark(data, det, workers=1, cache_dir=cache)
        pf = report["per_frame"]
        print(
            f"{key:>12} {ms[key]:>10.1f} {ms[key] / ms[1]:>6.2f} {pf['recall_mean']:>7.3f} "
            f"{pf['precision_mean'] or 0:>9.3f} {pf['hit_frame_fraction']:>10.3f}"
        )


if __name__ == "__main__":
    main()
