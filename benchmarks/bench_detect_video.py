"""``tsrkit detect`` on a long 1280x720 video: frames/s with 1 worker and with every core.

The video (MPEG-4, 25 frames/s, 10 minutes by default) loops over a few synthetic 1280x720 road
frames; it is written once to the temporary folder. Each run is ``tsrkit detect VIDEO -w N -o
records.jsonl``, timed from the outside (start-up, decoding and writing included), and the record
files of all runs must be identical but for the per-frame ``ms``.

    python benchmarks/bench_detect_video.py                 # 10 min, gray-tophat, 1 and all cores
    python benchmarks/bench_detect_video.py --minutes 1 --detector conspicuity
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import harness

FPS = 25


def make_video(path: Path, minutes: float, unique: int = 50) -> int:
    """Write the looping video; returns its frame count."""
    import cv2

    from tsrkit.synth import generate

    frames_dir = path.with_suffix("")
    dataset = generate(frames_dir, unique, seed=3, width=1280, height=720, overwrite=True)
    images = [cv2.imread(s.source) for s in dataset.samples]
    total = int(minutes * 60 * FPS)
    writer = cv2.VideoWriter(str(path), cv2.VideoWriter_fourcc(*"mp4v"), FPS, (1280, 720))
    for i in range(total):
        writer.write(images[i % unique])
    writer.release()
    return total


def run(video: Path, detector: str, workers: int, out: Path) -> float:
    tsrkit = Path(sys.executable).parent / "tsrkit"
    env = {**os.environ, "OMP_NUM_THREADS": "1"}
    cmd = [str(tsrkit), "detect", str(video), "-d", detector, "-w", str(workers), "-o", str(out)]
    start = time.perf_counter()
    subprocess.run(cmd, check=True, env=env, stderr=subprocess.DEVNULL)
    return time.perf_counter() - start


def without_ms(path: Path) -> list[str]:
    lines = []
    for line in path.read_text().splitlines():
        record = json.loads(line)
        record.pop("ms")
        lines.append(json.dumps(record, sort_keys=True))
    return lines


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--minutes", type=float, default=10.0)
    parser.add_argument("--detector", default="gray-tophat")
    args = parser.parse_args()
    harness.announce()
    folder = Path(tempfile.gettempdir()) / "tsrkit-bench-video"
    folder.mkdir(exist_ok=True)
    video = folder / f"drive-{args.minutes:g}min.mp4"
    if not video.is_file():
        print(f"writing {video} ...", flush=True)
        make_video(video, args.minutes)
    cores = os.cpu_count() or 1
    print(f"{video.name}: 1280x720, {args.detector}, machine with {cores} cores", flush=True)
    outputs, base = [], None
    for workers in sorted({1, cores}):
        out = folder / f"records-{workers}.jsonl"
        wall = run(video, args.detector, workers, out)
        frames = len(out.read_text().splitlines())
        fps = frames / wall
        base = base or fps
        outputs.append(without_ms(out))
        print(
            f"workers {workers}: {frames} frames in {wall:.1f} s = {fps:.1f} frames/s "
            f"({fps / base:.2f}x)",
            flush=True,
        )
    print("records identical across worker counts:", all(o == outputs[0] for o in outputs))


if __name__ == "__main__":
    main()
