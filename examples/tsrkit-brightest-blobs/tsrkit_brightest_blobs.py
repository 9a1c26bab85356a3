"""Example third-party tsrkit plugin: the brightest blobs of a frame as lens candidates.

Threshold the HSV value channel at a top percentile, label 8-connected blobs, and report the
``top`` brightest as circles. Deliberately simple: a template for plugin authors.
"""

import cv2
import numpy as np

from tsrkit.api import Candidate, Detector, Param, hookimpl


class BrightestBlobs(Detector):
    """The ``top`` brightest connected blobs above the ``percentile`` of V."""

    name = "brightest-blobs"
    summary = "Brightest connected blobs of the V channel (example plugin)"
    section = "none (example)"
    PARAMS = (
        Param("percentile", "float", 99.5, min=50, max=100, help="V percentile threshold"),
        Param("top", "int", 5, min=1, max=100, help="Blobs to keep"),
        Param("min_area", "int", 2, min=1, help="Smallest blob in pixels"),
    )

    def detect(self, frame):
        value = cv2.cvtColor(frame.image, cv2.COLOR_BGR2HSV)[:, :, 2]
        level = np.percentile(value, self.params["percentile"])
        mask = (value >= max(level, 1)).astype(np.uint8)
        count, labels, stats, centroids = cv2.connectedComponentsWithStats(mask, connectivity=8)
        found = []
        for label in range(1, count):
            x, y, w, h, area = stats[label]
            if area < self.params["min_area"]:
                continue
            brightness = float(value[labels == label].mean())
            cx, cy = centroids[label]
            found.append(
                Candidate(
                    float(cx),
                    float(cy),
                    max(w, h) / 2.0,
                    (float(x), float(y), float(x + w), float(y + h)),
                    brightness,
                )
            )
        found.sort(key=lambda c: c.score, reverse=True)
        return found[: self.params["top"]]


@hookimpl
def register_detectors(register):
    register(BrightestBlobs)
