"""Metric ``coco-ap``: class-agnostic COCO AP at IoU 0.5 and 0.5:0.95 computed by pycocotools
on the evaluated box, with its precision-recall curve (``iou50.ap``, ``ap_50_95``, ``pr_curve``)."""

from __future__ import annotations

from tsrkit.api import (
    CocoResult,
    EvalSettings,
    FrameRecord,
    Metric,
    Sample,
    coco_ap,
    coco_dataset,
    coco_frame,
    hookimpl,
)


class CocoAP(Metric):
    """``iou50.ap``, ``iou50.ap_50_95`` and ``iou50.pr_curve``: pycocotools on the evaluated box."""

    name = "coco-ap"
    summary = "class-agnostic COCO AP at IoU 0.5 and 0.5:0.95 (pycocotools)"
    section = "COCO detection evaluation (cocodataset.org/#detection-eval)"

    def reset(self, settings: EvalSettings) -> None:
        self.settings = settings
        self.images: list[dict] = []
        self.annotations: list[dict] = []
        self.results: list[dict] = []

    def update(self, sample: Sample, record: FrameRecord) -> None:
        image, anns, dets = coco_frame(sample, record, len(self.annotations) + 1, self.settings.box)
        self.images.append(image)
        self.annotations += anns
        self.results += dets

    result_type = CocoResult

    def compute(self) -> CocoResult:
        if not self.settings.detection:
            return CocoResult({})
        ap = coco_ap(
            coco_dataset(self.images, self.annotations, self.settings.dataset), self.results
        )
        if not self.settings.exhaustive:
            ap = {"ap50": None, "ap": None, "curve": None}
        return CocoResult(
            {"iou50": {"ap": ap["ap50"], "ap_50_95": ap["ap"], "pr_curve": ap["curve"]}}
        )


@hookimpl
def register_metrics(register):
    register(CocoAP)
