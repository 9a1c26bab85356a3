"""Speed of the conspicuity and GRAY-TOPHAT detectors against the direct-correlation oracle,
against the straightforward OpenCV ``filter2D`` map (``conspicuity_filter2d.py``) and against an
earlier commit's conspicuity detector (its map, localization and kernel modules loaded from git:
A/B in the same run, outputs checked equal).

Frames: roboflow_traffic_light_kr road scenes resized to 480x356 (the thesis's size) and
1280x720. Single thread. The timed calls are interleaved (every repetition runs each call on
every frame in turn), so load from other processes falls on all of them alike. Prints the
first-call cost (numba compile or cache load), medians of wall and CPU time per frame and the
ratios measured in this run.
Usage: python benchmarks/bench_conspicuity.py [--frames 8] [--reps 5] [--baseline d213fc8]
"""

import harness

harness.single_thread()

import argparse  # noqa: E402
import importlib.util  # noqa: E402
import json  # noqa: E402
import re  # noqa: E402
import subprocess  # noqa: E402
import sys  # noqa: E402
import tempfile  # noqa: E402
import time  # noqa: E402
from pathlib import Path  # noqa: E402

import cv2  # noqa: E402
import numpy as np  # noqa: E402

import tsrkit  # noqa: E402
from tsrkit import Frame  # noqa: E402
from tsrkit_plugins.detectors.conspicuity import conspicuity_map  # noqa: E402
from tsrkit_plugins.detectors.localization import localize  # noqa: E402

REPO = harness.REPO
sys.path.insert(0, str(REPO / "tests"))
from at_commit import plugin_at  # noqa: E402
from conspicuity_filter2d import conspicuity_filter2d  # noqa: E402
from oracles.conspicuity_oracle import conspicuity_reference  # noqa: E402

DATA = harness.data_dir()


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


#: The modules of the conspicuity detector, in import order.
BASELINE_MODULES = ("conspicuity_kernel", "localization", "conspicuity")


def baseline_module(commit):
    """The conspicuity module of ``commit`` with the kernel and localization of that commit
    (``git show``, old flat or new package layout), imported as a package of its own."""
    package = f"conspicuity_at_{commit}"
    root = Path(tempfile.mkdtemp())
    (root / package).mkdir()
    (root / package / "__init__.py").write_text("")
    own = re.compile(
        r"tsrkit_plugins\.detectors\.(?:conspicuity\.)?(" + "|".join(BASELINE_MODULES) + r")\b"
    )
    for module in BASELINE_MODULES:
        for path in (
            f"plugins/detectors/{module}.py",
            f"plugins/detectors/conspicuity/{module}.py",
        ):
            shown = subprocess.run(
                ["git", "-C", str(REPO), "show", f"{commit}:{path}"], capture_output=True, text=True
            )
            if shown.returncode == 0:
                break
        else:
            raise SystemExit(f"commit {commit} has no {module}.py")
        (root / package / f"{module}.py").write_text(own.sub(rf"{package}.\1", shown.stdout))
    sys.path.insert(0, str(root))
    return importlib.import_module(f"{package}.conspicuity")


def baseline_detector(module):
    """The baseline module's detector with its default parameters."""
    return plugin_at(module.Conspicuity)


def same_output(old, new, detect_old, detect_new, images):
    """Frames on which the baseline's map or candidates differ from the current ones."""
    differ = 0
    for image in images:
        a, b = old(image), new(image)
        equal = np.array_equal(a.values, b.values) and np.array_equal(a.radius, b.radius)
        differ += not (equal and detect_old(image) == detect_new(image))
    return differ


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
    harness.add_frames(parser, 8)
    harness.add_repeats(parser, 5, flag="--reps")
    parser.add_argument("--oracle-frames", type=int, default=2)
    parser.add_argument(
        "--baseline",
        default="d213fc8",
        help="commit whose conspicuity detector is timed alongside ('' to skip)",
    )
    args = parser.parse_args()
    harness.announce()
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
        module = baseline_module(args.baseline)
        old = detect(baseline_detector(module))
        calls[f"baseline {args.baseline} map"] = (module.conspicuity_map, small)
        calls["  baseline map 1280x720"] = (module.conspicuity_map, large)
        calls["  baseline detect 1280x720"] = (old, large)
        new = detect(conspicuity)
        differ = same_output(module.conspicuity_map, conspicuity_map, old, new, small + large)
        print(
            f"frames whose map or candidates differ from {args.baseline}'s: "
            f"{differ} of {len(small) + len(large)}"
        )
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
            small_map = ratio(f"baseline {args.baseline} map", "  map only")
            large_map = ratio("  baseline map 1280x720", "  map only 1280x720")
            large_detect = ratio("  baseline detect 1280x720", "conspicuity 1280x720")
            line += (
                f"; {args.baseline} / now: map {small_map:.2f}x at 480x356, {large_map:.2f}x at "
                f"1280x720, detect {large_detect:.2f}x at 1280x720"
            )
        print(line)


if __name__ == "__main__":
    main()
