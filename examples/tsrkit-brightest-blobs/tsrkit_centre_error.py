"""Example third-party tsrkit metric: how far matched detections sit from the box centre.

A detection is matched as in Zheng 5.2.1 (its centre in the minimum enclosing circle of a
ground-truth box, one detection per box, best score first); the metric reports the distance in
pixels from its centre to the box centre, as the ``centre_error`` section of ``report.json``.
Its result says what to show: the mean distance as a headline figure (every summary, the HTML
page and ``headline.csv`` get it without a writer knowing the metric) and a histogram plot.
"""

import math
import statistics
from dataclasses import dataclass

from tsrkit.api import (
    Figure,
    Metric,
    MetricResult,
    Plot,
    box_centre,
    centre_hits,
    greedy_match,
    hookimpl,
)


@dataclass(frozen=True)
class CentreErrorResult(MetricResult):
    """Renders the ``centre_error`` section; reads nothing else (so that ``tsrkit report`` can
    rebuild it from ``report.json``)."""

    def headline(self):
        error = self.sections["centre_error"]
        about = "mean px from a matched detection's centre to its box's centre"
        return [Figure("centre_error.mean_px", "centre px", error["mean_px"], ".2f", about=about)]

    def remarks(self):
        error = self.sections["centre_error"]
        if not error["pairs"]:
            return ["Centre error: no matched pair."]
        return [
            f"Centre error over {error['pairs']} matched pairs; median {error['median_px']:.2f} px."
        ]

    def plots(self):
        distances = self.sections["centre_error"]["distances_px"]
        if not distances:
            return []

        def draw(figure):
            ax = figure.subplots()
            ax.hist(distances, bins=20, label="matched pairs")
            ax.set_xlabel("distance from the box centre (px)")
            ax.set_ylabel("pairs")
            ax.legend()

        caption = "How far each matched detection's centre sits from its box's centre."
        return [Plot("centre_error.png", caption, draw, (4.5, 3.0))]


class CentreError(Metric):
    name = "centre-error"
    summary = "pixel distance from matched detection centres to ground-truth box centres"
    section = "none (example)"
    result_type = CentreErrorResult

    def reset(self, settings):
        self.distances = []

    def update(self, sample, record):
        dets, truth = record.detections, [a.bbox for a in sample.annotations]
        hits = centre_hits([(d.x, d.y) for d in dets], truth).astype(float)
        for i, j in greedy_match([d.score for d in dets], hits, 0.5):
            cx, cy = box_centre(truth[j])
            self.distances.append(math.hypot(dets[i].x - cx, dets[i].y - cy))

    def compute(self):
        d = self.distances
        return CentreErrorResult(
            {
                "centre_error": {
                    "pairs": len(d),
                    "mean_px": statistics.fmean(d) if d else None,
                    "median_px": statistics.median(d) if d else None,
                    "distances_px": [round(x, 3) for x in d],
                }
            }
        )


@hookimpl
def register_metrics(register):
    register(CentreError)
