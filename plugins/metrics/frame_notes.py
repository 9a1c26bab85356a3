"""Metric ``frame-notes``: how many frames each plugin note was given for (a model's fallback,
other per-frame remarks); the ``frame_notes`` section, absent when no plugin wrote a note."""

from __future__ import annotations

from collections import Counter

from tsrkit.api import EvalSettings, FrameNotesResult, FrameRecord, Metric, Sample, hookimpl


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


@hookimpl
def register_metrics(register):
    register(FrameNotes)
