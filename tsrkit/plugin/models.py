"""Trained models as plain arrays (``.npz``) plus JSON metadata, never pickles.

``save_model`` writes ``NAME.npz`` and ``NAME.json`` atomically; the JSON records the plugin,
its version, the parameters, the training set's checksum and a sha256 of every array, so
``load_model`` can refuse a corrupt, truncated or mismatched file with a clear message. A model
may also hold whole files in a format of their own (an ONNX network: ``NAME.onnx``), written
beside the JSON and checked by their sha256 the same way; a model of files only has no ``.npz``.
"""

from __future__ import annotations

import hashlib
import io
import json
import os
import zipfile
import zlib
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from tsrkit.core.atomic import atomic_open, write_json
from tsrkit.core.errors import TsrkitError
from tsrkit.core.files import InputFileError, file_size, not_regular, read_text
from tsrkit.plugin.params import Part

__all__ = ["FORMAT_VERSION", "Model", "ModelError", "load_model", "model_paths", "save_model"]

FORMAT_VERSION = 1


class ModelError(TsrkitError):
    """A model file that is missing, corrupt, or made for another plugin."""


@dataclass(frozen=True)
class Model:
    """What a trainable plugin's ``fit`` returns and its ``model`` parameter loads.

    ``arrays`` hold every learned number (numeric dtypes only); ``files`` whole files by their
    suffix (``{"onnx": b"..."}`` is written as ``NAME.onnx``); ``info`` holds small JSON facts
    (class names, explained variance, ...). ``meta`` is filled by :func:`load_model`.
    """

    arrays: Mapping[str, np.ndarray]
    info: Mapping[str, Any] = field(default_factory=dict)
    meta: Mapping[str, Any] = field(default_factory=dict)
    files: Mapping[str, bytes] = field(default_factory=dict)


def model_paths(path: str | os.PathLike) -> tuple[Path, Path]:
    """The ``.npz`` and ``.json`` paths for a model named ``path`` (with or without suffix)."""
    path = Path(path)
    base = path.with_suffix("") if path.suffix in (".npz", ".json", ".onnx") else path
    return base.with_suffix(".npz"), base.with_suffix(".json")


def _digest(array: np.ndarray) -> str:
    return hashlib.sha256(np.ascontiguousarray(array).tobytes()).hexdigest()


def save_model(
    path: str | os.PathLike,
    model: Model,
    *,
    plugin: str,
    plugin_version: str,
    params: Mapping[str, Any],
    training: Mapping[str, Any],
) -> Path:
    """Write ``model`` for ``plugin``; return the ``.npz`` path.

    Raises
    ------
    ModelError
        When an array is not numeric (object arrays would need pickle).
    """
    npz_path, json_path = model_paths(path)
    for name, array in model.arrays.items():
        if np.asarray(array).dtype.kind not in "biufc":
            raise ModelError(f"model array '{name}' is not numeric; cannot save without pickle")
    for suffix in model.files:
        if not suffix.isalnum() or suffix in ("npz", "json"):
            raise ModelError(f"model file suffix {suffix!r}: not a plain suffix of its own")
    if model.arrays or not model.files:
        buffer = io.BytesIO()
        arrays = {k: np.asarray(v) for k, v in model.arrays.items()}
        # numpy's stub reads **arrays as its allow_pickle keyword; the arrays are numeric (above)
        np.savez_compressed(buffer, **arrays)  # type: ignore[arg-type]
        with atomic_open(npz_path, "wb") as fh:
            fh.write(buffer.getvalue())
    for suffix, data in model.files.items():
        with atomic_open(json_path.with_suffix("." + suffix), "wb") as fh:
            fh.write(data)
    # reads the installed metadata: only when a model is saved
    from tsrkit.core.version import __version__

    write_json(
        json_path,
        {
            "format_version": FORMAT_VERSION,
            "plugin": plugin,
            "plugin_version": plugin_version,
            "tsrkit_version": __version__,
            "params": _plain(params),
            "training": _plain(training),
            "info": _plain(model.info),
            "arrays": {
                k: {
                    "shape": list(np.shape(v)),
                    "dtype": str(np.asarray(v).dtype),
                    "sha256": _digest(np.asarray(v)),
                }
                for k, v in model.arrays.items()
            },
            "files": {
                k: {"bytes": len(v), "sha256": hashlib.sha256(v).hexdigest()}
                for k, v in model.files.items()
            },
        },
    )
    return npz_path if model.arrays or not model.files else json_path


#: The largest model file read, in bytes.
MAX_MODEL_BYTES = 4 * 2**30


def load_model(path: str | os.PathLike, plugin: str) -> Model:
    """Read a model saved by :func:`save_model` and check it belongs to ``plugin``.

    Raises
    ------
    ModelError
        Missing files, unreadable JSON or archive, another plugin's model, or arrays whose
        checksums differ from the metadata.
    """
    npz_path, json_path = model_paths(path)
    meta = _metadata(json_path, plugin)
    arrays = _arrays(npz_path, meta["arrays"]) if meta["arrays"] or not meta["files"] else {}
    files = {}
    for suffix, entry in meta["files"].items():
        where = json_path.with_suffix("." + suffix)
        data = _read_file(where)
        if hashlib.sha256(data).hexdigest() != entry.get("sha256"):
            raise ModelError(f"model {where}: does not match its checksum in {json_path.name}")
        files[suffix] = data
    return Model(arrays=arrays, info=meta.get("info", {}), meta=meta, files=files)


def _read_file(path: Path) -> bytes:
    """The bytes of a model file, refused as :class:`ModelError` when missing, not a regular
    file or larger than :data:`MAX_MODEL_BYTES`."""
    problem = not_regular(path)
    if problem == "no such file":
        raise ModelError(f"model {path}: no such file (a model's files lie beside its .json)")
    if problem:
        raise ModelError(f"model {path}: {problem}")
    try:
        file_size(path, MAX_MODEL_BYTES)
        return path.read_bytes()
    except InputFileError as exc:
        raise ModelError(f"model {exc}") from None
    except OSError as exc:
        raise ModelError(f"model {path}: unreadable ({exc.strerror or exc})") from None


def _metadata(json_path: Path, plugin: str) -> dict[str, Any]:
    """The model's JSON metadata, checked to be tsrkit's and made for ``plugin``."""
    problem = not_regular(json_path)
    if problem == "no such file":
        raise ModelError(
            f"model {json_path}: no such file (a model is a .npz or .onnx with a .json beside it)"
        )
    if problem:
        raise ModelError(f"model {json_path}: {problem}")
    try:
        meta = json.loads(read_text(json_path, MAX_MODEL_BYTES))
    except InputFileError as exc:
        raise ModelError(f"model {json_path}: unreadable metadata ({exc.problem})") from None
    except (json.JSONDecodeError, RecursionError) as exc:
        raise ModelError(f"model {json_path}: unreadable metadata ({exc})") from None
    if (
        not isinstance(meta, dict)
        or not isinstance(meta.get("plugin"), str)
        or not isinstance(meta.get("arrays"), dict)
        or not all(isinstance(entry, dict) for entry in meta["arrays"].values())
        or not isinstance(meta.get("files", {}), dict)
        or not all(
            isinstance(entry, dict) and str(suffix).isalnum() and suffix not in ("npz", "json")
            for suffix, entry in meta.get("files", {}).items()
        )
        or not isinstance(meta.get("info", {}), dict)
    ):
        raise ModelError(f"model {json_path}: not tsrkit model metadata")
    if meta["plugin"] != plugin:
        raise ModelError(f"model {json_path} was trained for '{meta['plugin']}', not '{plugin}'")
    meta.setdefault("files", {})
    return meta


def _arrays(npz_path: Path, expected: Mapping[str, Any]) -> dict[str, np.ndarray]:
    """The arrays of the model's ``.npz``, checked against their checksums in ``expected``."""
    problem = not_regular(npz_path)
    if problem == "no such file":
        raise ModelError(
            f"model {npz_path}: no such file (a model is a .npz with a .json beside it)"
        )
    if problem:
        raise ModelError(f"model {npz_path}: {problem}")
    try:
        file_size(npz_path, MAX_MODEL_BYTES)
    except InputFileError as exc:
        raise ModelError(f"model {exc}") from None
    try:
        with np.load(npz_path, allow_pickle=False) as archive:
            arrays = {name: archive[name] for name in archive.files}
    except (
        OSError,
        ValueError,
        zipfile.BadZipFile,
        EOFError,
        zlib.error,
        NotImplementedError,
        RuntimeError,
    ) as exc:
        # a damaged deflate stream (zlib.error) or zip header (NotImplementedError: "zip file
        # version 21.7", "compression method is not supported") found by benchmarks/fuzz.py;
        # RuntimeError: a damaged flag bit reads as "File ... is encrypted" (hypothesis)
        raise ModelError(
            f"model {npz_path}: corrupt archive ({type(exc).__name__}: {exc})"
        ) from None
    if set(arrays) != set(expected):
        raise ModelError(
            f"model {npz_path}: arrays {sorted(arrays)} do not match the "
            f"metadata {sorted(expected)}"
        )
    for name, array in arrays.items():
        if _digest(array) != expected[name].get("sha256"):
            raise ModelError(f"model {npz_path}: array '{name}' does not match its checksum")
    return arrays


def _plain(value: Any) -> Any:
    """Make parameters and info JSON-friendly (tuples to lists, numpy scalars to Python)."""
    if isinstance(value, Mapping):
        return {str(k): _plain(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_plain(v) for v in value]
    if isinstance(value, np.generic):
        return value.item()
    if isinstance(value, np.ndarray):
        return value.tolist()
    if isinstance(value, Part):
        return value.spec
    return value
