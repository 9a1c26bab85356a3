"""Frames per second of ``tsrkit detect VIDEO --config recommended -w 2`` on 1280x720 video, at an
earlier commit and in this tree, in one run.

The video is rendered once into ``benchmarks/out/detect_fps/`` with the command a user would
type, ``tsrkit datasets synth --out DIR --frames N --width 1280 --height 720 --video
drive.mp4`` (independent synthetic road scenes, 10 frames/s). Each measured run is the whole
command, ``PYTHON -m tsrkit detect VIDEO --config recommended -w 2 -o OUT -q`` from a scratch
folder, timed from the outside (start-up, decoding, writing included): frames per second is the
frame count over its wall time; CPU is the summed user + system time of the command and its
worker processes. The earlier commit runs from its own environment
(:func:`at_commit.python_at`); commits alternate within each repeat. ``--key-every K`` adds runs
of this tree with key frames every K frames on a rendered drive (:mod:`tsrkit.synth.drive` at
1280x720: consecutive frames of one drive, where following pays); the drive's frames per
second with K = 1 is printed beside them.

    python benchmarks/bench_detect_fps.py --repeats 3                     # 42dcb98 vs this tree
    python benchmarks/bench_detect_fps.py --frames 100 --key-every 4 --drive-frames 200
"""

from __future__ import annotations

import argparse
import os
import statistics
import subprocess
import sys
import time
from pathlib import Path

import harness
from at_commit import python_at
from bench_run_tail import tree_cpu

WORK = harness.REPO / "benchmarks" / "out" / "detect_fps"


def render_video(frames: int) -> Path:
    """The synthetic 1280x720 video of ``frames`` frames (rendered once)."""
    folder = WORK / f"synth-{frames}"
    video = folder / "drive.mp4"
    if not video.is_file():
        command = [sys.executable, "-m", "tsrkit", "datasets", "synth", "--out", str(folder)]
        command += ["--frames", str(frames), "--seed", "7", "--width", "1280", "--height", "720"]
        subprocess.run([*command, "--video", str(video), "-q"], check=True)
    return video


def render_drive(frames: int) -> Path:
    """A rendered 1280x720 drive through one intersection, cut to its first ``frames``."""
    from tsrkit.synth.drive import DriveOptions, render_drive

    folder = WORK / "drive-1280x720"
    if not (folder / "drive.mp4").is_file():
        render_drive(folder, DriveOptions(width=1280, height=720, route=("left",)), seed=0)
    return folder / "drive.mp4"


def measure(python: Path, video: Path, extra: list[str], out: Path) -> tuple[float, float, int]:
    """Wall seconds, tree CPU seconds and records of one ``detect`` run."""
    import psutil

    command = [str(python), "-m", "tsrkit", "detect", str(video), "--config", "recommended"]
    command += ["-w", "2", "-o", str(out), "-q", *extra]
    seen: dict[int, float] = {}
    begin = time.perf_counter()
    popen = subprocess.Popen(
        command,
        cwd=out.parent,
        env={**os.environ, **harness.SINGLE_THREAD},
        stdout=subprocess.DEVNULL,
        stderr=subprocess.PIPE,
    )
    proc = psutil.Process(popen.pid)
    while popen.poll() is None:
        tree_cpu(proc, seen)
        time.sleep(0.05)
    wall = time.perf_counter() - begin
    assert popen.stderr is not None
    if popen.returncode:
        raise SystemExit(f"detect failed ({popen.returncode}): {popen.stderr.read().decode()}")
    return wall, sum(seen.values()), len(out.read_text().splitlines())


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--baseline", default="42dcb98")
    harness.add_frames(parser, 100, "frames of the synthetic video (default 100)")
    harness.add_repeats(parser, 3)
    parser.add_argument("--key-every", default="", help="comma list of K for the drive runs")
    parser.add_argument("--drive-frames", type=int, default=200)
    args = parser.parse_args()
    harness.announce()
    WORK.mkdir(parents=True, exist_ok=True)
    runs: dict[str, tuple[Path, Path, list[str]]] = {
        args.baseline: (python_at(args.baseline), render_video(args.frames), []),
        "tree": (Path(sys.executable), render_video(args.frames), []),
    }
    keys = [int(k) for k in args.key_every.split(",") if k]
    if keys:
        drive = render_drive(args.drive_frames)
        runs["tree, drive, K 1"] = (Path(sys.executable), drive, ["--end", str(args.drive_frames)])
        for k in keys:
            extra = ["--end", str(args.drive_frames), "--key-every", str(k)]
            runs[f"tree, drive, K {k}"] = (Path(sys.executable), drive, extra)
    for python, video, extra in runs.values():  # a new tree compiles its numba functions once
        measure(python, video, [*extra, "--end", "2"], WORK / "warm.jsonl")
    results: dict[str, list[tuple[float, float, int]]] = {label: [] for label in runs}
    for r in range(args.repeats):
        for label, (python, video, extra) in runs.items():
            done = measure(python, video, extra, WORK / f"run-{r}.jsonl")
            results[label].append(done)
            print(f"  repeat {r} {label}: {done[2]} frames, wall {done[0]:.1f} s", flush=True)
    print("\n| run | frames | frames/s (median, min-max) | wall s | tree CPU s | CPU ms/frame |")
    print("|---|---:|---|---:|---:|---:|")
    for label, done in results.items():
        fps = [n / wall for wall, _, n in done]
        wall = statistics.median(d[0] for d in done)
        cpu = statistics.median(d[1] for d in done)
        n = done[0][2]
        print(
            f"| {label} | {n} | {statistics.median(fps):.2f} ({min(fps):.2f}-{max(fps):.2f}) "
            f"| {wall:.1f} | {cpu:.1f} | {1000 * cpu / n:.0f} |"
        )


if __name__ == "__main__":
    main()
