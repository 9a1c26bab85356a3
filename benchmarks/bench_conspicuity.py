"""Speed of the conspicuity and GRAY-TOPHAT detectors against the direct-correlation oracle
against the straightforward OpenCV ``filter2D`` map (``conspicuity_filter2d.py``) and against an
earlier commit's conspicuity map (A/B in the same run).

Frames: roboflow_traffic_light_kr road scenes resized to 480x356 (the thesis's size) and
1280x720. Single thread. The timed calls are interleaved (every repetition runs each call on
every frame in turn), so load from other processes falls on all of them alike. Prints the
first-call cost (numba compile or cache load), medians of wall and CPU time per frame and the
ratios measured in this run.
Usage: python benchmarks/bench_conspicuity.py [--frames 8] [--reps 5] [--baseline e57479b]
"""

import os

for _var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ[_var] = "1"

import argparse  # noqa: E402
import importlib.util  # noqa: E402
import json  # noqa: E402
import subprocess  # noqa: E402
import sys  # noqa: E402
import tempfile  # noqa: E402
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
from conspicuity_filter2d import conspicuity_filter2d  # noqa: E402
from oracles.conspicuity_oracle import conspicuity_reference  # noqa: E402

cv2.setNumThreads(1)
DATA = Path(os.environ.get("TSRKIT_DATA_DIR", REPO.parent / "shared" / "datasets"))


def frames(count, size):
    root = DATA / "roboflow_traffic_light_kr"
    entries = json.loads((root / "annotations.json").read_text())[:count]
    return [
        cv2.resize(cv2.imread(str(root / e["file"])), size, interpolation=cv2.INTER_AREA)
        for e in entries
    ]


def first_call_seconds():
    """Seconds of the first conspicuity map in this process (JIT compile or cache load)."""
    start = time.perf_counter()
    conspicuity_map(np.zeros((8, 8, 3), np.uint8))
    return time.perf_counter() - start


def baseline_map(commit):
    """``conspicuity_map`` of ``plugins/detectors/conspicuity.py`` at ``commit`` (git show)."""
    source = subprocess.run(
        ["git", "-C", str(REPO), "show", f"{commit}:plugins/detectors/conspicuity.py"],
        check=True,
        capture_output=True,
        text=True,
    ).stdout
    path = Path(tempfile.mkdtemp()) / "conspicuity_baseline.py"
    path.write_text(source)
    spec = importlib.util.spec_from_file_location("conspicuity_baseline", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module.conspicuity_map


def interleaved(calls, reps):
    """Median wall and CPU milliseconds per item of each ``name: (call, items)``; every
    repetition runs each call over its items in turn."""
    wall = {name: [] for name in calls}
    cpu = {name: [] for name in calls}
    for _ in range(reps):
        for name, (call, items) in calls.items():
            for item in items:
                w0, c0 = time.perf_counter(), time.process_time()
                call(item)
                wall[name].append(time.perf_counter() - w0)
                cpu[name].append(time.process_time() - c0)
    return {
        name: (1e3 * float(np.median(wall[name])), 1e3 * float(np.median(cpu[name])))
        for name in calls
    }


def main():
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--frames", type=int, default=8)
    parser.add_argument("--reps", type=int, default=5)
    parser.add_argument("--oracle-frames", type=int, default=2)
    parser.add_argument(
        "--baseline",
        default="e57479b",
        help="commit whose conspicuity map is timed alongside ('' to skip)",
    )
    args = parser.parse_args()
    print(f"first conspicuity_map call: {first_call_seconds():.2f} s")
    conspicuity = tsrkit.detector("conspicuity")
    tophat = tsrkit.detector("gray-tophat")
    small = frames(args.frames, (480, 356))
    large = frames(args.frames, (1280, 720))
    maps = [conspicuity_map(image) for image in small]

    def detect(detector):
        return lambda image: detector.detect(Frame(image, "b"))

    calls = {
        "conspicuity 480x356": (detect(conspicuity), small),
        "  map only": (conspicuity_map, small),
        "  localization only": (
            lambda i: localize(maps[i].values, conspicuity.params, maps[i].radius),
            range(len(maps)),
        ),
        "conspicuity 1280x720": (detect(conspicuity), large),
        "  map only 1280x720": (conspicuity_map, large),
        "filter2D map 480x356": (conspicuity_filter2d, small),
        "filter2D map 1280x720": (conspicuity_filter2d, large),
        "gray-tophat 480x356": (detect(tophat), small),
        "gray-tophat 1280x720": (detect(tophat), large),
    }
    if args.baseline:
        old_map = baseline_map(args.baseline)
        calls[f"baseline {args.baseline} map"] = (old_map, small)
        differ = sum(not np.array_equal(old_map(im).values, m.values) for im, m in zip(small, maps))
        print(f"frames whose map differs from {args.baseline}'s: {differ} of {len(small)}")
    results = interleaved(calls, args.reps)
    oracle_images = small[: args.oracle_frames]
    results["oracle map 480x356"] = interleaved(
        {"oracle": (conspicuity_reference, oracle_images)}, 1
    )["oracle"]
    worst = max(
        float(np.abs(conspicuity_map(im).values - conspicuity_reference(im)[0]).max())
        for im in oracle_images
    )

    print(f"{'what':28s} {'wall ms':>10s} {'cpu ms':>10s}")
    for name, (wall, cpu) in results.items():
        print(f"{name:28s} {wall:10.2f} {cpu:10.2f}")
    print(f"max |fast - oracle| on {len(oracle_images)} frames: {worst:.2e}")
    for k, kind in enumerate(("wall", "cpu")):

        def ratio(a, b, k=k):
            return results[a][k] / results[b][k]

        line = (
            f"[{kind}] oracle map / fast map: {ratio('oracle map 480x356', '  map only'):.1f}x;"
            f" oracle map / fast detect: "
            f"{ratio('oracle map 480x356', 'conspicuity 480x356'):.1f}x; conspicuity "
            f"1280x720 / 480x356: {ratio('conspicuity 1280x720', 'conspicuity 480x356'):.2f}x"
            f" (map only {ratio('  map only 1280x720', '  map only'):.2f}x); gray-tophat "
            f"1280x720 / 480x356: {ratio('gray-tophat 1280x720', 'gray-tophat 480x356'):.2f}x"
        )
        line += (
            f"; filter2D map / map: {ratio('filter2D map 480x356', '  map only'):.1f}x at "
            f"480x356, {ratio('filter2D map 1280x720', '  map only 1280x720'):.1f}x at 1280x720"
        )
        if args.baseline:
            baseline = ratio(f"baseline {args.baseline} map", "  map only")
            line += f"; baseline map / map: {baseline:.2f}x"
        print(line)


if __name__ == "__main__":
    main()
