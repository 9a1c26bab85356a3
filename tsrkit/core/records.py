"""The per-frame record: what the engine yields, the cache stores and the metrics read.

A :class:`FrameRecord` holds one frame's size, compute time, lighting and its detections as
:class:`DetectionRecord` values (rounded as written to disk), or the reason it was skipped.
``to_json`` / ``from_json`` are the one place records become JSON (the cache, ``detect`` and
``detections.jsonl`` all write this form) and come back.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any

from tsrkit.core.geometry import Box

__all__ = ["BOX_CHOICES", "DECIMALS", "DetectionRecord", "FrameRecord"]

#: Decimals kept for coordinates (and ``ms``) in records.
DECIMALS = 3
#: The boxes an evaluation can read from a record (``--eval-box``).
BOX_CHOICES = ("lens", "housing")


def _rounded(values) -> Box:
    x0, y0, x1, y1 = (round(float(v), DECIMALS) for v in values)
    return x0, y0, x1, y1


def _typed(value: Any, kind: type, name: str, optional: bool = False) -> Any:
    """``value`` read from JSON when it is a ``kind`` (never a bool) or, when ``optional``,
    None.

    Raises
    ------
    TypeError
        Anything else: a record read from JSON is refused whole, not half used.

    >>> _typed(3, int, "frame")
    3
    >>> _typed("3", int, "frame")
    Traceback (most recent call last):
    TypeError: 'frame' must be int, not str
    """
    if (value is None and optional) or (isinstance(value, kind) and not isinstance(value, bool)):
        return value
    raise TypeError(f"{name!r} must be {kind.__name__}, not {type(value).__name__}")


def _number(value: Any, name: str, null: float | None = math.nan) -> Any:
    """A number read from JSON; null reads as ``null``: NaN by default, since
    :func:`tsrkit.core.atomic.json_line` writes a non-finite number as null.

    >>> _number(2, "x"), _number(None, "x")
    (2, nan)
    >>> _number(True, "x")
    Traceback (most recent call last):
    TypeError: 'x' must be a number, not bool
    """
    if value is None:
        return null
    if isinstance(value, (int, float)) and not isinstance(value, bool):
        return value
    raise TypeError(f"{name!r} must be a number, not {type(value).__name__}")


def _box(value: Any, name: str) -> Box:
    """Four numbers read from JSON as a box (see :func:`_number`)."""
    if not isinstance(value, list) or len(value) != 4:
        raise TypeError(f"{name!r} must be a list of 4 numbers")
    x0, y0, x1, y1 = (_number(v, name) for v in value)
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
        """The record of a :class:`tsrkit.core.types.Detection` (coordinates rounded)."""
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
        """Read :meth:`to_json`'s form back (older records without ``lens_bbox`` too).

        Raises
        ------
        KeyError, TypeError
            A required field is missing or a field has the wrong type.
        """
        bbox = _box(data["bbox"], "bbox")
        scores = _typed(data.get("state_scores", {}), dict, "state_scores")
        return cls(
            _number(data["x"], "x"),
            _number(data["y"], "y"),
            _number(data["radius"], "radius"),
            bbox,
            _box(data["lens_bbox"], "lens_bbox") if "lens_bbox" in data else bbox,
            _number(data["score"], "score"),
            _typed(data.get("state", "unknown"), str, "state"),
            {_typed(k, str, "state"): _number(v, k) for k, v in scores.items()},
            _typed(data.get("origin", "detected"), str, "origin"),
            _number(data.get("housing_score"), "housing_score", None),
            _typed(data.get("track_id"), int, "track_id", optional=True),
            _number(data.get("distance_m"), "distance_m", None),
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
        """The record of a :class:`tsrkit.plugin.pipeline.FrameResult`."""
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
        """Read :meth:`to_json`'s form back.

        Raises
        ------
        KeyError, TypeError
            A required field is missing or a field has the wrong type (a hand-edited or
            damaged file): the record is refused whole.
        """
        source = _typed(data["source"], str, "source")
        frame = _typed(data.get("frame", 0), int, "frame")
        if "skipped" in data:
            return cls(source, frame, skipped=_typed(data["skipped"], str, "skipped"))
        return cls(
            source,
            frame,
            _typed(data["width"], int, "width"),
            _typed(data["height"], int, "height"),
            _number(data["ms"], "ms"),
            _typed(data.get("lighting"), str, "lighting", optional=True),
            tuple(
                DetectionRecord.from_json(d) for d in _typed(data["detections"], list, "detections")
            ),
            notes=tuple(str(n) for n in _typed(data.get("notes", []), list, "notes")),
        )
