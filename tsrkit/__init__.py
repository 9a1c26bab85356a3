"""tsrkit: traffic signal recognition with interchangeable, benchmarked methods.

Everything the command line does is a plain call here first::

    import tsrkit
    det = tsrkit.detector("conspicuity", weights=(1, 1, 2))
    cls = tsrkit.classifier("ab-hist")
    frame = tsrkit.read_frame("frame.png")
    detections = cls.classify(frame, det.detect(frame))
"""
from __future__ import annotations

from importlib import metadata as _metadata
from typing import Any

from tsrkit.errors import TsrkitError
from tsrkit.inputs import ImageReadError, iter_frames, read_image
from tsrkit.models import Model, ModelError, load_model, save_model
from tsrkit.params import Param, ParamError
from tsrkit.pipeline import FrameResult, Pipeline
from tsrkit.plugin import Classifier, DatasetFormat, Detector, Tracker, Verifier
from tsrkit.registry import PluginNotFound, get_registry
from tsrkit.types import (STATES, Annotation, Candidate, Dataset, Detection, Frame, Sample,
                          Skipped)

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


def benchmark(dataset: Dataset, detector: Detector, classifier: Classifier | None = None,
              **options: Any) -> dict[str, Any]:
    """Run a detector (and verifier, classifier) over a dataset and return the report dict.

    ``options`` are those of :func:`tsrkit.runner.benchmark` (``verifier=``, ``workers=``...).
    """
    from tsrkit.runner import benchmark as _benchmark

    return _benchmark(dataset, detector, classifier, **options)


def train(name: str, dataset: Dataset, out: str, **params: Any):
    """Fit the trainable plugin ``name`` on ``dataset`` and save the model to ``out``."""
    from tsrkit.training import train as _train

    return _train(name, dataset, out, params)


__all__ = [
    "STATES", "Annotation", "Candidate", "Classifier", "Dataset", "DatasetFormat", "Detection",
    "Detector", "Frame", "FrameResult", "ImageReadError", "Model", "ModelError", "Param",
    "ParamError", "Pipeline", "PluginNotFound", "Sample", "Skipped", "Tracker", "TsrkitError", "Verifier",
    "benchmark", "classifier", "dataset", "detector", "iter_frames", "load_model", "plugins",
    "read_frame", "read_image", "save_model", "tracker", "train", "verifier",
]
