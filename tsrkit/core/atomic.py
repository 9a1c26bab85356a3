"""Atomic file output: write beside the target, then rename over it in one step."""

from __future__ import annotations

import contextlib
import json
import math
import os
import tempfile
from pathlib import Path
from typing import Any

from tsrkit.core.outputs import refuse_input, refuse_special

__all__ = ["atomic_open", "finite", "json_line", "json_text", "write_json"]


@contextlib.contextmanager
def atomic_open(
    path: str | os.PathLike, mode: str = "w", encoding: str | None = "utf-8", sync: bool = True
):
    """Open a temporary file next to ``path``; on success it replaces ``path`` atomically.

    On an exception the temporary file is removed and ``path`` is left as it was. A ``path``
    that names one of the run's inputs (:func:`tsrkit.core.outputs.reading`) is refused before
    anything is written, and so is a device node (:func:`tsrkit.core.outputs.refuse_special`).
    ``sync`` forces the bytes to disk before the rename (``fsync``), so that a crash of the
    machine cannot leave an empty file under the new name; a cache entry, which is recomputed
    when it cannot be read, skips that wait.
    """
    path = Path(path)
    refuse_input(path)
    refuse_special(path, follow=False)
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=path.parent)
    try:
        with os.fdopen(fd, mode, encoding=None if "b" in mode else encoding) as fh:
            yield fh
            fh.flush()
            if sync:
                os.fsync(fh.fileno())
        os.chmod(tmp, 0o666 & ~_umask())
        os.replace(tmp, path)
    except BaseException:
        with contextlib.suppress(FileNotFoundError):
            os.unlink(tmp)
        raise


def _umask() -> int:
    """The process umask (read by setting and restoring it)."""
    mask = os.umask(0)
    os.umask(mask)
    return mask


def finite(data: Any) -> Any:
    """``data`` with every NaN or infinite float replaced by None, so that JSON written from it
    holds no ``NaN`` / ``Infinity`` tokens (which are not JSON).

    Examples
    --------
    >>> finite({"score": float("nan"), "box": [1.0, float("inf")], "n": 2})
    {'score': None, 'box': [1.0, None], 'n': 2}
    """
    if isinstance(data, float):
        return data if math.isfinite(data) else None
    if isinstance(data, dict):
        return {key: finite(value) for key, value in data.items()}
    if isinstance(data, (list, tuple)):
        return [finite(value) for value in data]
    return data


def json_text(data: Any, indent: int | None = None, default: Any = None) -> str:
    """``data`` as JSON text with every non-finite number written as null (:func:`finite`):
    what tsrkit writes is JSON that any strict reader accepts (no ``NaN`` / ``Infinity``).

    Examples
    --------
    >>> json_text({"p": float("nan"), "m": float("-inf"), "n": 1.5})
    '{"p": null, "m": null, "n": 1.5}'
    """
    return json.dumps(finite(data), indent=indent, default=default, allow_nan=False)


def json_line(data: Any) -> str:
    """One JSON Lines record (no newline), with non-finite numbers as null."""
    return json_text(data)


def write_json(path: str | os.PathLike, data: Any, indent: int | None = 2) -> None:
    """Write ``data`` as indented JSON, atomically, with non-finite numbers as null."""
    with atomic_open(path) as fh:
        fh.write(json_text(data, indent) + "\n")
