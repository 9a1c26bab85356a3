"""``notes``: the result counting the frames each plugin note was given for (e.g. a model's
fallback); the metric that fills it is the plugin ``tsrkit_plugins.metrics.frame_notes``."""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

from tsrkit.core.results import MetricResult, Table

__all__ = ["FrameNotesResult"]


@dataclass(frozen=True)
class FrameNotesResult(MetricResult):
    """``frame_notes``: shown as the report's notes (``N of M frames: note``), not again here."""

    order: ClassVar[int] = 60

    def tables(self) -> list[Table]:
        return []
