"""Metric ``per-frame``: Zheng 2016, 5.2.1's per-frame recall, precision and hit-frame
fraction (a candidate's centre in a ground-truth box's minimum enclosing circle), with bootstrap
intervals; the ``per_frame`` and ``intervals`` sections of ``report.json``."""

from __future__ import annotations

from typing import Any

from tsrkit.api import (
    NOT_DETECTION,
    EvalSettings,
    FrameRecord,
    FrameScore,
    Metric,
    PerFrameResult,
    Sample,
    frame_score,
    headline_intervals,
    hookimpl,
    summarise,
)


class FrameScoreMetric(Metric):
    """A metric computed from every frame's :class:`FrameScore` (kept in ``self.scores``)."""

    def reset(self, settings: EvalSettings) -> None:
        self.settings = settings
        self.scores: list[FrameScore] = []

    def update(self, sample: Sample, record: FrameRecord) -> None:
        self.scores.append(frame_score(sample, record))


class ZhengPerFrame(FrameScoreMetric):
    """``per_frame`` and ``intervals``: Zheng 5.2.1's per-frame means with bootstrap intervals.

    A detection's centre (the lens centre) is matched to the ground truth's minimum enclosing
    circles whichever box is evaluated.
    """

    name = "per-frame"
    summary = "per-frame recall, precision and hit-frame fraction (centre in enclosing circle)"
    section = "Zheng 2016, 5.2.1"

    result_type = PerFrameResult

    def compute(self) -> PerFrameResult:
        if not self.settings.detection:
            return PerFrameResult({"per_frame": NOT_DETECTION, "intervals": {}})
        summary: dict[str, Any] = summarise(self.scores)
        intervals: dict[str, Any] = headline_intervals(self.scores)
        for figures in (summary, intervals):
            figures["precision_mean"] = self.settings.false_positive_figure(
                figures["precision_mean"]
            )
        return PerFrameResult({"per_frame": summary, "intervals": intervals})


@hookimpl
def register_metrics(register):
    register(ZhengPerFrame)
