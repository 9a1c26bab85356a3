"""Hand-built frames and tiny in-process plugins for the evaluation and benchmark tests.

``OracleDetector`` returns the candidates stored in each frame's metadata (``"dets"``: a list of
``(x, y, score)``), so a test decides exactly which hits, misses and false positives occur.
"""

from __future__ import annotations

import time

import numpy as np

from tsrkit.core.errors import TsrkitError
from tsrkit.core.types import Annotation, Candidate, Dataset, Detection, Sample
from tsrkit.plugin.base import Classifier, Detector
from tsrkit.plugin.hookspecs import hookimpl
from tsrkit.plugin.params import Param


class OracleDetector(Detector):
    name = "oracle"
    summary = "returns the candidates written in the frame's metadata"
    PARAMS = (
        Param("delay", "float", 0.0, min=0, help="seconds to sleep per frame"),
        Param("crash_on", "str", "", help="raise on the frame with this source"),
    )

    def detect(self, frame):
        if self.params["delay"]:
            time.sleep(self.params["delay"])
        if frame.source == self.params["crash_on"]:
            raise RuntimeError("deliberate crash")
        return [Candidate.from_circle(x, y, 3, s) for x, y, s in frame.metadata["dets"]]


class ShiftedDetector(OracleDetector):
    name = "shifted"
    summary = "the oracle's candidates moved 20 px right (mostly misses)"

    def detect(self, frame):
        return [
            Candidate.from_circle(c.x + 20, c.y, c.radius, c.score) for c in super().detect(frame)
        ]


class RedClassifier(Classifier):
    name = "always-red"
    summary = "says red, with fixed colour scores"

    def classify(self, frame, candidates):
        scores = {"red": 0.8, "yellow": 0.4, "green": 0.2}
        return [Detection(c, "red", scores) for c in candidates]


class UntrainedDetector(Detector):
    name = "untrained"
    summary = "like a trainable detector run without its model: a TsrkitError on every frame"

    def detect(self, frame):
        raise TsrkitError("untrained needs a model: pass --param model=M")


class FrameCrasher(Detector):
    name = "frame-crasher"
    summary = "finds nothing; raises on the video frame with the given index"
    PARAMS = (Param("crash_at", "int", 0, min=0, help="index of the frame that raises"),)

    def detect(self, frame):
        if frame.index == self.params["crash_at"]:
            raise RuntimeError("deliberate crash")
        return []


@hookimpl
def register_detectors(register):
    register(OracleDetector)
    register(ShiftedDetector)
    register(UntrainedDetector)


@hookimpl
def register_classifiers(register):
    register(RedClassifier)


def hand_dataset(frames: int = 6, name: str = "hand") -> Dataset:
    """Frames of 40x40 px with a red box at (10..16) and a green box at (20..26).

    Odd frames: one hit and one false positive (recall 1/2, precision 1/2); even frames: both
    boxes hit (recall 1, precision 1). Brightness varies so the estimated lighting varies.
    """
    samples = []
    for i in range(frames):
        image = np.full((40, 40, 3), (i * 37) % 256, np.uint8)
        boxes = (Annotation((10, 10, 16, 16), "red"), Annotation((20, 20, 26, 26), "green"))
        dets = [(13, 13, 0.9), (35, 35, 0.5)] if i % 2 else [(13, 13, 0.9), (23, 23, 0.8)]
        samples.append(Sample(f"frame{i:03d}", boxes, 40, 40, metadata={"dets": dets}, image=image))
    return Dataset(name, tuple(samples))


def make(cls, **params):
    """Instantiate a fake plugin with its schema's validated parameters."""
    from tsrkit.plugin.params import validate

    return cls(**validate(cls.PARAMS, params, cls.name))
