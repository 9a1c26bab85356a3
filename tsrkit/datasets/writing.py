"""Writing a dataset with a format plugin (``tsrkit datasets convert``, the generated sets'
annotation files); it needs neither the dataset registry nor the readers."""

from __future__ import annotations

import os
from pathlib import Path

from tsrkit.core.errors import TsrkitError
from tsrkit.core.types import Dataset
from tsrkit.plugin.registry import get_registry

__all__ = ["write_dataset"]


def write_dataset(dataset: Dataset, format: str, out: str | os.PathLike) -> Path:
    """Write ``dataset`` with the format plugin ``format`` at ``out`` (file or folder)."""
    writer = get_registry().create("format", format)
    if not writer.writable:
        writable = ", ".join(
            i.name for i in get_registry().plugins("format") if getattr(i.cls, "writable", False)
        )
        raise TsrkitError(f"format '{format}' has no writer (writable: {writable})")
    writer.write(dataset, Path(out))
    return Path(out)
