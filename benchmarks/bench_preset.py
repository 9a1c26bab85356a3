"""Time the recommended preset on real 1280x720 road frames, end to end and per stage.

What a user runs, ``tsrkit.select(config="recommended").pipeline().process(frame)``, is timed on
one thread in CPU time (``time.process_time``), medians over the frames (each frame's median
over ``--repeats`` calls). The stages are timed on their own on the same frames: each member
of the ``union`` detector, the union's merge, the verifier (with the housing stage it runs
first) and the state classifier; the stages' sum is close to the end-to-end figure.

**Frames.** ``iwai_japan_tl``'s 1280x960 frames (one Japanese dash-cam), rows 120-839 cut out,
so each frame is a real 1280x720 road view without resampling; ``--frames`` of them, evenly
spaced in file order.

**Yardstick.** The straightforward ``filter2D`` conspicuity map
(``benchmarks/conspicuity_filter2d.py``) is timed on the same frames in the same process, and
every figure is also given as a share of it: on a shared machine that ratio holds where an
absolute time swings.

**Baseline.** ``--baseline COMMIT`` measures the tree of ``COMMIT`` too, in a second process
that takes turns with this one frame by frame (so both see the same load). Its tree is
installed, with its own entry points, in a virtual environment under ``benchmarks/out/at-COMMIT``
that borrows this environment's packages (``at_commit.python_at``, made once, reused). Only
what both trees have is called: the pipeline, the union's ``members`` and the module-level
``merge`` beside it.

``--members`` times this tree's preset with other union members (the baseline keeps its own).

Run: python benchmarks/bench_preset.py [--frames 12] [--repeats 3] [--baseline 42dcb98]
[--members "lab-blob top=30 scale_top=0.6; ..."] [--out benchmarks/out/bench_preset]
"""

from __future__ import annotations

import os

import harness

harness.single_thread()
os.environ["NUMBA_NUM_THREADS"] = "1"

import argparse  # noqa: E402
import json  # noqa: E402
import shlex  # noqa: E402
import statistics  # noqa: E402
import subprocess  # noqa: E402
import sys  # noqa: E402
import time  # noqa: E402
from pathlib import Path  # noqa: E402

import cv2  # noqa: E402
import numpy as np  # noqa: E402

REPO = harness.REPO

from at_commit import python_at  # noqa: E402
from conspicuity_filter2d import conspicuity_filter2d  # noqa: E402

import tsrkit  # noqa: E402
from tsrkit import Frame  # noqa: E402
from tsrkit.api import write_json  # noqa: E402

SET = "iwai_japan_tl"
#: The rows of a 1280x960 frame kept: its middle 720.
ROWS = (120, 840)


def frame_files(count: int) -> list[Path]:
    """``count`` of the set's 1280x960 frames, evenly spaced in file order."""
    root = harness.data_dir() / SET
    labels = root / "annotations.json"
    try:
        entries = json.loads(labels.read_text())
    except OSError as error:
        raise SystemExit(f"bench_preset: cannot read {labels}: {error}") from None
    files = sorted(e["file"] for e in entries if (e["width"], e["height"]) == (1280, 960))
    if count < 1 or count > len(files):
        raise SystemExit(f"bench_preset: --frames must be 1..{len(files)}; got {count}")
    picks = np.linspace(0, len(files) - 1, count).round().astype(int)
    return [root / files[i] for i in picks]


def load_frame(path: Path) -> Frame:
    """The middle 720 rows of a 1280x960 frame."""
    image = cv2.imread(str(path))
    if image is None:
        raise SystemExit(f"bench_preset: cannot read {path}")
    return Frame(np.ascontiguousarray(image[ROWS[0] : ROWS[1]]), str(path))


def cpu_ms(call, repeats: int) -> tuple[float, object]:
    """Median CPU ms of ``repeats`` calls of ``call()``, and its last result."""
    times, result = [], None
    for _ in range(repeats):
        start = time.process_time()
        result = call()
        times.append((time.process_time() - start) * 1000)
    return statistics.median(times), result


class Stages:
    """The recommended pipeline and its stages, callable one by one."""

    def __init__(self, members: str = ""):
        params = [f"detector.members={members}"] if members else []
        self.pipeline = tsrkit.select(config="recommended", params=params).pipeline()
        union = self.pipeline.detector
        self.members = union.members
        self.merge = sys.modules[type(union).__module__].merge
        self.merge_args = tuple(union.params[k] for k in ("merge", "min_distance", "reach_by"))

    def names(self) -> list[str]:
        """Stage names, in order."""
        members = [m.detector.name for m in self.members]
        return members + ["merge", "housing + verifier", "classifier"]

    def measure(self, frame: Frame, repeats: int) -> dict:
        """CPU ms of every stage, of ``process`` end to end and of the yardstick on ``frame``."""
        ms = {}
        lists = []
        for member in self.members:
            ms[member.detector.name], found = cpu_ms(lambda m=member: m.detect(frame), repeats)
            lists.append(found)
        ms["merge"], merged = cpu_ms(lambda: self.merge(lists, *self.merge_args), repeats)
        verifier, classifier = self.pipeline.verifier, self.pipeline.classifier
        ms["housing + verifier"], kept = cpu_ms(lambda: verifier.verify(frame, merged), repeats)
        ms["classifier"], _ = cpu_ms(lambda: classifier.classify(frame, kept), repeats)
        ms["end to end"], result = cpu_ms(lambda: self.pipeline.process(frame), repeats)
        ms["yardstick"], _ = cpu_ms(lambda: conspicuity_filter2d(frame.image), 1)
        counts = {"candidates": len(merged), "kept": len(kept), "reported": len(result.detections)}
        return {"ms": ms, "counts": counts}


def worker(files: list[Path], repeats: int) -> None:
    """Baseline side: warm up on the first frame, then measure frame ``i`` for every line
    ``i`` read from stdin and answer with one JSON line (the preset as it is at the baseline)."""
    stages = Stages()
    stages.measure(load_frame(files[0]), 1)
    print(json.dumps({"ready": True, "stages": stages.names()}), flush=True)
    for line in sys.stdin:
        print(json.dumps(stages.measure(load_frame(files[int(line)]), repeats)), flush=True)


def summary(rows: list[dict]) -> dict:
    """Median over frames of every stage's ms, and of its share of the yardstick."""
    names = list(rows[0]["ms"])
    out = {}
    for name in names:
        values = [r["ms"][name] for r in rows]
        shares = [r["ms"][name] / r["ms"]["yardstick"] for r in rows]
        out[name] = {"ms": statistics.median(values), "share": statistics.median(shares)}
    for key in rows[0]["counts"]:
        out[key] = statistics.median(r["counts"][key] for r in rows)
    return out


def markdown(now: dict, base: dict | None, commit: str) -> str:
    """The table: CPU ms and yardstick share per stage, now and at the baseline."""
    head = "| stage | CPU ms | / yardstick |"
    rule = "|---|---:|---:|"
    if base is not None:
        head += f" CPU ms at {commit} | / yardstick at {commit} | speed-up (ratio of shares) |"
        rule += "---:|---:|---:|"
    lines = [head, rule]
    names = [k for k, v in now.items() if isinstance(v, dict)]
    names += [k for k, v in (base or {}).items() if isinstance(v, dict) and k not in names]
    for name in names:
        cells = [name]
        row = now.get(name)
        cells += [f"{row['ms']:.1f}", f"{row['share']:.4f}"] if row else ["-", "-"]
        if base is not None:
            old = base.get(name)
            cells += [f"{old['ms']:.1f}", f"{old['share']:.4f}"] if old else ["-", "-"]
            cells.append(f"{old['share'] / row['share']:.2f}x" if row and old else "-")
        lines.append("| " + " | ".join(cells) + " |")
    counts = ", ".join(f"{k} {now[k]:g}" for k in ("candidates", "kept", "reported"))
    lines.append("")
    lines.append(f"medians per frame: {counts}")
    return "\n".join(lines)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--frames", type=int, default=12, help="frames to time (default 12)")
    parser.add_argument("--repeats", type=int, default=3, help="calls per frame (default 3)")
    parser.add_argument("--baseline", default="", help="commit measured in a second process")
    parser.add_argument("--out", default="benchmarks/out/bench_preset", help="results folder")
    parser.add_argument(
        "--members", default="", help="the union's members in this tree (default: the preset's)"
    )
    parser.add_argument("--worker", action="store_true", help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.repeats < 1:
        raise SystemExit("bench_preset: --repeats must be at least 1")
    files = frame_files(args.frames)
    if args.worker:
        worker(files, args.repeats)
        return
    command = "python benchmarks/bench_preset.py " + shlex.join(sys.argv[1:])
    harness.announce()
    child = None
    if args.baseline:
        script = [str(Path(__file__).resolve()), "--worker", "--frames", str(args.frames)]
        child = subprocess.Popen(
            [str(python_at(args.baseline)), *script, "--repeats", str(args.repeats)],
            stdin=subprocess.PIPE,
            stdout=subprocess.PIPE,
            text=True,
            cwd=REPO,
        )
        assert child.stdin is not None and child.stdout is not None
        json.loads(child.stdout.readline())
    stages = Stages(args.members)
    stages.measure(load_frame(files[0]), 1)
    rows, base_rows = [], []
    for i, path in enumerate(files):
        frame = load_frame(path)
        if child is not None:
            child.stdin.write(f"{i}\n")
            child.stdin.flush()
            base_rows.append(json.loads(child.stdout.readline()))
        rows.append(stages.measure(frame, args.repeats))
        print(f"frame {i}: {rows[-1]['ms']['end to end']:.1f} ms", flush=True)
    if child is not None:
        child.stdin.close()
        child.wait()
    now = summary(rows)
    base = summary(base_rows) if base_rows else None
    table = markdown(now, base, args.baseline)
    print(table)
    results = {"command": command, "summary": now, "baseline_summary": base}
    write_json(Path(args.out) / "results.json", {**results, "now": rows, "baseline": base_rows})


if __name__ == "__main__":
    main()
