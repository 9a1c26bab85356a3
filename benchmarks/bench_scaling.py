"""Throughput of ``tsrkit.benchmark`` with 1..N worker processes, and its memory at 200 vs 2,000
frames, on synthetic 1280x720 frames (targets: efficiency >= 0.8, memory ratio <= 1.5).

Each run is a child process (``--child``) that benchmarks the first F frames of one generated
set (no cache, report writers ``json`` only, so the frame loop and the evaluation are timed, not
the plots); the parent samples the summed RSS of the child and its pool workers. Efficiency is
frames/s with N workers divided by N x frames/s with one, all in this one run.

    python benchmarks/bench_scaling.py                      # 2,000 frames, conspicuity + ab-hist
    python benchmarks/bench_scaling.py --frames 300 --detector gray-tophat --classifier ''
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import harness
from memory_benchmark import tree_rss


def child(frames: int, data: Path, detector: str, classifier: str, workers: int) -> None:
    """Benchmark the first ``frames`` frames of ``data`` (runs in the measured process)."""
    import tsrkit
    from tsrkit import Dataset
    from tsrkit.api import open_dataset

    harness.single_thread()
    full = open_dataset(str(data / "annotations.json"))
    subset = Dataset(f"synth-{frames}", full.samples[:frames], full.format, full.root)
    with tempfile.TemporaryDirectory() as out:
        report = tsrkit.benchmark(
            subset,
            tsrkit.detector(detector),
            tsrkit.classifier(classifier) if classifier else None,
            workers=workers,
            out=out,
            cache=False,
            writers=["json"],
        )
    print(report["frames"], report["timing"]["frames_per_second"])


def measure(frames: int, args: argparse.Namespace, workers: int) -> tuple[float, float, float]:
    """Peak tree RSS (MiB), wall seconds and the evaluated frames/s of one child run."""
    import psutil

    cmd = [sys.executable, __file__, "--child", str(frames), "--data", str(args.data)]
    cmd += ["--detector", args.detector, "--classifier", args.classifier]
    cmd += ["--workers", str(workers)]
    start = time.perf_counter()
    popen = subprocess.Popen(
        cmd, env={**os.environ, **harness.SINGLE_THREAD}, stdout=subprocess.PIPE
    )
    proc, peak = psutil.Process(popen.pid), 0
    while popen.poll() is None:
        peak = max(peak, tree_rss(proc))
        time.sleep(0.05)
    assert popen.stdout is not None
    output = popen.stdout.read().decode().split()
    if popen.returncode or len(output) != 2:
        raise SystemExit(f"child failed ({popen.returncode}) with {workers} workers")
    return peak / 2**20, time.perf_counter() - start, float(output[1])


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--child", type=int, default=None, help=argparse.SUPPRESS)
    harness.add_frames(parser, 2000)
    parser.add_argument("--data", type=Path, default=None, help="synthetic set (made if absent)")
    parser.add_argument("--detector", default="conspicuity")
    parser.add_argument("--classifier", default="ab-hist")
    parser.add_argument("--workers", default=None, help="comma list (default 1..cores)")
    args = parser.parse_args()
    if args.child is not None:
        child(args.child, args.data, args.detector, args.classifier, int(args.workers))
        return
    harness.announce()
    if args.data is None:
        args.data = Path(tempfile.gettempdir()) / f"tsrkit-scaling-{args.frames}-1280x720"
    if not (args.data / "annotations.json").is_file():
        from tsrkit.synth import generate

        print(f"rendering {args.frames} frames of 1280x720 into {args.data} ...", flush=True)
        generate(args.data, args.frames, seed=16, width=1280, height=720)
    cores = os.cpu_count() or 1
    counts = [int(w) for w in args.workers.split(",")] if args.workers else range(1, cores + 1)
    print(
        f"{args.frames} frames 1280x720, {args.detector} + {args.classifier or '-'}, {cores} cores"
    )
    base = None
    for n in counts:
        peak, wall, fps = measure(args.frames, args, n)
        base = base or fps
        print(
            f"workers {n}: {fps:6.2f} frames/s, wall {wall:6.1f} s, peak RSS {peak:6.0f} MiB, "
            f"speed-up {fps / base:4.2f}x, efficiency {fps / (n * base):4.2f}"
        )
    small = measure(min(200, args.frames), args, max(counts))[0]
    large = measure(args.frames, args, max(counts))[0]
    print(
        f"peak RSS with {max(counts)} workers: {min(200, args.frames)} frames {small:.0f} MiB, "
        f"{args.frames} frames {large:.0f} MiB, ratio {large / small:.2f} (target <= 1.5)"
    )


if __name__ == "__main__":
    main()
