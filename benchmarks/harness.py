"""What every benchmark script shares: one thread, the datasets folder, common options, and the
record block (machine, commit, command, load) that a result in ``benchmarks/RESULTS*.md`` cites.

Scripts run from the repository root (``python benchmarks/NAME.py``), so this folder is first on
``sys.path`` and ``import harness`` finds this module. A timing script calls
:func:`single_thread` before it imports NumPy or OpenCV: OpenMP, OpenBLAS and MKL read their
thread counts when they load.

    import harness

    harness.single_thread()

    import numpy as np  # noqa: E402

    def main():
        parser = argparse.ArgumentParser(description=__doc__)
        harness.add_frames(parser, 10)
        harness.add_repeats(parser, 5)
        args = parser.parse_args()
        harness.announce()          # machine, commit, command, load now; load and time at exit
"""

from __future__ import annotations

import argparse
import atexit
import datetime
import os
import platform
import shlex
import subprocess
import sys
import time
from importlib import metadata
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
"""The repository root."""

SINGLE_THREAD = {"OMP_NUM_THREADS": "1", "OPENBLAS_NUM_THREADS": "1", "MKL_NUM_THREADS": "1"}
"""The environment that keeps OpenMP, OpenBLAS and MKL (and so NumPy, SciPy, scikit-learn) on
one thread; also given to child processes that must run single-threaded."""

LIBRARIES = ("numpy", "opencv-python-headless", "opencv-python", "numba", "scikit-learn", "scipy")
"""Distributions whose versions the machine block names (those installed)."""


def single_thread(opencv: bool = True) -> None:
    """Keep this process on one thread: set :data:`SINGLE_THREAD` and, with ``opencv``, call
    ``cv2.setNumThreads(1)``.

    Call it before NumPy, SciPy or OpenCV is imported; the BLAS variables have no effect later.
    """
    os.environ.update(SINGLE_THREAD)
    if opencv:
        import cv2

        cv2.setNumThreads(1)


def data_dir() -> Path:
    """The datasets folder: ``$TSRKIT_DATA_DIR``, else ``../shared/datasets`` beside the
    repository (the same rule as :mod:`tsrkit.datasets`)."""
    return Path(os.environ.get("TSRKIT_DATA_DIR", REPO.parent / "shared" / "datasets"))


def add_frames(parser: argparse.ArgumentParser, default: int, help: str | None = None) -> None:
    """``--frames N``: how many frames (or scenes) to time or evaluate."""
    parser.add_argument(
        "--frames", type=int, default=default, help=help or f"frames to use (default {default})"
    )


def add_repeats(
    parser: argparse.ArgumentParser, default: int, flag: str = "--repeats", help: str | None = None
) -> None:
    """``--repeats N`` (or another ``flag``, such as ``--reps``): timed repetitions per frame."""
    parser.add_argument(
        flag,
        type=int,
        default=default,
        help=help or f"timed repetitions of every call (default {default})",
    )


def commit() -> str:
    """The short hash of the checked-out commit, ``-dirty`` when tracked files differ from it,
    or ``unknown`` outside a git checkout."""

    def git(*args: str) -> subprocess.CompletedProcess[str]:
        return subprocess.run(
            ["git", "-C", str(REPO), *args], capture_output=True, text=True, check=False
        )

    head = git("rev-parse", "--short", "HEAD")
    if head.returncode != 0:
        return "unknown"
    dirty = git("diff", "--quiet", "HEAD", "--").returncode != 0
    return head.stdout.strip() + ("-dirty" if dirty else "")


def load() -> str:
    """The 1-, 5- and 15-minute load averages, as ``/proc/loadavg`` gives them."""
    return " ".join(f"{value:.2f}" for value in os.getloadavg())


def cpu_model() -> str:
    """The processor's model name (``/proc/cpuinfo``), else what :mod:`platform` knows."""
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or platform.machine()


def memory_gib() -> float | None:
    """Total memory in GiB (``/proc/meminfo``), or None where it cannot be read."""
    try:
        for line in Path("/proc/meminfo").read_text().splitlines():
            if line.startswith("MemTotal:"):
                return int(line.split()[1]) / 2**20
    except (OSError, ValueError, IndexError):
        pass
    return None


def machine() -> str:
    """One line naming the machine and the library versions a number depends on."""
    memory = memory_gib()
    parts = [
        f"{cpu_model()}, {os.cpu_count()} cores"
        + (f", {memory:.0f} GiB" if memory is not None else ""),
        f"Python {platform.python_version()}",
    ]
    for name in LIBRARIES:
        try:
            parts.append(f"{name} {metadata.version(name)}")
        except metadata.PackageNotFoundError:
            continue
    return "; ".join(parts)


def record_block() -> str:
    """The lines a recorded result cites: machine, commit, command, date and load at start."""
    command = shlex.join(["python", os.path.relpath(sys.argv[0], REPO), *sys.argv[1:]])
    now = datetime.datetime.now(datetime.UTC).strftime("%Y-%m-%d %H:%M UTC")
    return "\n".join(
        [
            f"machine: {machine()}",
            f"commit:  {commit()}",
            f"command: {command}",
            f"date:    {now}",
            f"load:    {load()} (start)",
        ]
    )


def announce() -> None:
    """Print :func:`record_block` now and, when the script ends, the load and the wall time."""
    start = time.perf_counter()
    print(record_block(), flush=True)

    def finish() -> None:
        print(f"load:    {load()} (end; {time.perf_counter() - start:.0f} s)", flush=True)

    atexit.register(finish)
