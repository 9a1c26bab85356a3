"""Metric ``iou-overlap``: Lee 2017, 3.6.2's overlap precision and recall (and area precision
and recall) of IoU matching at 0.5 and ``--iou``; the ``iou50`` and ``iou`` sections."""

from __future__ import annotations

from tsrkit.api import (
    NOT_DETECTION,
    EvalSettings,
    FrameRecord,
    Metric,
    OverlapResult,
    OverlapScore,
    Sample,
    hookimpl,
    score_overlap,
    summarise_overlap,
)


class OverlapPR(Metric):
    """``iou50`` and ``iou``: Lee 3.6.2's overlap precision and recall at IoU 0.5 and ``--iou``.

    Reads the evaluated box of each detection (``lens_bbox`` or ``bbox``, ``--eval-box``).
    """

    name = "iou-overlap"
    summary = "precision, recall and area precision / recall of IoU matching at 0.5 and --iou"
    section = "Lee 2017, 3.6.2"

    def reset(self, settings: EvalSettings) -> None:
        self.settings = settings
        self.at50: list[OverlapScore] = []
        self.at_threshold: list[OverlapScore] = []

    def update(self, sample: Sample, record: FrameRecord) -> None:
        boxes = [d.box(self.settings.box) for d in record.detections]
        scores = [d.score for d in record.detections]
        truth = [a.bbox for a in sample.annotations]
        self.at50.append(score_overlap(boxes, scores, truth, 0.5))
        self.at_threshold.append(score_overlap(boxes, scores, truth, self.settings.iou_threshold))

    result_type = OverlapResult

    def compute(self) -> OverlapResult:
        if not self.settings.detection:
            return OverlapResult({"iou50": NOT_DETECTION, "iou": NOT_DETECTION})
        out = {
            "iou50": summarise_overlap(self.at50, 0.5),
            "iou": summarise_overlap(self.at_threshold, self.settings.iou_threshold),
        }
        for section in out.values():
            section["precision"] = self.settings.false_positive_figure(section["precision"])
        return OverlapResult(out)


@hookimpl
def register_metrics(register):
    register(OverlapPR)
