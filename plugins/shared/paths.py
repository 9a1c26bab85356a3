"""Paths as the dataset formats and report writers store them."""

from __future__ import annotations

import os
from pathlib import Path

__all__ = ["relative_source"]


def relative_source(source: str, folder: Path) -> str:
    """``source`` written relative to ``folder`` (POSIX separators), as writers store it."""
    return Path(os.path.relpath(Path(source).resolve(), Path(folder).resolve())).as_posix()
