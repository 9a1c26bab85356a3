"""Report writer ``coco``: the evaluated frames as COCO ground truth and COCO detection results.

``ground_truth.coco.json`` and ``detections.coco.json`` are the dictionaries the ``coco-ap``
metric gave pycocotools, with the evaluated box (``report.json``'s ``evaluated_box``), built
afresh (none of the keys pycocotools adds while evaluating) and with each image's ``file_name``
relative to the dataset's root folder, as COCO tools expect.
"""

from __future__ import annotations

from pathlib import Path

from tsrkit.api import ReportWriter, RunResult, coco_run, hookimpl, write_json
from tsrkit_plugins.shared.paths import relative_source


class CocoFiles(ReportWriter):
    name = "coco"
    summary = "ground_truth.coco.json and detections.coco.json (class-agnostic, pycocotools)"

    def files(self, run: RunResult) -> list[str]:
        if run.dataset is None:  # a run without ground truth (tsrkit track)
            return []
        return ["detections.coco.json", "ground_truth.coco.json"]

    def write(self, run: RunResult, folder: Path) -> None:
        if run.dataset is None or run.settings is None:
            return
        truth, results = coco_run(run.settings.dataset, run.pairs(), run.settings.box)
        if run.dataset.root:
            for image in truth["images"]:
                image["file_name"] = relative_source(image["file_name"], Path(run.dataset.root))
        write_json(folder / "ground_truth.coco.json", truth)
        write_json(folder / "detections.coco.json", results)


@hookimpl
def register_report_writers(register):
    register(CocoFiles)
