"""``notes``: how many frames each plugin note was given for (e.g. a model's fallback)."""

from __future__ import annotations

from collections import Counter

from tsrkit.eval.settings import EvalSettings
from tsrkit.plugin import Metric
from tsrkit.records import FrameRecord
from tsrkit.types import Sample

__all__ = ["FrameNotes"]


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

    def compute(self) -> dict:
        if not self.counts:
            return {}
        return {"frame_notes": {"frames": self.frames, "counts": dict(sorted(self.counts.items()))}}
