"""Zheng 2016, 3.4.2: the vicinity profile of 1 million synthetic positions against 10,000
signalised intersections, by the basic k-d tree query (scipy's cKDTree, one query per position)
and by Zheng's extended k-d tree recursion with tau_min = 1.5 s, timed in one run, answers
compared. Two drives: frames at 14 fps (the video case Zheng designed it for) and 1 Hz GPS fixes
(a log without video, where tau_min spans no position between two fixes).

    python benchmarks/bench_vicinity.py [--positions 1000000] [--side 100] [--repeats 3]
"""

from __future__ import annotations

import argparse
import time

import harness
import numpy as np
from scipy.spatial import cKDTree

from tsrkit.geo.nearest import TAU_MIN, nearest_extended, nearest_kdtree
from tsrkit.geo.simulate import grid_city, grid_drive


class CountingTree(cKDTree):
    """A cKDTree that counts the positions it is asked about."""

    searched = 0

    def query(self, x, *args, **kwargs):
        self.searched += len(x)
        return super().query(x, *args, **kwargs)


def best_of(repeats: int, method, *args) -> tuple[float, tuple]:
    times, answer = [], ()
    for _ in range(repeats):
        start = time.perf_counter()
        answer = method(*args)
        times.append(time.perf_counter() - start)
    return min(times), answer


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--positions", type=int, default=1_000_000)
    parser.add_argument("--side", type=int, default=100, help="grid side: side^2 signals")
    harness.add_repeats(parser, 3)
    args = parser.parse_args()
    harness.announce()
    city = grid_city(args.side, seed=0)
    print(
        f"{args.positions:,} positions, {len(city):,} signals, tau_min {TAU_MIN} s, "
        f"best of {args.repeats}"
    )
    start = time.perf_counter()
    tree = cKDTree(city)
    print(f"tree build: {1000 * (time.perf_counter() - start):.1f} ms (shared by both methods)")
    for fps in (14.0, 1.0):
        times, points = grid_drive(args.side, args.positions, fps=fps, seed=1)
        basic_s, (basic, basic_d) = best_of(args.repeats, nearest_kdtree, tree, points)
        ext_s, (ext, ext_d) = best_of(args.repeats, nearest_extended, tree, points, times)
        counting = CountingTree(city)
        nearest_extended(counting, points, times)
        differ = int(np.count_nonzero(basic != ext))
        print(
            f"{fps:4.0f} fps ({times[-1] / 3600:6.1f} h of driving): basic {basic_s:.3f} s, "
            f"extended {ext_s:.3f} s (x{basic_s / ext_s:.2f}), extended searched "
            f"{counting.searched:,} positions ({100 * counting.searched / len(points):.1f} %); "
            f"nearest differs at {differ} positions, "
            f"max distance difference {np.abs(basic_d - ext_d).max():.2e} m",
            flush=True,
        )


if __name__ == "__main__":
    main()
