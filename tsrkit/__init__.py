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

import importlib as _importlib
from importlib import metadata as _metadata
from typing import TYPE_CHECKING, Any

#: Where each public name lives; imported on first use (PEP 562), so that ``import tsrkit``
#: (and ``tsrkit --help``) does not load NumPy, OpenCV or the plugins.
_LAZY = {
    "TsrkitError": "tsrkit.errors",
    "EvalSettings": "tsrkit.eval.settings",
    "hookimpl": "tsrkit.hookspecs",
    "ImageReadError": "tsrkit.images",
    "read_image": "tsrkit.images",
    "iter_frames": "tsrkit.inputs",
    "Model": "tsrkit.models",
    "ModelError": "tsrkit.models",
    "load_model": "tsrkit.models",
    "save_model": "tsrkit.models",
    "Param": "tsrkit.params",
    "ParamError": "tsrkit.params",
    "FrameResult": "tsrkit.pipeline",
    "Pipeline": "tsrkit.pipeline",
    "Classifier": "tsrkit.plugin",
    "DatasetFormat": "tsrkit.plugin",
    "Detector": "tsrkit.plugin",
    "Metric": "tsrkit.plugin",
    "ReportWriter": "tsrkit.plugin",
    "Tracker": "tsrkit.plugin",
    "Trainable": "tsrkit.plugin",
    "Verifier": "tsrkit.plugin",
    "DetectionRecord": "tsrkit.records",
    "FrameRecord": "tsrkit.records",
    "PluginNotFound": "tsrkit.registry",
    "get_registry": "tsrkit.registry",
    "RunResult": "tsrkit.report",
    "Selection": "tsrkit.selection",
    "STATES": "tsrkit.types",
    "Annotation": "tsrkit.types",
    "Candidate": "tsrkit.types",
    "Dataset": "tsrkit.types",
    "Detection": "tsrkit.types",
    "Frame": "tsrkit.types",
    "Sample": "tsrkit.types",
    "Skipped": "tsrkit.types",
}

if TYPE_CHECKING:
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
    from tsrkit.registry import PluginNotFound
    from tsrkit.report import RunResult
    from tsrkit.selection import Selection
    from tsrkit.types import (
        STATES,
        Annotation,
        Candidate,
        Dataset,
        Detection,
        Frame,
        Sample,
        Skipped,
    )


def __getattr__(name: str) -> Any:
    if name == "select":
        from tsrkit.selection import build

        return build
    if name in _LAZY:
        value = getattr(_importlib.import_module(_LAZY[name]), name)
        globals()[name] = value
        return value
    try:  # a subpackage, as ``tsrkit.datasets.open_datasets`` (imported on first use)
        return _importlib.import_module(f"{__name__}.{name}")
    except ModuleNotFoundError as exc:
        if exc.name != f"{__name__}.{name}":
            raise
    raise AttributeError(f"module 'tsrkit' has no attribute {name!r}")


def __dir__() -> list[str]:
    return sorted({*globals(), *_LAZY, "select"})


try:
    __version__ = _metadata.version("tsrkit")
except _metadata.PackageNotFoundError:  # running from a source tree that is not installed
    __version__ = "0+unknown"


def detector(name: str, **params: Any) -> Detector:
    """An installed detector, its parameters validated against its schema."""
    from tsrkit.registry import get_registry

    return get_registry().create("detector", name, params)


def classifier(name: str, **params: Any) -> Classifier:
    """An installed classifier, its parameters validated against its schema."""
    from tsrkit.registry import get_registry

    return get_registry().create("classifier", name, params)


def verifier(name: str, **params: Any) -> Verifier:
    """An installed verifier, its parameters validated against its schema."""
    from tsrkit.registry import get_registry

    return get_registry().create("verifier", name, params)


def tracker(name: str, **params: Any) -> Tracker:
    """An installed tracker, its parameters validated against its schema."""
    from tsrkit.registry import get_registry

    return get_registry().create("tracker", name, params)


def plugins(kind: str | None = None) -> list[dict[str, Any]]:
    """Installed plugins as JSON-ready dicts (failed ones have ``kind == "failed"``)."""
    from tsrkit.registry import get_registry

    registry = get_registry()
    found = [info.to_json() for info in registry.plugins(kind)]
    return found + [f.to_json() for f in registry.failures] if kind is None else found


def read_frame(path: str) -> Frame:
    """Read one image file as a :class:`Frame`."""
    from tsrkit.images import read_image
    from tsrkit.types import Frame

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
