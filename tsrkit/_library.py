"""The Python API behind ``tsrkit``: what the command line does, as plain calls.

Each call imports what it uses when it runs, so that ``import tsrkit`` (and ``tsrkit --help``)
loads neither NumPy, OpenCV nor the plugins; ``tsrkit/__init__.pyi`` re-exports these names.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from tsrkit.core.types import Dataset, Frame
    from tsrkit.plugin.base import Classifier, Detector, Tracker, Verifier

__all__ = [
    "benchmark",
    "classifier",
    "compare",
    "dataset",
    "detector",
    "plugins",
    "read_frame",
    "tracker",
    "train",
    "verifier",
]


def detector(name: str, **params: Any) -> Detector:
    """An installed detector, its parameters validated against its schema."""
    # on first call: ``import tsrkit`` loads neither NumPy nor the plugins
    from tsrkit.plugin.registry import get_registry

    return get_registry().create("detector", name, params)


def classifier(name: str, **params: Any) -> Classifier:
    """An installed classifier, its parameters validated against its schema."""
    # on first call: ``import tsrkit`` loads neither NumPy nor the plugins
    from tsrkit.plugin.registry import get_registry

    return get_registry().create("classifier", name, params)


def verifier(name: str, **params: Any) -> Verifier:
    """An installed verifier, its parameters validated against its schema."""
    # on first call: ``import tsrkit`` loads neither NumPy nor the plugins
    from tsrkit.plugin.registry import get_registry

    return get_registry().create("verifier", name, params)


def tracker(name: str, **params: Any) -> Tracker:
    """An installed tracker, its parameters validated against its schema."""
    # on first call: ``import tsrkit`` loads neither NumPy nor the plugins
    from tsrkit.plugin.registry import get_registry

    return get_registry().create("tracker", name, params)


def plugins(kind: str | None = None) -> list[dict[str, Any]]:
    """Installed plugins as JSON-ready dicts (failed ones have ``kind == "failed"``)."""
    # on first call: ``import tsrkit`` loads neither NumPy nor the plugins
    from tsrkit.plugin.registry import get_registry

    registry = get_registry()
    found = [info.to_json() for info in registry.plugins(kind)]
    return found + [f.to_json() for f in registry.failures] if kind is None else found


def read_frame(path: str) -> Frame:
    """Read one image file as a :class:`Frame`."""
    # on first call: ``import tsrkit`` loads neither NumPy nor the plugins
    from tsrkit.core.images import read_image
    from tsrkit.core.types import Frame

    return Frame(image=read_image(path), source=str(path))


def dataset(ref: str, format: str | None = None, images: str | None = None) -> Dataset:
    """A dataset by registry name or path (format auto-detected where unambiguous)."""
    # on first call: ``import tsrkit`` loads neither NumPy nor the plugins
    from tsrkit.datasets import open_dataset

    return open_dataset(ref, format=format, images=images)


def benchmark(
    dataset: Dataset,
    detector: Detector | None = None,
    classifier: Classifier | None = None,
    **options: Any,
) -> dict[str, Any]:
    """Run a detector (and verifier, classifier) over a dataset and return the report dict.

    ``options`` are those of :func:`tsrkit.reporting.benchmarking.benchmark` (``verifier=``,
    ``box=``,
    ``workers=``, ``out=``...).
    """
    # on first call: ``import tsrkit`` loads neither NumPy nor the plugins
    from tsrkit.reporting.benchmarking import benchmark as _benchmark

    return _benchmark(dataset, detector, classifier, **options)


def compare(
    dataset: Dataset,
    detectors: list[Detector],
    classifier: Classifier | None = None,
    **options: Any,
) -> dict[str, Any]:
    """Benchmark several detectors on the same frames, with paired tests
    (:func:`tsrkit.reporting.comparison.compare`)."""
    # on first call: ``import tsrkit`` loads neither NumPy nor the plugins
    from tsrkit.reporting.comparison import compare as _compare

    return _compare(dataset, detectors, classifier, **options)


def train(name: str, dataset: Dataset, out: str, detector: Detector | None = None, **params: Any):
    """Fit the trainable plugin ``name`` on ``dataset`` and save the model to ``out``.

    ``detector`` is the detector a trainable verifier learns on.
    """
    # on first call: ``import tsrkit`` loads neither NumPy nor the plugins
    from tsrkit.runner.training import train as _train

    return _train(name, dataset, out, params, detector)
