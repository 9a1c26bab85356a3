"""Fitting a trainable plugin on a dataset and saving its model (``tsrkit train``).

Every trainable plugin follows :class:`tsrkit.plugin.base.Trainable`: ``fit(samples, *,
detector=None)``;
a verifier receives the detector whose candidates it learns to verify.
"""

from __future__ import annotations

import hashlib
from collections.abc import Mapping
from pathlib import Path
from typing import Any

from tsrkit.core.errors import TsrkitError
from tsrkit.core.types import Dataset
from tsrkit.datasets.concat import parse_reference
from tsrkit.datasets.registry import load_registry
from tsrkit.plugin.base import Detector, is_trainable
from tsrkit.plugin.models import save_model
from tsrkit.plugin.registry import PluginInfo, get_registry

__all__ = ["data_licences", "dataset_checksum", "train", "trainable_plugin"]


def trainable_plugin(name: str) -> PluginInfo:
    """The trainable detector, verifier or classifier called ``name``."""
    registry = get_registry()
    candidates = [
        info
        for info in registry.plugins()
        if info.name == name and info.kind in ("detector", "verifier", "classifier")
    ]
    if not candidates:
        known = sorted(i.name for i in registry.plugins() if is_trainable(i.cls))
        raise TsrkitError(
            f"no trainable plugin called '{name}' (trainable: "
            f"{', '.join(known) or 'none installed'})"
        )
    trainable = [info for info in candidates if is_trainable(info.cls)]
    if not trainable:
        raise TsrkitError(f"{candidates[0].kind} '{name}' is not trainable")
    return trainable[0]


def dataset_checksum(dataset: Dataset) -> str:
    """sha256 over every sample's image bytes and annotations, in dataset order."""
    digest = hashlib.sha256()
    for sample in dataset:
        sample.hash_into(digest)
        for ann in sample.annotations:
            digest.update(repr((tuple(round(v, 3) for v in ann.bbox), ann.state)).encode())
    return digest.hexdigest()


def data_licences(dataset: Dataset) -> dict[str, str]:
    """The licence of each part of ``dataset`` (each ``NAME[:SPLIT]`` concatenated, or the
    dataset itself): its registry entry's, else the licence the dataset carries, else ``"not
    stated"``; written into every trained model, so that it says what data it was trained on
    and under which terms."""
    registry = load_registry()
    out = {}
    for part in dataset.info.get("parts") or [dataset.name]:
        entry = registry.get(parse_reference(part)[0])
        own = dataset.info.get("licence") if part == dataset.name else None
        out[part] = entry.licence if entry is not None else str(own or "not stated")
    return out


def train(
    name: str,
    dataset: Dataset,
    out: str | Path,
    params: Mapping[str, Any],
    detector: Detector | None = None,
) -> Path:
    """Fit plugin ``name`` on ``dataset`` with ``params``; write the model; return its path.

    ``detector`` is passed to ``fit`` (a verifier learns on that detector's candidates).
    """
    info = trainable_plugin(name)
    if info.kind == "verifier" and detector is None:
        raise TsrkitError(
            f"verifier '{name}' learns on a detector's candidates: give one "
            "(tsrkit train NAME --detector X)"
        )
    plugin = get_registry().create(info.kind, info.name, params)
    extra = {"detector": detector} if detector is not None else {}
    model = plugin.fit(dataset, **extra)  # type: ignore[attr-defined]
    training = {
        "dataset": dataset.name,
        "samples": len(dataset),
        "checksum": dataset_checksum(dataset),
        "licences": data_licences(dataset),
    }
    if detector is not None:
        training["detector"] = {"name": detector.name, "params": detector.params}
    return save_model(
        out,
        model,
        plugin=info.name,
        plugin_version=info.version,
        params=plugin.params,
        training=training,
    )
