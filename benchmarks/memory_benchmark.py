"""Peak memory of ``tsrkit.benchmark`` on 200 vs 2,000 synthetic frames (the runner streams).

Each run is a child process (``--child N``) benchmarking the first N frames of one generated
synthetic set with gray-tophat, 2 worker processes, no cache; the parent samples the summed RSS
of the child and all its descendants (the pool workers) every 20 ms and keeps the peak.

    python benchmarks/memory_benchmark.py [--repeats 3] [--data DIR]
"""

from __future__ import annotations

import argparse
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import harness

SIZES = (200, 2000)


def child(frames: int, data: Path, detector: str, workers: int) -> None:
    """Benchmark the first ``frames`` frames of ``data`` (runs in the measured process)."""
    import tsrkit
    from tsrkit import Dataset
    from tsrkit.api import open_dataset

    harness.single_thread()
    full = open_dataset(str(data / "annotations.json"))
    subset = Dataset(f"synth-{frames}", full.samples[:frames], full.format, full.root)
    with tempfile.TemporaryDirectory() as out:
        report = tsrkit.benchmark(
            subset, tsrkit.detector(detector), workers=workers, out=out, cache=False
        )
    print(report["frames"], report["timing"]["frames_per_second"])


def tree_rss(proc) -> int:
    """Summed resident memory of a process and its descendants, in bytes."""
    import psutil

    total = 0
    for p in [proc] + proc.children(recursive=True):
        try:
            total += p.memory_info().rss
        except psutil.NoSuchProcess:
            continue
    return total


def measure(frames: int, data: Path, detector: str, workers: int) -> tuple[float, float, str]:
    """Peak tree RSS (MiB), wall seconds and the child's output for one run."""
    import psutil

    env = {**os.environ, **harness.SINGLE_THREAD}
    cmd = [
        sys.executable,
        __file__,
        "--child",
        str(frames),
        "--data",
        str(data),
        "--detector",
        detector,
        "--workers",
        str(workers),
    ]
    start = time.perf_counter()
    popen = subprocess.Popen(cmd, env=env, stdout=subprocess.PIPE, text=True)
    proc = psutil.Process(popen.pid)
    peak = 0
    while popen.poll() is None:
        peak = max(peak, tree_rss(proc))
        time.sleep(0.02)
    output = popen.stdout.read().strip()
    if popen.returncode:
        raise SystemExit(f"child failed ({popen.returncode}) on {frames} frames")
    return peak / 2**20, time.perf_counter() - start, output


def ensure_data(folder: Path) -> Path:
    """Generate the 2,000-frame synthetic set once (outside the repository)."""
    from tsrkit.synth import generate

    if not (folder / "annotations.json").is_file():
        print(f"generating {max(SIZES)} synthetic frames into {folder} ...", flush=True)
        generate(folder, max(SIZES), seed=7)
    return folder


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--child", type=int, default=None, help=argparse.SUPPRESS)
    parser.add_argument(
        "--data", type=Path, default=Path(tempfile.gettempdir()) / "tsrkit-memory-bench-2000"
    )
    parser.add_argument("--detector", default="gray-tophat")
    parser.add_argument("--workers", type=int, default=2)
    harness.add_repeats(parser, 3)
    args = parser.parse_args()
    if args.child is not None:
        child(args.child, args.data, args.detector, args.workers)
        return
    harness.announce()
    data = ensure_data(args.data)
    peaks = {}
    for frames in SIZES:
        runs = [measure(frames, data, args.detector, args.workers) for _ in range(args.repeats)]
        peaks[frames] = statistics.median(r[0] for r in runs)
        for peak, wall, output in runs:
            print(
                f"{frames:5d} frames: peak RSS {peak:7.1f} MiB, wall {wall:6.1f} s "
                f"(frames, frames/s: {output})"
            )
    small, large = peaks[SIZES[0]], peaks[SIZES[1]]
    print(
        f"median peak RSS: {SIZES[0]} frames {small:.1f} MiB, {SIZES[1]} frames "
        f"{large:.1f} MiB, ratio {large / small:.2f} (target <= 1.5)"
    )


if __name__ == "__main__":
    main()
