"""Datasets: the registry (``datasets.yaml``), opening by name or path with format detection,
checksums, several sets as one, and the renderer of the bundled sample (:mod:`.scenes`).

>>> from tsrkit.datasets import open_dataset
>>> ds = open_dataset("roboflow_traffic_light_kr")          # doctest: +SKIP
>>> ds = open_dataset("path/to/coco.json", format="coco")   # doctest: +SKIP
"""

from tsrkit.datasets.concat import concat_datasets, open_datasets, parse_reference
from tsrkit.datasets.errors import DatasetError
from tsrkit.datasets.manifest import Verification, verify_manifest
from tsrkit.datasets.opening import (
    SAMPLE,
    detect_format,
    open_dataset,
    read_dataset,
    relabel,
)
from tsrkit.datasets.registry import DatasetEntry, data_dir, load_registry, registry_path
from tsrkit.datasets.states import to_state
from tsrkit.datasets.writing import write_dataset

__all__ = [
    "SAMPLE",
    "DatasetEntry",
    "DatasetError",
    "Verification",
    "concat_datasets",
    "data_dir",
    "detect_format",
    "load_registry",
    "open_dataset",
    "open_datasets",
    "parse_reference",
    "read_dataset",
    "registry_path",
    "relabel",
    "to_state",
    "verify_manifest",
    "write_dataset",
]
