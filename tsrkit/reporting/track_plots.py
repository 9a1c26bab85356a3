"""Figures of ``tsrkit track``, drawn into a given matplotlib figure: the vicinity profile
(Zheng 2016, Figure 3-13) and a timeline of each traversal's tracks (Figures 3-20 to 3-22: one
row per track, a filled marker per detected candidate, a hollow one per DOF candidate, coloured
by state)."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import TYPE_CHECKING, Any

import numpy as np

if TYPE_CHECKING:
    from matplotlib.figure import Figure

__all__ = ["STATE_COLOURS", "draw_timeline", "draw_vicinity"]

STATE_COLOURS = {"red": "#d62728", "yellow": "#e6a800", "green": "#2ca02c"}


def draw_vicinity(
    figure: Figure,
    frames: np.ndarray,
    distance: np.ndarray,
    vicinity: float,
    records: Sequence[Mapping[str, Any]],
) -> None:
    """Distance to the nearest intersection per frame, the threshold, clips shaded, anchors."""
    ax = figure.subplots()
    ax.plot(frames, distance, lw=0.8, color="#1f77b4", label="nearest signal")
    ax.axhline(vicinity, color="#d62728", lw=0.8, label=f"vicinity {vicinity:g} m")
    for k, record in enumerate(records):
        first = k == 0
        ax.axvspan(
            record["first_frame"],
            record["last_frame"],
            color="#ff7f0e",
            alpha=0.2,
            label="traversal clip" if first else None,
        )
        ax.plot(
            record["anchor_frame"],
            record["closest_m"],
            "s",
            mfc="none",
            color="#d62728",
            label="anchor frame" if first else None,
        )
    ax.set_ylim(0, max(3 * vicinity, 1.0))
    ax.set_xlabel("frame")
    ax.set_ylabel("nearest signal (m)")
    ax.legend(loc="upper right", fontsize=8)


def draw_timeline(figure: Figure, record: Mapping[str, Any]) -> None:
    """One row per track, frames across; the short range and the anchor marked."""
    tracks = record["tracks"]
    ax = figure.subplots()
    up, down = record["short_range"]
    ax.axvspan(up, down, color="#cccccc", alpha=0.5, label="short range")
    ax.axvline(record["anchor_frame"], color="k", lw=0.8, ls="--", label="anchor")
    for row, track in enumerate(tracks):
        for origin, filled in (("detected", True), ("dof", False)):
            points = [p for p in track["points"] if p["origin"] == origin]
            colours = [STATE_COLOURS.get(p["state"], "#7f7f7f") for p in points]
            ax.scatter(
                [p["frame"] for p in points],
                [row] * len(points),
                s=14,
                c=colours if filled else "none",
                edgecolors=colours,
                linewidths=0.8,
            )
    for state, colour in STATE_COLOURS.items():
        ax.scatter([], [], s=14, c=colour, label=state)
    ax.scatter([], [], s=14, c="none", edgecolors="#7f7f7f", label="DOF (hollow)")
    ax.set_yticks(range(len(tracks)), [f"track {t['id']}" for t in tracks])
    ax.set_ylim(-0.7, max(len(tracks), 1) - 0.3)
    ax.set_xlabel("frame")
    ax.set_title(
        f"traversal {record['traversal']}: intersection {record['intersection']}, "
        f"{record['movement']}",
        fontsize=9,
    )
    ax.legend(loc="upper left", bbox_to_anchor=(1.0, 1.0), fontsize=7)
