"""``notes``: how many frames each plugin note was given for (e.g. a model's fallback)."""

from __future__ import annotations

from collections import Counter
from dataclasses import dataclass
from typing import ClassVar

from tsrkit.core.records import FrameRecord
from tsrkit.core.results import MetricResult, Table
from tsrkit.core.types import Sample
from tsrkit.eval.settings import EvalSettings
from tsrkit.plugin.base import Metric

__all__ = ["FrameNotes", "FrameNotesResult"]


@dataclass(frozen=True)
class FrameNotesResult(MetricResult):
    """``frame_notes``: shown as the report's notes (``N of M frames: note``), not again here."""

    order: ClassVar[int] = 60

    def tables(self) -> list[Table]:
        return []


class FrameNotes(Metric):
    """``frame_notes``: the number of frames of each note the plugins wrote into the records;
    absent from the report when no plugin wrote any."""

    name = "frame-notes"
    summary = "frames counted per plugin note (fallbacks and other per-frame remarks)"
    section = "tsrkit"

    def reset(self, settings: EvalSettings) -> None:
        self.counts: Counter[str] = Counter()
        self.frames = 0

    def update(self, sample: Sample, record: FrameRecord) -> None:
        self.frames += 1
        self.counts.update(set(record.notes))

    result_type = FrameNotesResult

    def compute(self) -> FrameNotesResult:
        if not self.counts:
            return FrameNotesResult({})
        counts = dict(sorted(self.counts.items()))
        return FrameNotesResult({"frame_notes": {"frames": self.frames, "counts": counts}})
