"""Example third-party tsrkit metric: how far matched detections sit from the box centre.

A detection is matched as in Zheng 5.2.1 (its centre in the minimum enclosing circle of a
ground-truth box, one detection per box, best score first); the metric reports the distance in
pixels from its centre to the box centre, as the ``centre_error`` section of ``report.json``.
"""

import math
import statistics

from tsrkit.api import Metric, box_centre, centre_hits, greedy_match, hookimpl


class CentreError(Metric):
    name = "centre-error"
    summary = "pixel distance from matched detection centres to ground-truth box centres"
    section = "none (example)"

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
        return {
            "centre_error": {
                "pairs": len(d),
                "mean_px": statistics.fmean(d) if d else None,
                "median_px": statistics.median(d) if d else None,
            }
        }


@hookimpl
def register_metrics(register):
    register(CentreError)
