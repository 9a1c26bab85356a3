"""Speed of the conspicuity and GRAY-TOPHAT detectors against the direct-correlation oracle.

Frames: roboflow_traffic_light_kr road scenes resized to 480x356 (the thesis's size) and
1280x720. Single thread. Prints medians of wall and CPU time per frame and the ratios measured
in this run. Usage: python benchmarks/bench_conspicuity.py [--frames 8] [--reps 5]
"""
import os

for _var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ[_var] = "1"

import argparse  # noqa: E402
import json  # noqa: E402
import sys  # noqa: E402
import time  # noqa: E402
from pathlib import Path  # noqa: E402

import cv2  # noqa: E402
import numpy as np  # noqa: E402

import tsrkit  # noqa: E402
from tsrkit.types import Frame  # noqa: E402
from tsrkit_plugins.detectors.conspicuity import conspicuity_map  # noqa: E402
from tsrkit_plugins.detectors.localization import localize  # noqa: E402

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO / "tests"))
from oracles.conspicuity_oracle import conspicuity_reference  # noqa: E402

cv2.setNumThreads(1)
DATA = Path(os.environ.get("TSRKIT_DATA_DIR", REPO.parent / "shared" / "datasets"))


def frames(count, size):
    root = DATA / "roboflow_traffic_light_kr"
    entries = json.loads((root / "annotations.json").read_text())[:count]
    return [cv2.resize(cv2.imread(str(root / e["file"])), size, interpolation=cv2.INTER_AREA)
            for e in entries]


def timed(call, images, reps):
    """Median wall and CPU milliseconds of ``call(image)`` over all images and repetitions."""
    wall, cpu = [], []
    for _ in range(reps):
        for image in images:
            w0, c0 = time.perf_counter(), time.process_time()
            call(image)
            wall.append(time.perf_counter() - w0)
            cpu.append(time.process_time() - c0)
    return 1e3 * float(np.median(wall)), 1e3 * float(np.median(cpu))


def main():
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--frames", type=int, default=8)
    parser.add_argument("--reps", type=int, default=5)
    parser.add_argument("--oracle-frames", type=int, default=2)
    args = parser.parse_args()
    conspicuity = tsrkit.detector("conspicuity")
    tophat = tsrkit.detector("gray-tophat")
    small = frames(args.frames, (480, 356))
    large = frames(args.frames, (1280, 720))
    maps = [conspicuity_map(image) for image in small]

    results = {
        "conspicuity 480x356": timed(lambda im: conspicuity.detect(Frame(im, "b")), small,
                                     args.reps),
        "  map only": timed(conspicuity_map, small, args.reps),
        "  localization only": timed(
            lambda i: localize(maps[i].values, conspicuity.params, maps[i].radius),
            range(len(maps)), args.reps),
        "conspicuity 1280x720": timed(lambda im: conspicuity.detect(Frame(im, "b")), large,
                                      max(1, args.reps // 2)),
        "gray-tophat 480x356": timed(lambda im: tophat.detect(Frame(im, "b")), small,
                                     args.reps),
        "gray-tophat 1280x720": timed(lambda im: tophat.detect(Frame(im, "b")), large,
                                      max(1, args.reps // 2)),
    }
    oracle_images = small[:args.oracle_frames]
    results["oracle map 480x356"] = timed(conspicuity_reference, oracle_images, 1)
    worst = max(float(np.abs(conspicuity_map(im).values - conspicuity_reference(im)[0]).max())
                for im in oracle_images)

    print(f"{'what':28s} {'wall ms':>10s} {'cpu ms':>10s}")
    for name, (wall, cpu) in results.items():
        print(f"{name:28s} {wall:10.2f} {cpu:10.2f}")
    print(f"max |fast - oracle| on {len(oracle_images)} frames: {worst:.2e}")
    for kind in ("wall", "cpu"):
        k = 0 if kind == "wall" else 1
        print(f"[{kind}] oracle map / fast map: "
              f"{results['oracle map 480x356'][k] / results['  map only'][k]:.1f}x; "
              f"oracle map / fast detect: "
              f"{results['oracle map 480x356'][k] / results['conspicuity 480x356'][k]:.1f}x; "
              f"conspicuity 1280x720 / 480x356: "
              f"{results['conspicuity 1280x720'][k] / results['conspicuity 480x356'][k]:.2f}x; "
              f"gray-tophat 1280x720 / 480x356: "
              f"{results['gray-tophat 1280x720'][k] / results['gray-tophat 480x356'][k]:.2f}x")


if __name__ == "__main__":
    main()
