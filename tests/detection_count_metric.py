"""A metric written the way a third party writes one: this one file plus its registration (an
entry point in a package; the tests register the module). It counts the detections of each
evaluated frame; nothing in tsrkit's writers knows about it.
"""

from collections import Counter
from dataclasses import dataclass

from tsrkit.api import Figure, Metric, MetricResult, Plot, Table, hookimpl


@dataclass(frozen=True)
class DetectionCountResult(MetricResult):
    """``detection_count``: the mean detections per frame (headline), the frames per count
    (table, plot) and how many frames had none (remark)."""

    def headline(self):
        count = self.sections["detection_count"]
        return [
            Figure(
                "detection_count.mean",
                "det/frame",
                count["mean"],
                ".2f",
                about="mean detections per evaluated frame",
            )
        ]

    def remarks(self):
        count = self.sections["detection_count"]
        return [f"{count['frames_without']} frames had no detection at all."]

    def tables(self):
        histogram = self.sections["detection_count"]["histogram"]
        return [
            Table(
                "detection-count",
                "Frames by number of detections",
                ("detections", "frames"),
                tuple((k, str(v)) for k, v in histogram.items()),
                "Each evaluated frame counted once, by how many detections it reported.",
            )
        ]

    def plots(self):
        return [
            Plot(
                "detection_count.png",
                "How many frames reported each number of detections.",
                self.draw,
                (4.0, 3.0),
            )
        ]

    def draw(self, figure):
        histogram = self.sections["detection_count"]["histogram"]
        ax = figure.subplots()
        ax.bar([int(k) for k in histogram], list(histogram.values()), label="frames")
        ax.set_xlabel("detections in the frame")
        ax.set_ylabel("frames")
        ax.legend()


class DetectionCount(Metric):
    name = "detection-count"
    summary = "detections per evaluated frame"
    section = "none (a test fixture)"
    result_type = DetectionCountResult

    def reset(self, settings):
        self.counts = []

    def update(self, sample, record):
        self.counts.append(len(record.detections))

    def compute(self):
        histogram = Counter(self.counts)
        return DetectionCountResult(
            {
                "detection_count": {
                    "frames": len(self.counts),
                    "mean": sum(self.counts) / len(self.counts) if self.counts else None,
                    "frames_without": histogram[0],
                    "histogram": {str(k): histogram[k] for k in sorted(histogram)},
                }
            }
        )


@hookimpl
def register_metrics(register):
    register(DetectionCount)
