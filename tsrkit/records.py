"""The per-frame record: what the engine yields, the cache stores and the metrics read.

A :class:`FrameRecord` holds one frame's size, compute time, lighting and its detections as
:class:`DetectionRecord` values (rounded as written to disk), or the reason it was skipped.
``to_json`` / ``from_json`` are the one place records become JSON (the cache, ``detect`` and
``detections.jsonl`` all write this form) and come back.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any

from tsrkit.geometry import Box

__all__ = ["BOX_CHOICES", "DECIMALS", "DetectionRecord", "FrameRecord"]

#: Decimals kept for coordinates (and ``ms``) in records.
DECIMALS = 3
#: The boxes an evaluation can read from a record (``--eval-box``).
BOX_CHOICES = ("lens", "housing")


def _rounded(values) -> Box:
    x0, y0, x1, y1 = (round(float(v), DECIMALS) for v in values)
    return x0, y0, x1, y1


@dataclass(frozen=True)
class DetectionRecord:
    """One reported object as written to disk.

    ``bbox`` is the housing once a verifier fitted one, else the lens box; ``lens_bbox`` is
    always the lens box (the lit lens the housing was fitted around, once a housing stage
    ran). ``x``, ``y`` and ``radius`` are the detector's lens circle.
    """

    x: float
    y: float
    radius: float
    bbox: Box
    lens_bbox: Box
    score: float
    state: str = "unknown"
    state_scores: Mapping[str, float] = field(default_factory=dict)
    origin: str = "detected"
    housing_score: float | None = None
    track_id: int | None = None
    distance_m: float | None = None

    @classmethod
    def from_detection(cls, detection) -> DetectionRecord:
        """The record of a :class:`tsrkit.types.Detection` (coordinates rounded)."""
        c = detection.candidate
        return cls(
            round(c.x, DECIMALS),
            round(c.y, DECIMALS),
            round(c.radius, DECIMALS),
            _rounded(c.object_bbox),
            _rounded(c.bbox),
            float(c.score),
            detection.state,
            {k: float(v) for k, v in detection.state_scores.items()},
            detection.origin,
            None if c.housing_score is None else round(float(c.housing_score), 4),
            detection.track_id,
            None if c.distance_m is None else round(float(c.distance_m), DECIMALS),
        )

    def box(self, which: str) -> Box:
        """``lens_bbox`` for ``"lens"``, ``bbox`` (housing when fitted) for ``"housing"``."""
        if which not in BOX_CHOICES:
            raise ValueError(f"box must be one of {', '.join(BOX_CHOICES)}; got {which!r}")
        return self.lens_bbox if which == "lens" else self.bbox

    def to_json(self) -> dict[str, Any]:
        """The JSON object of ``tsrkit detect`` for this detection."""
        out: dict[str, Any] = {
            "x": self.x,
            "y": self.y,
            "radius": self.radius,
            "bbox": list(self.bbox),
            "lens_bbox": list(self.lens_bbox),
            "score": self.score,
            "state": self.state,
            "state_scores": dict(self.state_scores),
            "origin": self.origin,
        }
        if self.housing_score is not None:
            out["housing_score"] = self.housing_score
        if self.track_id is not None:
            out["track_id"] = self.track_id
        if self.distance_m is not None:
            out["distance_m"] = self.distance_m
        return out

    @classmethod
    def from_json(cls, data: Mapping[str, Any]) -> DetectionRecord:
        """Read :meth:`to_json`'s form back (older records without ``lens_bbox`` too)."""
        bbox = tuple(data["bbox"])
        return cls(
            data["x"],
            data["y"],
            data["radius"],
            bbox,
            tuple(data.get("lens_bbox", bbox)),
            data["score"],
            data.get("state", "unknown"),
            dict(data.get("state_scores", {})),
            data.get("origin", "detected"),
            data.get("housing_score"),
            data.get("track_id"),
            data.get("distance_m"),
        )


@dataclass(frozen=True)
class FrameRecord:
    """One frame's result: its detections, or why it was skipped.

    ``index`` is the position in the dataset (or the frame number of a video); ``cached``
    says whether the engine read the record from its cache (never written to JSON).
    """

    source: str
    index: int = 0
    width: int = 0
    height: int = 0
    ms: float = 0.0
    lighting: str | None = None
    detections: tuple[DetectionRecord, ...] = ()
    skipped: str | None = None
    cached: bool = field(default=False, compare=False)
    notes: tuple[str, ...] = ()

    @classmethod
    def from_result(cls, result, lighting: str | None = None) -> FrameRecord:
        """The record of a :class:`tsrkit.pipeline.FrameResult`."""
        return cls(
            result.source,
            result.index,
            result.width,
            result.height,
            result.ms,
            lighting,
            tuple(DetectionRecord.from_detection(d) for d in result.detections),
            notes=tuple(result.notes),
        )

    def to_json(self) -> dict[str, Any]:
        """``{"source", "frame", "width", "height", "ms", ["lighting"], "detections",
        ["notes"]}``, or ``{"source", "frame", "skipped"}``."""
        if self.skipped is not None:
            return {"source": self.source, "frame": self.index, "skipped": self.skipped}
        out: dict[str, Any] = {
            "source": self.source,
            "frame": self.index,
            "width": self.width,
            "height": self.height,
            "ms": round(self.ms, DECIMALS),
        }
        if self.lighting is not None:
            out["lighting"] = self.lighting
        out["detections"] = [d.to_json() for d in self.detections]
        if self.notes:
            out["notes"] = list(self.notes)
        return out

    @classmethod
    def from_json(cls, data: Mapping[str, Any]) -> FrameRecord:
        """Read :meth:`to_json`'s form back."""
        if "skipped" in data:
            return cls(data["source"], data.get("frame", 0), skipped=data["skipped"])
        return cls(
            data["source"],
            data.get("frame", 0),
            data["width"],
            data["height"],
            data["ms"],
            data.get("lighting"),
            tuple(DetectionRecord.from_json(d) for d in data["detections"]),
            notes=tuple(str(n) for n in data.get("notes", ())),
        )
