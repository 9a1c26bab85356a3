"""Example third-party tsrkit report writer: ``missed.csv``, every ground-truth box no detection
centre fell into (Zheng 5.2.1's rule), with its frame, state and size, to look at by hand."""

import csv

from tsrkit.api import ReportWriter, atomic_open, centre_hits, hookimpl


class MissedBoxes(ReportWriter):
    name = "missed-boxes"
    summary = "missed.csv: the ground-truth boxes no detection hit"

    def files(self, run):
        return ["missed.csv"]

    def write(self, run, folder):
        with atomic_open(folder / "missed.csv") as fh:
            out = csv.writer(fh)
            out.writerow(["frame", "source", "state", "x_min", "y_min", "x_max", "y_max"])
            for sample, record in run.pairs():
                truth = [a.bbox for a in sample.annotations]
                hit = centre_hits([(d.x, d.y) for d in record.detections], truth).any(axis=0)
                for ann, found in zip(sample.annotations, hit):
                    if not found:
                        out.writerow([record.index, record.source, ann.state, *ann.bbox])


@hookimpl
def register_report_writers(register):
    register(MissedBoxes)
