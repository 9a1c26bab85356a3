"""Where a ``tsrkit benchmark`` run spends its time beyond its frames, at two commits in one run.

Each measured run is the command line itself, ``tsrkit benchmark --dataset D -d conspicuity -c
ab-hist -w N -o FRESH_FOLDER -q`` (cache on, default writers), in a fresh interpreter whose
functions are wrapped to stamp the phases:

- ``start-up``: process start to the engine's first call (imports, options, dataset, plugins);
- ``warm-up``: engine start to the first frame record (pool start, per-worker imports, plugin and
  model loading, numba cache loads, and the first frame itself);
- ``frame loop``: first to last record;
- ``pool close``: last record to the engine's end (workers shut down);
- ``evaluation``: engine end to the first report writer's ``write`` (metrics, report content);
- ``writers``: the first writer's start to the last one's end (each one named in ``--detail``);
- ``exit``: the rest (the table printed, the process's end).

``fixed`` is the run's wall time minus its frames' share: ``wall - loop * N / (N - 1)`` (the loop
spans N - 1 frame intervals). CPU is the summed user + system time of the process and every
descendant (pool workers included), sampled every 50 ms.

An older commit runs from its own virtual environment (:func:`at_commit.python_at`: its tree
installed with its own entry points, this environment's other packages), every run in a
scratch folder (so that no ``tsrkit`` of the working directory shadows it); commits and worker
counts are interleaved within each repeat so that load shifts hit all of them alike. The
machine is shared: read the spreads (min, median, max over repeats) and the load.

    python benchmarks/bench_run_tail.py --repeats 5                  # 42dcb98 vs this tree
    python benchmarks/bench_run_tail.py --commits tree --workers 1,2 --detail
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import harness
from at_commit import python_at

from tsrkit.synth import generate

REPO = Path(__file__).resolve().parents[1]
PHASES = ("start-up", "warm-up", "frame loop", "pool close", "evaluation", "writers", "exit")
#: The stamps that bound the phases.
BOUNDS = (
    "begin",
    "engine_start",
    "first_record",
    "last_record",
    "engine_end",
    "first_writer",
    "last_writer",
    "end",
)

#: Runs in the measured interpreter: wraps the engine and the writers, then runs the CLI.
PROBE = r"""
import atexit, json, os, sys, time
marks = {"writers": {}, "cpu": {}}

def stamp(name, first=False):
    if not (first and name in marks):
        marks[name] = time.time()
        marks["cpu"][name] = time.process_time()

def save():
    stamp("exit")
    with open(os.environ["TAIL_MARKS"], "w") as fh:
        json.dump(marks, fh)

atexit.register(save)
import tsrkit.plugin.base
import tsrkit.reporting.benchmarking as B

def timed_write(write, name):
    def timed(self, run, folder):
        stamp("first_writer", first=True)
        begin = time.time()
        try:
            return write(self, run, folder)
        finally:
            marks["writers"][name] = marks["writers"].get(name, 0.0) + time.time() - begin
            stamp("last_writer")
    return timed

def writer_subclass(cls, **kwargs):
    super(tsrkit.plugin.base.ReportWriter, cls).__init_subclass__(**kwargs)
    if "write" in cls.__dict__:
        cls.write = timed_write(cls.write, cls.__dict__.get("name", cls.__name__))

tsrkit.plugin.base.ReportWriter.__init_subclass__ = classmethod(writer_subclass)
_run = B.run_records

def run_records(*args, **kwargs):
    stamp("engine_start")
    for record in _run(*args, **kwargs):
        stamp("first_record", first=True)
        stamp("last_record")
        yield record
    stamp("engine_end")

B.run_records = run_records
sys.argv = ["tsrkit", *sys.argv[1:]]
from tsrkit.cli.main import main
main()
"""


def tree_cpu(proc, seen: dict[int, float]) -> None:
    """Record the latest user + system seconds of ``proc`` and each descendant in ``seen``."""
    import psutil

    try:
        family = [proc, *proc.children(recursive=True)]
    except psutil.NoSuchProcess:
        return
    for p in family:
        try:
            times = p.cpu_times()
        except psutil.NoSuchProcess:
            continue
        seen[p.pid] = max(seen.get(p.pid, 0.0), times.user + times.system)


def measure(python: Path, dataset: Path, workers: int, out: Path, extra: list[str]) -> dict:
    """One run of the command: wall and CPU seconds, and the phases."""
    import psutil

    marks_file = out.with_suffix(".marks.json")
    env = {**os.environ, **harness.SINGLE_THREAD, "TAIL_MARKS": str(marks_file)}
    command = [str(python), "-c", PROBE, "benchmark", "--dataset", str(dataset)]
    command += ["-d", "conspicuity", "-c", "ab-hist", "-w", str(workers), "-o", str(out), "-q"]
    seen: dict[int, float] = {}
    begin = time.time()
    popen = subprocess.Popen(
        [*command, *extra],
        env=env,
        cwd=out.parent,
        stdout=subprocess.DEVNULL,
        stderr=subprocess.PIPE,
    )
    proc = psutil.Process(popen.pid)
    while popen.poll() is None:
        tree_cpu(proc, seen)
        time.sleep(0.05)
    end = time.time()
    assert popen.stderr is not None
    if popen.returncode:
        raise SystemExit(f"run failed ({popen.returncode}): {popen.stderr.read().decode()}")
    marks = json.loads(marks_file.read_text())
    marks["begin"], marks["end"], marks["cpu"]["begin"] = begin, end, 0.0
    marks["cpu"]["end"] = marks["cpu"]["exit"]
    for name in ("first_writer", "last_writer"):  # a run without writers
        marks.setdefault(name, marks["engine_end"])
        marks["cpu"].setdefault(name, marks["cpu"]["engine_end"])
    bounds = list(zip(PHASES, BOUNDS, BOUNDS[1:], strict=False))
    return {
        "wall": end - begin,
        "cpu": sum(seen.values()),
        "phases": {p: marks[b] - marks[a] for p, a, b in bounds},
        "main cpu": {p: marks["cpu"][b] - marks["cpu"][a] for p, a, b in bounds},
        "detail": marks["writers"],
    }


def spread(values: list[float]) -> str:
    """``median (min-max)`` of ``values``."""
    return f"{statistics.median(values):6.2f} ({min(values):5.2f}-{max(values):5.2f})"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--commits", default="42dcb98,tree", help="commits; 'tree': this tree")
    parser.add_argument("--frames", type=int, default=300)
    parser.add_argument("--workers", default="1,2")
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--data", type=Path, default=None, help="synthetic set (made if absent)")
    parser.add_argument("--detail", action="store_true", help="print each writer's seconds")
    parser.add_argument("extra", nargs="*", help="more benchmark options, after --")
    args = parser.parse_args()
    harness.announce()
    data = args.data or Path(tempfile.gettempdir()) / f"tsrkit-tail-{args.frames}"
    if not (data / "annotations.json").is_file():
        print(f"rendering {args.frames} frames of 480x356 into {data} ...", flush=True)
        generate(data, args.frames, seed=1)
    counts = [int(w) for w in args.workers.split(",")]
    work = Path(tempfile.mkdtemp(prefix="tsrkit-tail-"))
    trees = {
        c: Path(sys.executable) if c == "tree" else python_at(c) for c in args.commits.split(",")
    }
    warm = work / "warm"
    generate(warm, 4, seed=1)
    for commit, tree in trees.items():  # compiles a new tree's numba functions once
        measure(tree, warm / "annotations.json", 1, work / f"warm-{commit}", [])
    runs: dict[tuple[str, int], list[dict]] = {(c, w): [] for c in trees for w in counts}
    for r in range(args.repeats):
        for (commit, workers), done in runs.items():
            out = work / f"run-{commit}-{workers}-{r}"
            result = measure(trees[commit], data / "annotations.json", workers, out, args.extra)
            done.append(result)
            print(
                f"  repeat {r} {commit} -w {workers}: wall {result['wall']:.2f} s, "
                f"loop {result['phases']['frame loop']:.2f} s",
                flush=True,
            )
    print(f"load:    {harness.load()} (after the runs)")
    n = args.frames
    print(f"\n{n} frames 480x356, conspicuity + ab-hist; median (min-max) over {args.repeats}")
    for (commit, workers), done in runs.items():
        print(f"\n{commit} -w {workers}")
        print(f"  {'wall':12s} {spread([d['wall'] for d in done])} s")
        print(f"  {'tree CPU':12s} {spread([d['cpu'] for d in done])} s")
        fixed = [d["wall"] - d["phases"]["frame loop"] * n / (n - 1) for d in done]
        print(f"  {'fixed':12s} {spread(fixed)} s")
        for phase in PHASES:
            wall = spread([d["phases"][phase] for d in done])
            cpu = spread([d["main cpu"][phase] for d in done])
            print(f"  {phase:12s} {wall} s, main process CPU {cpu} s")
        if args.detail:
            for name in done[0]["detail"]:
                print(f"    {name:10s} {spread([d['detail'][name] for d in done])} s")
    for commit in trees:
        if 1 in counts:
            for workers in counts:
                if workers == 1:
                    continue
                ratio = [
                    a["wall"] / b["wall"]
                    for a, b in zip(runs[(commit, 1)], runs[(commit, workers)], strict=True)
                ]
                print(f"\n{commit}: wall -w 1 / -w {workers} per repeat {spread(ratio)}")


if __name__ == "__main__":
    main()
