"""Drives to answers (issue 39): ``tsrkit track`` on a rendered drive with mixed behaviour,
its ``timelines.csv`` and ``events.csv`` scored against the drive's truth.

    python benchmarks/study_events.py                      # 24 signalised traversals
    python benchmarks/study_events.py --nodes 30 --seed 5 --run-share 0.4

The drive (``tsrkit.synth.drive``, 480x356 at 10 fps, no trucks, green 10 s / amber 3 s /
all-red 1 s, a random route of signalised intersections 150 m apart, the driver ignoring the
signal on ``--run-share`` of them) is rendered once into benchmarks/out/study_events/ (git-
ignored) and reused; ``tsrkit track`` runs afresh (no cache). Scored
(:mod:`tsrkit.spatiotemporal.scoring`): events matched to truth (same traversal and kind,
within 0.5 s) precision and recall, red-light crossings flagged and false flags, timeline
state accuracy (share of the approach time both timelines cover) and the unknown share,
amber-onset distance error.
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
import time
from pathlib import Path

import harness

from tsrkit.spatiotemporal.scoring import score
from tsrkit.synth.behaviour import TRUTH_WINDOW_M
from tsrkit.synth.drive import DriveOptions, render_drive

WORK = harness.REPO / "benchmarks" / "out" / "study_events"
#: The detector setting of RESULTS.track.md's runs.
PLUGINS = ["-d", "conspicuity", "-c", "ab-hist", "-p", "h_peak=0.8", "-p", "radii=1,2,3,4,5,6"]


def rendered(folder: Path, options: DriveOptions, seed: int) -> Path:
    """The drive's folder, rendered unless an identical one exists."""
    stamp = folder / "drive.json"
    if stamp.is_file() and (folder / "truth_events.csv").is_file():
        old = json.loads(stamp.read_text())
        if old["seed"] == seed and old["options"] == json.loads(json.dumps(options.__dict__)):
            return folder
    start = time.perf_counter()
    render_drive(folder, options, seed)
    print(f"rendered {folder} in {time.perf_counter() - start:.0f} s", file=sys.stderr)
    return folder


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--nodes", type=int, default=24, help="signalised intersections")
    parser.add_argument("--seed", type=int, default=3)
    parser.add_argument("--run-share", type=float, default=0.3)
    args = parser.parse_args()
    options = DriveOptions(
        fps=10,
        random_nodes=args.nodes,
        signal_fraction=1.0,
        run_share=args.run_share,
        all_red_s=1.0,
        trucks=False,
    )
    name = f"n{args.nodes}_s{args.seed}_r{args.run_share}"
    drive = rendered(WORK / name, options, args.seed)
    out = WORK / f"{name}_run"
    for path in (out / "cache").rglob("*.json") if (out / "cache").exists() else ():
        path.unlink()
    command = [
        sys.executable, "-m", "tsrkit", "track", str(drive / "drive.mp4"),
        "--gps", str(drive / "gps.csv"), "--map", str(drive / "map.osm"),
        "--vicinity", str(TRUTH_WINDOW_M), "--out", str(out), "--quiet", *PLUGINS,
    ]  # fmt: skip
    start = time.perf_counter()
    subprocess.run(command, check=True, stdout=subprocess.DEVNULL)
    figures = score(out, drive)
    figures["track_seconds"] = round(time.perf_counter() - start, 1)
    figures["commit"] = harness.commit()
    figures["load"] = harness.load()
    print(json.dumps(figures, indent=1))


if __name__ == "__main__":
    main()
