"""tsrkit: traffic signal recognition with interchangeable, benchmarked methods.

Everything the command line does is a plain call here first::

    import tsrkit
    det = tsrkit.detector("conspicuity", weights=(1, 1, 2))
    cls = tsrkit.classifier("ab-hist")
    frame = tsrkit.read_frame("frame.png")
    detections = cls.classify(frame, det.detect(frame))

It is also the whole plugin API: ``from tsrkit import hookimpl, Detector, Param, Candidate``
(and the other public names below) is all a plugin module needs to import.
"""

from __future__ import annotations

from importlib import metadata as _metadata
from typing import Any

from tsrkit.errors import TsrkitError
from tsrkit.eval.settings import EvalSettings
from tsrkit.hookspecs import hookimpl
from tsrkit.images import ImageReadError, read_image
from tsrkit.inputs import iter_frames
from tsrkit.models import Model, ModelError, load_model, save_model
from tsrkit.params import Param, ParamError
from tsrkit.pipeline import FrameResult, Pipeline
from tsrkit.plugin import (
    Classifier,
    DatasetFormat,
    Detector,
    Metric,
    ReportWriter,
    Tracker,
    Trainable,
    Verifier,
)
from tsrkit.records import DetectionRecord, FrameRecord
from tsrkit.registry import PluginNotFound, get_registry
from tsrkit.report import RunResult
from tsrkit.selection import Selection
from tsrkit.selection import build as select
from tsrkit.types import STATES, Annotation, Candidate, Dataset, Detection, Frame, Sample, Skipped

try:
    __version__ = _metadata.version("tsrkit")
except _metadata.PackageNotFoundError:  # running from a source tree that is not installed
    __version__ = "0+unknown"


def detector(name: str, **params: Any) -> Detector:
    """An installed detector, its parameters validated against its schema."""
    return get_registry().create("detector", name, params)


def classifier(name: str, **params: Any) -> Classifier:
    """An installed classifier, its parameters validated against its schema."""
    return get_registry().create("classifier", name, params)


def verifier(name: str, **params: Any) -> Verifier:
    """An installed verifier, its parameters validated against its schema."""
    return get_registry().create("verifier", name, params)


def tracker(name: str, **params: Any) -> Tracker:
    """An installed tracker, its parameters validated against its schema."""
    return get_registry().create("tracker", name, params)


def plugins(kind: str | None = None) -> list[dict[str, Any]]:
    """Installed plugins as JSON-ready dicts (failed ones have ``kind == "failed"``)."""
    registry = get_registry()
    found = [info.to_json() for info in registry.plugins(kind)]
    return found + [f.to_json() for f in registry.failures] if kind is None else found


def read_frame(path: str) -> Frame:
    """Read one image file as a :class:`Frame`."""
    return Frame(image=read_image(path), source=str(path))


def dataset(ref: str, format: str | None = None, images: str | None = None) -> Dataset:
    """A dataset by registry name or path (format auto-detected where unambiguous)."""
    from tsrkit.datasets import open_dataset

    return open_dataset(ref, format=format, images=images)


def benchmark(
    dataset: Dataset,
    detector: Detector | None = None,
    classifier: Classifier | None = None,
    **options: Any,
) -> dict[str, Any]:
    """Run a detector (and verifier, classifier) over a dataset and return the report dict.

    ``options`` are those of :func:`tsrkit.benchmarking.benchmark` (``verifier=``, ``box=``,
    ``workers=``, ``out=``...).
    """
    from tsrkit.benchmarking import benchmark as _benchmark

    return _benchmark(dataset, detector, classifier, **options)


def compare(
    dataset: Dataset,
    detectors: list[Detector],
    classifier: Classifier | None = None,
    **options: Any,
) -> dict[str, Any]:
    """Benchmark several detectors on the same frames, with paired tests
    (:func:`tsrkit.comparison.compare`)."""
    from tsrkit.comparison import compare as _compare

    return _compare(dataset, detectors, classifier, **options)


def train(name: str, dataset: Dataset, out: str, detector: Detector | None = None, **params: Any):
    """Fit the trainable plugin ``name`` on ``dataset`` and save the model to ``out``.

    ``detector`` is the detector a trainable verifier learns on.
    """
    from tsrkit.training import train as _train

    return _train(name, dataset, out, params, detector)


__all__ = [
    "STATES",
    "Annotation",
    "Candidate",
    "Classifier",
    "Dataset",
    "DatasetFormat",
    "Detection",
    "DetectionRecord",
    "Detector",
    "EvalSettings",
    "Frame",
    "FrameRecord",
    "FrameResult",
    "ImageReadError",
    "Metric",
    "Model",
    "ModelError",
    "Param",
    "ParamError",
    "Pipeline",
    "PluginNotFound",
    "ReportWriter",
    "RunResult",
    "Sample",
    "Selection",
    "Skipped",
    "Tracker",
    "Trainable",
    "TsrkitError",
    "Verifier",
    "benchmark",
    "classifier",
    "compare",
    "dataset",
    "detector",
    "hookimpl",
    "iter_frames",
    "load_model",
    "plugins",
    "read_frame",
    "read_image",
    "save_model",
    "select",
    "tracker",
    "train",
    "verifier",
]
