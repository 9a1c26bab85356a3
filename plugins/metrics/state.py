"""Metric ``state``: the states of detections matched to ground truth by Zheng's centre rule
(Mascetti 2016, 5.1; Zheng 2016, 5.3): accuracy, per class, confusion, red/yellow errors."""

from __future__ import annotations

from collections.abc import Mapping

from tsrkit.api import (
    EvalSettings,
    FrameRecord,
    Metric,
    Sample,
    StateResult,
    centre_hits,
    greedy_match,
    hookimpl,
    state_metrics,
)


class StateMetric(Metric):
    """``state``: the states of detections matched to ground truth by Zheng's centre rule.

    Each ground-truth box takes at most one detection (best score first) whose centre lies in
    its minimum enclosing circle; the pair's true and predicted states enter the figures.
    """

    name = "state"
    summary = "state accuracy, per-class figures, confusion, R-Y errors, discriminative ratio"
    section = "Mascetti 2016, 5.1; Zheng 2016, 5.3"

    def reset(self, settings: EvalSettings) -> None:
        self.settings = settings
        self.truth: list[str] = []
        self.predicted: list[str] = []
        self.scores: list[Mapping[str, float]] = []

    def update(self, sample: Sample, record: FrameRecord) -> None:
        dets = record.detections
        hits = centre_hits([(d.x, d.y) for d in dets], [a.bbox for a in sample.annotations])
        for i, j in greedy_match([d.score for d in dets], hits.astype(float), 0.5):
            self.truth.append(sample.annotations[j].state)
            self.predicted.append(dets[i].state)
            self.scores.append(dets[i].state_scores)

    result_type = StateResult

    def compute(self) -> StateResult:
        if all(p == "unknown" for p in self.predicted):
            return StateResult(
                {
                    "state": {
                        **state_metrics([], []),
                        "note": "the method predicts no state (every detection is 'unknown')",
                    }
                }
            )
        return StateResult({"state": state_metrics(self.truth, self.predicted, self.scores)})


@hookimpl
def register_metrics(register):
    register(StateMetric)
