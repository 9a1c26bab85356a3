"""The dataset registry: named datasets in ``datasets.yaml`` and where their files are.

The file is ``$TSRKIT_DATASETS_YAML`` when set, else the ``datasets.yaml`` installed inside the
``tsrkit`` package (in a checkout, ``tsrkit/datasets.yaml`` links to the one at the repository
root, so a wheel or ``pip install .`` carries a copy). A relative ``root`` resolves against
``$TSRKIT_DATA_DIR``; when that is unset, against ``<repo>/../shared/datasets``.
"""

from __future__ import annotations

import os
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from tsrkit.datasets.errors import DatasetError, read_yaml
from tsrkit.datasets.states import check_mapping

__all__ = [
    "BOXES",
    "DATA_DIR_ENV",
    "GENERATED_SAMPLE",
    "PACKAGED_REGISTRY",
    "REGISTRY_ENV",
    "REPO_ROOT",
    "REQUIRED",
    "DatasetEntry",
    "data_dir",
    "load_registry",
    "registry_path",
]

REGISTRY_ENV = "TSRKIT_DATASETS_YAML"
DATA_DIR_ENV = "TSRKIT_DATA_DIR"
REPO_ROOT = Path(__file__).resolve().parents[2]
PACKAGED_REGISTRY = Path(__file__).parents[1] / "datasets.yaml"
BOXES = ("lens", "housing", "crop", "roi")
GENERATED_SAMPLE = "generated:sample"
REQUIRED = ("format", "root", "licence", "citation", "task", "box")


@dataclass(frozen=True)
class DatasetEntry:
    """One named dataset of the registry.

    ``root`` is as written (relative or absolute); :meth:`root_path` resolves it. ``path`` is
    the annotation file or folder inside the root that the format reader opens (``"."`` for the
    root itself). ``states`` maps raw labels to signal states, overriding the reader's defaults.
    """

    name: str
    format: str
    root: str
    licence: str
    citation: str
    task: str
    box: str
    path: str = "."
    manifest: str | None = None
    splits: tuple[str, ...] = ()
    states: Mapping[str, str] = field(default_factory=dict)
    description: str = ""
    extra: Mapping[str, Any] = field(default_factory=dict)

    def root_path(self) -> Path:
        """The dataset folder: ``root`` if absolute, else under :func:`data_dir`.

        The root ``"generated:sample"`` is the synthetic sample's folder, generated on first
        use by :func:`tsrkit.synth.sample_path`.
        """
        if self.root == GENERATED_SAMPLE:
            from tsrkit.datasets import scenes as synth  # cv2, NumPy: only for the sample

            return Path(synth.sample_path()).parent
        root = Path(self.root).expanduser()
        return root if root.is_absolute() else data_dir() / root

    def annotation_path(self) -> Path:
        """What the format reader opens; a clear error when the data folder is missing."""
        root = self.root_path()
        if not root.exists():
            hint = (
                f"${DATA_DIR_ENV} is {os.environ[DATA_DIR_ENV]!r}"
                if DATA_DIR_ENV in os.environ
                else f"${DATA_DIR_ENV} is unset, so the default {data_dir()} was used"
            )
            raise DatasetError(
                root,
                f"dataset '{self.name}' not found ({hint}); set "
                f"{DATA_DIR_ENV} to the folder that holds it",
            )
        return (root / self.path).resolve() if self.path != "." else root

    def to_info(self) -> dict[str, Any]:
        """The facts a :class:`tsrkit.core.types.Dataset` carries in ``info``."""
        info = {
            "name": self.name,
            "format": self.format,
            "root": str(self.root_path()),
            "path": self.path,
            "licence": self.licence,
            "citation": self.citation,
            "task": self.task,
            "box": self.box,
            "manifest": self.manifest,
            "splits": list(self.splits),
            "states": dict(self.states),
            "description": self.description,
        }
        info.update(self.extra)
        return info


def data_dir() -> Path:
    """Where relative dataset roots live: ``$TSRKIT_DATA_DIR`` or ``<repo>/../shared/datasets``."""
    given = os.environ.get(DATA_DIR_ENV)
    return Path(given).expanduser() if given else REPO_ROOT.parent / "shared" / "datasets"


def registry_path() -> Path:
    """The ``datasets.yaml`` in use: ``$TSRKIT_DATASETS_YAML`` or the repository's own."""
    given = os.environ.get(REGISTRY_ENV)
    return Path(given).expanduser() if given else PACKAGED_REGISTRY


def load_registry(path: str | os.PathLike | None = None) -> dict[str, DatasetEntry]:
    """Read the registry; entries by name, in file order.

    Raises
    ------
    DatasetError
        Naming the file, the entry and the problem (missing key, unknown box convention...).
    """
    path = Path(path) if path is not None else registry_path()
    data = read_yaml(path, f"dataset registry not found (set ${REGISTRY_ENV})") or {}
    datasets = data.get("datasets") if isinstance(data, Mapping) else None
    if not isinstance(datasets, Mapping):
        raise DatasetError(path, "expected a top-level 'datasets:' mapping")
    return {str(name): _entry(path, str(name), fields) for name, fields in datasets.items()}


def _yaml_off(mapping: Any) -> Any:
    """YAML 1.1 loads an unquoted ``off`` as False; in a ``states`` mapping it means "off"."""
    if not isinstance(mapping, Mapping):
        return mapping
    return {("off" if k is False else k): ("off" if v is False else v) for k, v in mapping.items()}


def _entry(path: Path, name: str, fields: Any) -> DatasetEntry:
    where = f"datasets.{name}"
    if not isinstance(fields, Mapping):
        raise DatasetError(path, "expected a mapping of fields", where)
    missing = [key for key in REQUIRED if key not in fields]
    if missing:
        raise DatasetError(path, f"missing {', '.join(missing)}", where)
    if fields["box"] not in BOXES:
        raise DatasetError(
            path, f"box must be one of {', '.join(BOXES)}, got {fields['box']!r}", where
        )
    try:
        states = check_mapping(_yaml_off(fields.get("states") or {}), where)
    except ValueError as exc:
        raise DatasetError(path, str(exc)) from None
    known = set(REQUIRED) | {"path", "manifest", "splits", "states", "description"}
    return DatasetEntry(
        name=name,
        format=str(fields["format"]),
        root=str(fields["root"]),
        licence=str(fields["licence"]),
        citation=str(fields["citation"]).strip(),
        task=str(fields["task"]),
        box=str(fields["box"]),
        path=str(fields.get("path", ".")),
        manifest=fields.get("manifest"),
        splits=tuple(fields.get("splits") or ()),
        states=states,
        description=str(fields.get("description", "")).strip(),
        extra={k: v for k, v in fields.items() if k not in known},
    )
