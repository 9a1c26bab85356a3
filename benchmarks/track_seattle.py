"""``tsrkit track`` on the real Seattle drive and the Bellevue OpenStreetMap extract: the
traversals found, a check against the dataset README's "16 signals within 30 m of the track",
and the vicinity profile plot (Zheng 2016, Figure 3-13 style) written to benchmarks/.

    python benchmarks/track_seattle.py
"""

from __future__ import annotations

import argparse
from datetime import UTC, datetime

import harness
import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np
from scipy.spatial import cKDTree

from tsrkit.api import read_track
from tsrkit.geo import read_signals, traversals
from tsrkit.geo.osm import _nodes
from tsrkit.geo.vicinity import vicinity_profile

REPO = harness.REPO
DATA = harness.data_dir()
SET = DATA / "nk_seattle_gps_bellevue_osm"


def utc(seconds: float) -> str:
    return datetime.fromtimestamp(seconds, UTC).strftime("%H:%M:%S")


def main() -> None:
    argparse.ArgumentParser(description=__doc__).parse_args()  # --help only
    harness.announce()
    track = read_track(SET / "gps_data.txt")
    signals = read_signals(SET / "map-issue147.osm.gz")
    found = traversals(track, signals, 30.0)
    _, distance, projection = vicinity_profile(track, signals)
    raw = [
        n for n in _nodes(SET / "map-issue147.osm.gz") if n[3].get("highway") == "traffic_signals"
    ]
    rx, ry = projection(np.array([n[1] for n in raw]), np.array([n[2] for n in raw]))
    tx, ty = projection(track.lat, track.lon)
    near_raw, _ = cKDTree(np.column_stack([tx, ty])).query(np.column_stack([rx, ry]))
    print(
        f"{len(track)} fixes, {len(raw)} highway=traffic_signals nodes -> {len(signals)} "
        f"intersections (merged within 50 m); nodes within 30 m of the track: "
        f"{int((near_raw <= 30).sum())}; intersections traversed: "
        f"{len({t.intersection for t in found})} in {len(found)} traversals"
    )
    traversed = {i for t in found for i in signals.ids[t.intersection]}
    near_ids = {raw[k][0] for k in np.flatnonzero(near_raw <= 30)}
    print(
        f"nodes within 30 m that belong to a traversed intersection: "
        f"{len(near_ids & traversed)} of {len(near_ids)}"
    )
    print(
        "\n| # | intersection (OSM node ids) | lat, lon | entry - exit (UTC, 2009-01-17) "
        "| closest m | movement (turn deg) |"
    )
    print("|---:|---|---|---|---:|---|")
    for k, t in enumerate(found, 1):
        ids = ", ".join(map(str, signals.ids[t.intersection]))
        print(
            f"| {k} | {t.intersection} ({ids}) | {signals.lat[t.intersection]:.5f}, "
            f"{signals.lon[t.intersection]:.5f} | {utc(t.entry)} - {utc(t.exit)} | "
            f"{t.closest_m:.1f} | {t.movement} ({t.turn_deg:+.0f}) |"
        )
    minutes = (track.time - track.time[0]) / 60
    fig, ax = plt.subplots(figsize=(10, 3.2))
    ax.plot(minutes, distance, lw=0.7, color="tab:blue", label="distance to nearest intersection")
    ax.axhline(30, color="tab:red", lw=0.8, ls="--", label="vicinity 30 m")
    for t in found:
        ax.axvspan(
            (t.entry - track.time[0]) / 60,
            (t.exit - track.time[0]) / 60 + 1 / 60,
            color="tab:orange",
            alpha=0.4,
        )
    ax.set_ylim(0, 400)
    inside = minutes[distance < 1000]  # the part of the drive inside the extract's bounds
    ax.set_xlim(inside.min() - 0.5, inside.max() + 0.5)
    ax.set_xlabel("minutes since the first fix (20:27:37 UTC); the part inside the extract")
    ax.set_ylabel("metres")
    ax.set_title("Vicinity profile of the Seattle drive, Bellevue OSM signals (traversals shaded)")
    ax.legend(loc="upper right", fontsize=8)
    fig.tight_layout()
    out = REPO / "benchmarks" / "track_vicinity.png"
    fig.savefig(out, dpi=100)
    print(f"\nplot: {out.relative_to(REPO)}")


if __name__ == "__main__":
    main()
