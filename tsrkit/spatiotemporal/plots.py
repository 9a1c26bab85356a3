"""Figures of ``tsrkit track``: the vicinity profile (Zheng 2016, Figure 3-13) and a timeline
of each traversal's tracks (Figures 3-20 to 3-22: one row per track, a filled marker per
detected candidate, a hollow one per DOF candidate, coloured by state)."""

from __future__ import annotations

import io
import os
from typing import Any

import numpy as np

from tsrkit.atomic import atomic_open

__all__ = ["STATE_COLOURS", "timeline_plot", "vicinity_plot"]

STATE_COLOURS = {"red": "#d62728", "yellow": "#e6a800", "green": "#2ca02c"}


def _save(figure, path: str | os.PathLike) -> None:
    buffer = io.BytesIO()
    figure.savefig(buffer, format="png", dpi=110)
    with atomic_open(path, "wb") as fh:
        fh.write(buffer.getvalue())


def vicinity_plot(
    frames: np.ndarray,
    distance: np.ndarray,
    vicinity: float,
    records: list[dict[str, Any]],
    path: str | os.PathLike,
) -> None:
    """Distance to the nearest intersection per frame, the threshold, clips shaded, anchors."""
    from matplotlib.figure import Figure

    figure = Figure(figsize=(9, 3.2))
    ax = figure.subplots()
    ax.plot(frames, distance, lw=0.8, color="#1f77b4")
    ax.axhline(vicinity, color="#d62728", lw=0.8, label=f"vicinity {vicinity:g} m")
    for record in records:
        ax.axvspan(record["first_frame"], record["last_frame"], color="#ff7f0e", alpha=0.2)
        ax.plot(record["anchor_frame"], record["closest_m"], "s", mfc="none", color="#d62728")
    ax.set_ylim(0, max(3 * vicinity, 1.0))
    ax.set_xlabel("frame")
    ax.set_ylabel("nearest signal (m)")
    ax.legend(loc="upper right", fontsize=8)
    figure.tight_layout()
    _save(figure, path)


def timeline_plot(record: dict[str, Any], path: str | os.PathLike) -> None:
    """One row per track, frames across; the short range and the anchor marked."""
    from matplotlib.figure import Figure

    tracks = record["tracks"]
    figure = Figure(figsize=(9, 1.2 + 0.45 * max(len(tracks), 1)))
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
    ax.set_yticks(range(len(tracks)), [f"track {t['id']}" for t in tracks])
    ax.set_ylim(-0.7, max(len(tracks), 1) - 0.3)
    ax.set_xlabel("frame")
    ax.set_title(
        f"traversal {record['traversal']}: intersection {record['intersection']}, "
        f"{record['movement']}",
        fontsize=9,
    )
    ax.legend(loc="upper left", bbox_to_anchor=(1.0, 1.0), fontsize=7)
    figure.tight_layout()
    _save(figure, path)
