"""Start-up time of the command line: ``tsrkit --help`` and ``tsrkit plugins``.

Each command runs ``--runs`` times in a fresh interpreter (``python -m tsrkit``); the median
wall time is printed, with the bare interpreter and the old eager start-up (every plugin loaded
and every verb registered before anything else, which ``--help`` did before it became lazy)
measured the same way for comparison.

    python benchmarks/bench_startup.py [--runs 7]
"""

from __future__ import annotations

import argparse
import statistics
import subprocess
import sys
import time

import harness

COMMANDS = {
    "python -c pass (bare interpreter)": [sys.executable, "-c", "pass"],
    "tsrkit --help": [sys.executable, "-m", "tsrkit", "--help"],
    "tsrkit plugins": [sys.executable, "-m", "tsrkit", "plugins"],
    "eager start-up (all plugins and verbs loaded)": [
        sys.executable,
        "-c",
        "from tsrkit.cli.main import _add_commands; _add_commands()",
    ],
}


def median_seconds(command: list[str], runs: int) -> float:
    """Median wall time of ``runs`` runs of ``command`` (output discarded)."""
    times = []
    for _ in range(runs):
        start = time.perf_counter()
        subprocess.run(command, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, check=True)
        times.append(time.perf_counter() - start)
    return statistics.median(times)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=7)
    args = parser.parse_args()
    harness.announce()
    print(f"{args.runs} runs each")
    for label, command in COMMANDS.items():
        median_seconds(command, 1)  # warm the file cache
        print(f"{label:48s} median {median_seconds(command, args.runs):6.3f} s")


if __name__ == "__main__":
    main()
