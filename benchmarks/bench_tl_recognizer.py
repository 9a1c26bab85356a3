"""Speed of TL-recognizer on 1413x1884 frames and the resize-factor trade-off (Mascetti 4.2, Fig. 18).

Real frames of roboflow_traffic_light_kr are stretched to 1413 wide x 1884 high (the paper's test
resolution) with their boxes; for resize factors 1-4 the script prints the median detection time
per frame (single thread, several repetitions) and the per-frame recall and precision that
tsrkit's runner measures on those frames. Usage: ``python benchmarks/bench_tl_recognizer.py``.
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
        boxes = tuple(Annotation((a.bbox[0] * sx, a.bbox[1] * sy, a.bbox[2] * sx,
                                  a.bbox[3] * sy), a.state, a.attributes)
                      for a in sample.annotations)
        samples.append(Sample(sample.source, boxes, WIDTH, HEIGHT, sample.split, image=big))
    return Dataset(f"{dataset.name}@{WIDTH}x{HEIGHT}", tuple(samples), dataset.format)


def median_ms(detector, frames, repeats: int) -> float:
    """Median over frames of each frame's median detection time in milliseconds."""
    per_frame = []
    for frame in frames:
        times = []
        for _ in range(repeats):
            start = time.perf_counter()
            detector.detect(frame)
            times.append((time.perf_counter() - start) * 1000)
        per_frame.append(statistics.median(times))
    return statistics.median(per_frame)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--dataset", default="roboflow_traffic_light_kr")
    parser.add_argument("--repeats", type=int, default=5)
    args = parser.parse_args()
    cv2.setNumThreads(1)
    data = stretched(tsrkit.dataset(args.dataset))
    frames = [s.load() for s in data]
    print(f"{len(frames)} frames of {args.dataset} at {WIDTH}x{HEIGHT}, "
          f"{args.repeats} repetitions, single thread")
    print(f"{'factor':>6} {'ms median':>10} {'vs 1':>6} {'recall':>7} {'precision':>9} "
          f"{'hit frames':>10}")
    base = None
    for factor in (1, 2, 3, 4):
        det = tsrkit.detector("tl-recognizer", resize_factor=factor)
        ms = median_ms(det, frames, args.repeats)
        base = base or ms
        with tempfile.TemporaryDirectory() as cache:
            report = tsrkit.benchmark(data, det, workers=1, cache_dir=cache)
        pf = report["per_frame"]
        print(f"{factor:>6} {ms:>10.1f} {ms / base:>6.2f} {pf['recall_mean']:>7.3f} "
              f"{pf['precision_mean'] or 0:>9.3f} {pf['hit_frame_fraction']:>10.3f}")
    two = tsrkit.detector("tl-recognizer", threads=2)
    one = tsrkit.detector("tl-recognizer", threads=1)
    t1, t2 = median_ms(one, frames, args.repeats), median_ms(two, frames, args.repeats)
    print(f"factor 3, colour passes on 2 threads: {t2:.1f} ms vs {t1:.1f} ms "
          f"(ratio {t2 / t1:.2f})")


if __name__ == "__main__":
    main()
