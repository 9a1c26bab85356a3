"""Speed of TL-recognizer on 1413x1884 frames; the resize-factor trade-off (Mascetti 4.2, Fig. 18).

Real frames of roboflow_traffic_light_kr are stretched to 1413 wide x 1884 high (the paper's test
resolution) with their boxes; for resize factors 1-4 the script prints the median detection time
per frame (single thread; the factors are interleaved within every repetition of every frame, so
machine load falls on all of them alike) and the per-frame recall and precision that tsrkit's
runner measures on those frames. Usage: ``python benchmarks/bench_tl_recognizer.py
[-p context=housing ...]``.

``--cluttered N`` times the detector on the N most cluttered real frames at 1413x1884: of all
frames of the KR, cinTA and Japan sets (``iwai_japan_tl``) stretched to that size, those with
the most contours that survive pruning (city streets, signs, tail lights, foliage), against
the detector of ``--baseline`` (its ``tl_recognizer.py``, interleaved, outputs compared).

``--reference`` instead times the detector against its straightforward version
(``tl_recognizer_straightforward.py``) at 1280x720, separately on the road scenes and on
synthetic cluttered scenes (``--blobs`` saturated red, yellow and green blobs of 2-23 px on a
grey background, each a contour the detector must prune or validate), interleaved, and prints
the contour and candidate counts and how many of the reference's candidates the detector also
finds (same state, IoU >= 0.5); "scored" counts the contours per frame that survive pruning and
are validated.
"""

from __future__ import annotations

import harness

harness.single_thread()

import argparse  # noqa: E402
import json  # noqa: E402
import statistics  # noqa: E402
import sys  # noqa: E402
import tempfile  # noqa: E402
import time  # noqa: E402
from pathlib import Path  # noqa: E402

import cv2  # noqa: E402
import numpy as np  # noqa: E402

import tsrkit  # noqa: E402
from tsrkit import Annotation, Dataset, Frame, Sample  # noqa: E402
from tsrkit.api import iou_matrix  # noqa: E402

sys.path.insert(0, str(Path(__file__).resolve().parent))
from at_commit import module_at, plugin_at  # noqa: E402
from tl_recognizer_straightforward import tl_recognizer_straightforward  # noqa: E402

WIDTH, HEIGHT = 1413, 1884
REPO = harness.REPO
DATA = harness.data_dir()
#: Hues (OpenCV scale) of the cluttered scenes' blobs: red, orange-yellow, green, magenta-red.
CLUTTER_HUES = (5, 20, 80, 175)


def cluttered_scene(seed: int, blobs: int, size=(720, 1280)) -> np.ndarray:
    """A grey textured frame with ``blobs`` filled ellipses of saturated traffic-light hues
    (half-axes 1-11 px, any angle, overlapping at random): many contours per colour pass."""
    rng = np.random.default_rng(seed)
    image = cv2.GaussianBlur(rng.integers(60, 140, (*size, 3), dtype=np.uint8), (0, 0), 3)
    for hue in rng.choice(CLUTTER_HUES, blobs):
        hsv = np.uint8([[[hue, rng.integers(150, 256), rng.integers(120, 256)]]])
        colour = tuple(int(c) for c in cv2.cvtColor(hsv, cv2.COLOR_HSV2BGR)[0, 0])
        centre = (int(rng.integers(0, size[1])), int(rng.integers(0, size[0])))
        axes = (int(rng.integers(1, 12)), int(rng.integers(1, 12)))
        cv2.ellipse(image, centre, axes, float(rng.uniform(0, 180)), 0, 360, colour, -1)
    return image


def road_scenes(count: int, size=(1280, 720)) -> list[np.ndarray]:
    """The first ``count`` roboflow_traffic_light_kr frames resized to ``size``."""
    root = DATA / "roboflow_traffic_light_kr"
    entries = json.loads((root / "annotations.json").read_text())[:count]
    return [
        cv2.resize(cv2.imread(str(root / e["file"])), size, interpolation=cv2.INTER_AREA)
        for e in entries
    ]


def agreement(shipped, reference) -> tuple[int, int]:
    """Reference candidates with a shipped one of the same state at IoU >= 0.5, and all."""
    if not shipped or not reference:
        return 0, len(reference)
    overlap = iou_matrix([r.bbox for r in reference], [c.bbox for c in shipped])
    same = np.array([[r.state == c.state for c in shipped] for r in reference])
    return int(np.count_nonzero(((overlap >= 0.5) & same).any(axis=1))), len(reference)


def baseline_detector(commit: str, params: dict):
    """TL-recognizer as of ``commit`` (its ``tl_recognizer.py``), with ``params`` over the
    defaults."""
    cls = module_at(commit, "plugins/detectors/tl_recognizer/tl_recognizer.py").TlRecognizer
    return plugin_at(cls, **params)


def reference_comparison(
    params: dict, frames: int, blobs: int, repeats: int, baseline: str
) -> None:
    """Shipped detector against the straightforward version (and against the detector of
    commit ``baseline`` unless empty), road and cluttered scenes."""
    detector = tsrkit.detector("tl-recognizer", **params)
    old = baseline_detector(baseline, params) if baseline else None
    sets = {
        "road 1280x720": road_scenes(frames),
        f"cluttered 1280x720 ({blobs} blobs)": [cluttered_scene(s, blobs) for s in range(frames)],
    }
    print(
        f"{'scenes':>34} {'scored':>9} {'shipped ms':>10} {'reference ms':>12} {'ratio':>6} "
        f"{'candidates':>10} {'agree':>7}"
    )
    for name, images in sets.items():
        frames_ = [Frame(image, f"{name} {k}") for k, image in enumerate(images)]
        calls = {
            "shipped": detector.detect,
            "reference": lambda f: tl_recognizer_straightforward(detector, f),
        }
        if old is not None:
            calls["baseline"] = old.detect
            differ = sum(old.scored(f) != detector.scored(f) for f in frames_)
            print(f"{name}: frames whose candidates differ from {baseline}'s: {differ}")
        ms = interleaved_ms(calls, frames_, repeats)
        contours = np.mean([len(detector.scored(f)) for f in frames_])
        found = [
            agreement(detector.detect(f), tl_recognizer_straightforward(detector, f))
            for f in frames_
        ]
        shipped_count = sum(len(detector.detect(f)) for f in frames_)
        print(
            f"{name:>34} {contours:>9.0f} {ms['shipped']:>10.1f} {ms['reference']:>12.1f} "
            f"{ms['reference'] / ms['shipped']:>6.2f} {shipped_count:>10d} "
            f"{sum(a for a, _ in found)}/{sum(b for _, b in found)}"
        )
        if old is not None:
            print(
                f"{'':>34} {baseline} detector {ms['baseline']:.1f} ms: "
                f"{ms['baseline'] / ms['shipped']:.2f}x the shipped time"
            )


def cluttered_frames(count: int) -> list[Frame]:
    """The ``count`` real frames with the most pruned contours at WIDTH x HEIGHT (module
    docstring), most cluttered first."""
    detector = tsrkit.detector("tl-recognizer")
    ranked = []
    for name in ("roboflow_traffic_light_kr", "roboflow_cinta_v2_id", "iwai_japan_tl"):
        for sample in tsrkit.dataset(str(harness.data_dir() / name), format="normalized"):
            image = cv2.resize(sample.load().image, (WIDTH, HEIGHT), interpolation=cv2.INTER_LINEAR)
            ranked.append((len(detector.scored(Frame(image, sample.source))), sample.source))
    ranked.sort(key=lambda item: (-item[0], item[1]))
    frames = []
    for contours, source in ranked[:count]:
        image = cv2.resize(cv2.imread(source), (WIDTH, HEIGHT), interpolation=cv2.INTER_LINEAR)
        frames.append(Frame(image, source))
        print(f"  {contours:4d} contours  {Path(source).name}")
    return frames


def cluttered_comparison(params: dict, count: int, repeats: int, baseline: str) -> None:
    """This tree's detector against ``baseline``'s on the cluttered real frames."""
    print(f"the {count} most cluttered real frames at {WIDTH}x{HEIGHT}:")
    frames = cluttered_frames(count)
    detectors = {"this tree": tsrkit.detector("tl-recognizer", **params)}
    if baseline:
        detectors[baseline] = baseline_detector(baseline, params)
        differ = sum(
            detectors[baseline].detect(f) != detectors["this tree"].detect(f) for f in frames
        )
        print(f"frames whose candidates differ from {baseline}'s: {differ} of {len(frames)}")
    cpu = interleaved_ms(detectors, frames, repeats, clock=time.process_time)
    for key, ms in cpu.items():
        print(
            f"{key:>12}: {ms:.1f} ms CPU per frame (median over frames of the median of {repeats})"
        )


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


def interleaved_ms(detectors: dict, frames, repeats: int, clock=time.perf_counter) -> dict:
    """Median over frames of each frame's median detection time (ms, by ``clock``), per
    detector.

    Every repetition of every frame runs all detectors back to back, so slow spells of a shared
    machine hit each of them, not whichever happened to be measured then.
    """
    per_frame = {key: [] for key in detectors}
    for frame in frames:
        times = {key: [] for key in detectors}
        for _ in range(repeats):
            for key, detector in detectors.items():
                start = clock()
                (detector if callable(detector) else detector.detect)(frame)
                times[key].append((clock() - start) * 1000)
        for key in detectors:
            per_frame[key].append(statistics.median(times[key]))
    return {key: statistics.median(values) for key, values in per_frame.items()}


def parsed(pairs) -> dict:
    """``KEY=VALUE`` strings as a dict (values converted by the plugin's schema)."""
    return dict(pair.split("=", 1) for pair in pairs)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--dataset", default="roboflow_traffic_light_kr")
    harness.add_repeats(parser, 5)
    parser.add_argument(
        "-p",
        "--param",
        action="append",
        default=[],
        help="detector parameter KEY=VALUE (repeatable)",
    )
    parser.add_argument("--reference", action="store_true", help="time against the reference")
    parser.add_argument(
        "--cluttered", type=int, default=0, metavar="N", help="time on the N most cluttered frames"
    )
    harness.add_frames(parser, 5, help="frames per set (--reference)")
    parser.add_argument("--blobs", type=int, default=1500, help="blobs per cluttered scene")
    parser.add_argument(
        "--baseline", default="74eb292", help="commit timed alongside with --reference ('' to skip)"
    )
    args = parser.parse_args()
    harness.announce()
    params = parsed(args.param)
    if args.cluttered:
        cluttered_comparison(params, args.cluttered, args.repeats, args.baseline)
        return
    if args.reference:
        print(f"tl-recognizer params {params or 'default'}, {args.repeats} repetitions, one thread")
        reference_comparison(params, args.frames, args.blobs, args.repeats, args.baseline)
        return
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
